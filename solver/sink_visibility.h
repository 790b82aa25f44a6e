#pragma once
/// Unlit sides that no patch can see (DESIGN.md §4: pay for what the scene
/// uses). An unlit side of a segment is a sink: black, it absorbs what it
/// receives (SPEC). The outer side of a room lit inside, with everything
/// else in the room, and the inner side of a pillar lit outside, with
/// nothing in it, receive nothing: the solver makes no node for them, and
/// an escape-free patch (light that cannot leave the scene,
/// engine/connectivity.h) that sees no visible sink knows that its form
/// factors to the lit patches sum to 1 (solver/closed_rows.h).
///
/// Rule (sufficient): the segment is on a simple loop L of known orientation
/// (engine/connectivity.h) and
///  - the unlit side faces L's exterior, every segment not on L lies
///    inside L (both endpoints inside and no contact with L; or, touching
///    L, no endpoint outside, no edge properly crossed, no corner of L on
///    it and its midpoint inside: a shelf against a wall, as L stays closed
///    where it is touched), and no side of L facing its exterior is lit; or
///  - the unlit side faces L's interior, no segment not on L has an
///    endpoint inside L or touches L, and no side of L facing its interior
///    is lit.
/// The sides' places against L: solver/loop_sides.h, with a segment in line
/// with an edge of L counted as touching it (kept for its results, see
/// polygon_tests.h's meets_or_in_line). A point within rounding of L's
/// boundary counts as touching (then the sink is kept: not proven).
/// Cost: O((segments off L) x |L|) per loop with unlit sides, skipped
/// (sinks kept) beyond 1e8 tests in all. A round room of 10^5 walls and
/// nothing inside costs nothing (it once counted its own walls: 10^10,
/// over the budget, so its outer sides stayed as sinks and its clusters
/// faced both ways).
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

namespace flatrad {

/// Two entries per segment (left side, right side of a -> b): 1 when the
/// side is unlit and not proven invisible, 0 when it is lit or proven
/// invisible.
std::vector<char> visible_sinks(const Scene& scene, const Connectivity& connectivity);

}  // namespace flatrad
