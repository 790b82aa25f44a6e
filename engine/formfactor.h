#pragma once
/// Unoccluded flatland form factor kernels (DESIGN.md §1).
///
/// The 2D kernel K(x, y) = cos(phi_x) cos(phi_y) / (2 r) integrates to 1 over
/// a half circle. All segments here are oriented with the lit side on their
/// left (Segment::left_normal()).
#include <optional>
#include <utility>

#include "engine/geometry.h"

namespace flatrad {

/// Point-to-segment form factor F(x -> [c, d]) = (sin b - sin a) / 2, a and b
/// the angles of c and d from the unit normal n at x (DESIGN.md §1).
/// Pre: |n| = 1; [c, d] lies wholly in the half-plane in front of x and is
/// fully visible from x. Post: 0 <= F <= 1 (orientation of [c, d] ignored).
double form_factor_point_segment(Vec2 x, Vec2 n, const Segment& s);

/// Mutual lit-half-plane clipping: the part of i in front of j's lit side
/// and the part of j in front of i's lit side (closed half-planes). Only these
/// parts exchange light. Returns nothing when either part is a point or empty
/// (for example collinear segments, or segments facing away).
/// Both segments are oriented lit-left; the clipped parts keep the
/// orientation.
std::optional<std::pair<Segment, Segment>> clip_to_lit_halfplanes(const Segment& i, const Segment& j);

/// Hottel's crossed strings for two lit-left segments i = [a, b], j = [c, d]
/// that each lie wholly on the lit side of the other (as clip_to_lit_halfplanes
/// leaves them): returns L_i F_ij = 1/2 ((|a-c| + |b-d|) - (|a-d| + |b-c|)),
/// the half measure of the lines meeting both.
/// Evaluated by the second-difference form of DESIGN.md §1, in which only
/// small vectors are subtracted: a few 1e-15 relative even at distance/length
/// 1e8, where the plain sum has no correct digit.
/// Post: >= 0; symmetric: exchange(i, j) == exchange(j, i) up to rounding.
double exchange_crossed_strings(const Segment& i, const Segment& j);

/// The same, summed plainly. Kept as the textbook formula for tests; it
/// cancels catastrophically when the segments are far apart.
double exchange_crossed_strings_naive(const Segment& i, const Segment& j);

/// Unoccluded form factor F_ij between lit-left segments: clip, then crossed
/// strings divided by L_i (the unclipped length). 0 when they cannot see
/// each other's lit side.
double form_factor_unoccluded(const Segment& i, const Segment& j);

}  // namespace flatrad
