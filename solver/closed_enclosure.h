#pragma once
/// Closed enclosures of reflectance 1 (DESIGN.md §3): a set of elements
/// whose light stays among themselves (rows of F summing to 1 within the
/// set) with reflectance 1 makes I - rho F singular, so the scene has no
/// unique solution and is refused. Shared by every solver.
#include <Eigen/Dense>
#include <vector>

#include "engine/scene.h"

namespace flatrad {

/// Form factors are exact to ~1e-13 (closure tests), so 1e-9 catches only
/// enclosures closed up to rounding, while any real opening or absorber
/// (even 1e-6 of the view) counts as a leak.
inline constexpr double closure_tolerance = 1e-9;

/// Indices a with rho[a] == 1 that keep all their light among themselves:
/// starting from all reflectance-1 elements, drop those that leak out of the
/// set until it is stable. Empty when the system is regular.
std::vector<int> closed_white_set(const Eigen::MatrixXd& F, const std::vector<double>& rho);

/// Throws InputError naming the surfaces of `patches` (patch indices of the
/// scene): "no unique solution: ... enclose(s) light with reflectance 1".
[[noreturn]] void refuse_closed_white(const Scene& scene, const std::vector<int>& patches, int channel);

}  // namespace flatrad
