#pragma once
/// Closure screens: one proof of closure that answers many long shafts
/// (DESIGN.md §2; for the hierarchical solver's links from a bright element
/// to clusters far across a dense forest, solver/hierarchical_solver.cpp).
///
/// A screen of a segment A (lit on its left) is a segment T in front of A,
/// facing it, such that every line from a point of A to a point of T meets
/// a blocker between the two (shown closed by
/// MultiscaleVisibility::shown_closed, from bands of blockers near A).
/// Then, for any part a of A and any region R wholly beyond T's line (on
/// the side away from A), a line from a point p of a to a point q of R that
/// crosses T's line inside T is blocked: its piece from p to the crossing x
/// joins A to T, so a blocker meets it before x, hence before q. That
/// blocker lies in the hull of A and T, on A's side of T's line, so it is
/// none of R's (the query may leave R's own segments out).
///
/// Where the lines joining a's two ends to R's four corners all cross T's
/// line inside T, every line from a to R does: for a fixed p, the crossing
/// moves along T's line as a central projection of q from p, which maps a
/// segment lying wholly beyond the line onto the segment between its ends'
/// images, so the crossings of the convex R fill the hull of its corners'
/// crossings; the same holds in p for a fixed q. So one proof answers,
/// exactly (a transmittance of 0, not an estimate), every query from A's
/// parts to targets its screen covers.
#include <optional>

#include "engine/geometry.h"

namespace flatrad {

/// The screen of `a` (lit on its left) toward the point `toward`:
/// perpendicular to the line from a's midpoint m to `toward`, centred on it
/// at distance `depth` from m, `half_width` to each side, oriented with its
/// left side facing a. Empty when `toward` is m, or when the screen would
/// not lie wholly in front of a (strictly on a's lit side) with a wholly in
/// front of it: the proof's clipping would then change the pair.
std::optional<Segment> closure_screen(const Segment& a, Vec2 toward, double depth, double half_width);

/// Whether a screen (a segment facing `a`, as closure_screen makes them)
/// answers for every line from `a` to a point of `region`: `a` strictly in
/// front of the screen's line, `region` strictly behind it, and the lines
/// from a's ends to the region's corners crossing the line inside the
/// screen. Margins of rounding (relative to the coordinates' magnitude, and
/// 1e-9 of the screen's length at its ends) make every doubt a "no".
bool screen_covers(const Segment& screen, const Segment& a, const Box& region);

}  // namespace flatrad
