#pragma once
/// Closure of a whole box: a proof that every line from a segment, or from
/// any point of one box, to any point of a hierarchy node's box meets a
/// blocker that is none of either end's (MultiscaleVisibility::
/// box_shown_closed, boxes_shown_closed). For the hierarchical solver's
/// links from a bright element to clusters many layers of shadow away,
/// asked before such a link is split on its geometry: one proof drops the
/// whole link, exactly, where each of its pieces would otherwise be asked
/// on its own (solver/hierarchical_solver.cpp).
///
/// Why it holds. Let B be a box holding every segment of the receiving
/// node (its tight box, widened a little against rounding), and p a point
/// outside B. A line from p to a point q of B enters B at a point x of its
/// boundary, through a side of B whose outer half-plane holds p (B is
/// convex: the line runs outside B up to x and inside after it). The piece
/// from p to x is part of the line from p to q; a blocker on it blocks the
/// line. So if, for every side of B (oriented lit outward), every line from
/// the sender's lit side to that side's lit side is blocked, every line
/// from the sender to B is, whatever the receiver holds. The blocker meets
/// the piece from p to x, outside B's interior: it is not one of B's
/// segments, which may therefore be left out of the proof (they must be:
/// a segment along B's side would otherwise seem to close it). When the
/// sender is a box A as well (disjoint from B), a line from a point of A to
/// one of B leaves A through a side of A whose outer half-plane holds the
/// rest of the line, then enters B as above: the piece between the two
/// sides is blocked when every line between those two sides is, for every
/// pair of sides that see each other's outer half-plane.
///
/// Each pair (a segment and a side, or two sides) is one slab proof of
/// closure (MultiscaleVisibility::shown_closed's step: bands of blockers in
/// three slabs near the narrower end); the pair is closed only if all of
/// them are. A pair whose ends do not face each other (no line from lit
/// side to lit side) has no lines to block.
///
/// With a budget, the same cover bounds what passes: every free line from
/// the sender to a point of B is free up to the side it enters by, so the
/// light entering B (so reaching anything inside it) is at most the
/// sender's radiosity times the sum over the pairs of their exchanges, each
/// at most its bands' upper bound.
#include <array>

#include "engine/geometry.h"

namespace flatrad {

/// The margin the proofs widen a box by: 64 ulps of its largest coordinate
/// and 1e-9 of its diagonal, so that a segment on its side (rounded) lies
/// strictly inside.
double box_margin(const Box& b);

/// `b` widened by box_margin(b) on every side.
Box widened_box(const Box& b);

/// The four sides of `b`, each oriented with its lit (left) side facing out
/// of the box.
std::array<Segment, 4> outward_sides(const Box& b);

}  // namespace flatrad
