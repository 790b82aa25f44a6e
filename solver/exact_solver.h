#pragma once
/// The exact reference solver (DESIGN.md §3, last paragraph): every patch cut
/// into K equal elements, every element pair's exact occluded form factor,
/// and the dense system (I - rho F) B = E solved directly (Eigen LU) per
/// channel. The yardstick for every approximation.
#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

struct ExactSolverOptions {
    int subdivide = 1;   ///< K >= 1 elements per patch
    int threads = 0;     ///< 0: all cores
};

/// Throws InputError when the system has no unique solution (a closed
/// enclosure of reflectance 1 without absorber, in some channel), naming
/// the surfaces involved.
Solution solve_exact(const Scene& scene, const ExactSolverOptions& options = {});

}  // namespace flatrad
