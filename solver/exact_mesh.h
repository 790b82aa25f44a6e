#pragma once
/// A mesh for the exact reference solver (solver/exact_solver.h) other than
/// K equal elements per patch: each patch cut where the mesh says, so that
/// a reference can spend its elements where the radiosity varies (a slit
/// under a table leg, the gap between two books) instead of everywhere
/// (cli/reference_solution.h grades one this way).
#include <vector>

#include "engine/scene.h"

namespace flatrad {

struct ExactMesh {
    /// Per patch (scene.patches order), the interior cut points of its
    /// elements in the patch's file-order parameter t (SPEC.md "Result
    /// file": t0, t1), strictly increasing inside (0, 1). Empty: the patch
    /// is one element.
    std::vector<std::vector<double>> cuts;

    /// Elements in all: sum over patches of (cuts + 1).
    long elements() const;
};

/// K equal elements per patch (cuts at k / K), K >= 1.
ExactMesh uniform_mesh(const Scene& scene, int K);

/// Every element of `mesh` cut at its midpoint.
ExactMesh halved(const ExactMesh& mesh);

/// `mesh` with element e halved level[e] times over (into 2^level[e]
/// pieces; 0 leaves it whole). Elements are numbered patch by patch, in
/// increasing t within each patch (as solve_exact lists them in a
/// solution's patches). A piece too short to halve in floating point
/// stays whole. Pre: level.size() == mesh.elements(), levels >= 0.
ExactMesh split_levels(const ExactMesh& mesh, const std::vector<int>& level);

/// Throws std::invalid_argument unless `mesh` has one entry per patch of
/// `scene` and every patch's cuts are finite, strictly increasing and
/// strictly inside (0, 1).
void check_mesh(const Scene& scene, const ExactMesh& mesh);

}  // namespace flatrad
