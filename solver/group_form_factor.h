#pragma once
/// Form factor between two groups of surfaces (SPEC.md, `flatrad formfactor`):
/// F_AB = sum_{i in A, j in B} L_i F_ij / L_A over lit patches, every segment
/// of the scene an occluder; F_reverse the same from B to A.
#include <string>
#include <vector>

#include "engine/scene.h"
#include "visibility/stats.h"

namespace flatrad {

enum class FormFactorMethod { Exact, Unoccluded };

struct GroupFormFactor {
    double F = 0;
    double F_reverse = 0;
    double time_s = 0;
    VisibilityStats stats;
};

/// `from` and `to` are surface indices (a surface may appear in both).
GroupFormFactor group_form_factor(const Scene& scene, const std::vector<int>& from,
                                  const std::vector<int>& to, FormFactorMethod method);

}  // namespace flatrad
