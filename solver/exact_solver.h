#pragma once
/// The exact reference solver (DESIGN.md §3, last paragraph): every patch cut
/// into K equal elements, every element pair's exact occluded form factor,
/// and the dense system (I - rho F) B = E solved directly (Eigen LU) per
/// channel. The yardstick for every approximation.
#include "engine/scene.h"
#include "solver/exact_mesh.h"
#include "solver/solution.h"

namespace flatrad {

struct ExactSolverOptions {
    int subdivide = 1;   ///< K >= 1 elements per patch
    int threads = 0;     ///< 0: all cores
};

/// Most memory the exact solver may plan to use: 8 GiB, a third of this
/// project's 24 GiB machines, so that a run beyond it is refused up front
/// instead of swapping or being killed by the kernel half-way.
constexpr double exact_solver_memory_limit_bytes = 8.0 * 1024 * 1024 * 1024;

/// Estimated peak memory of solve_exact(scene, {K}), in bytes: n = patches
/// x K elements, three dense n x n double matrices alive at once (the form
/// factors F, the system I - rho F, and its LU factors) = 3 n^2 x 8, plus
/// the per-element arrays (elements, sinks, B, F B: O(n), small beside it).
/// A double because absurd K overflow any integer type; exact to well
/// under a byte in the range that matters (below 2^53).
/// Pre: K >= 1.
double exact_solver_memory_bytes(const Scene& scene, int K);
/// The same for a mesh of `elements` elements in all.
double exact_solver_memory_bytes_for(const Scene& scene, double elements);

/// Throws InputError (file: the scene's; path: "--subdivide" when K > 1,
/// else none) when exact_solver_memory_bytes(scene, K) exceeds
/// exact_solver_memory_limit_bytes, saying how much the run would need.
/// solve_exact calls it first; callers may call it earlier (before other
/// work, as the CLI does).
void check_exact_solver_memory(const Scene& scene, int K);
/// The same for a mesh's elements (no flag named).
void check_exact_solver_memory(const Scene& scene, const ExactMesh& mesh);

/// Throws InputError when the system has no unique solution (a closed
/// enclosure of reflectance 1 without absorber, in some channel), naming
/// the surfaces involved, and, before any work, when the run would need
/// more memory than the limit (check_exact_solver_memory).
Solution solve_exact(const Scene& scene, const ExactSolverOptions& options = {});

/// The same on `mesh`'s elements (solver/exact_mesh.h) instead of K equal
/// ones (options.subdivide is not read): the solution's `subdivide` is 0
/// and each patch's radiosity the length-weighted mean of its elements'.
/// Throws std::invalid_argument for a mesh that check_mesh refuses, and
/// InputError for one beyond the memory limit.
Solution solve_exact(const Scene& scene, const ExactMesh& mesh, const ExactSolverOptions& options = {});

}  // namespace flatrad
