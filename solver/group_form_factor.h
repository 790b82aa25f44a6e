#pragma once
/// Form factor between two groups of surfaces (SPEC.md, `flatrad formfactor`):
/// F_AB = sum_{i in A, j in B} L_i F_ij / L_A over lit patches, every segment
/// of the scene an occluder; F_reverse the same from B to A.
#include <string>
#include <vector>

#include "engine/scene.h"
#include "visibility/multiscale.h"
#include "visibility/stats.h"

namespace flatrad {

enum class FormFactorMethod { Exact, Unoccluded, Multiscale };

struct GroupFormFactorOptions {
    double eps = 0;                      ///< multiscale tolerance on each patch pair's F
    GammaRule rule = GammaRule::Bound;   ///< multiscale criterion
};

struct GroupFormFactor {
    double F = 0;
    double F_reverse = 0;
    double time_s = 0;
    /// Multiscale: claimed bound on |F - F_exact| (F_AB is a length-weighted
    /// mean of patch-pair F_ij, so the bound is the same mean of theirs), and
    /// the same for F_reverse.
    double error_bound = 0, error_bound_reverse = 0;
    double table_seconds = 0;   ///< multiscale: time spent building cluster tables
    long tables_built = 0;
    VisibilityStats stats;
};

/// `from` and `to` are surface indices (a surface may appear in both).
GroupFormFactor group_form_factor(const Scene& scene, const std::vector<int>& from,
                                  const std::vector<int>& to, FormFactorMethod method,
                                  const GroupFormFactorOptions& options = {});

}  // namespace flatrad
