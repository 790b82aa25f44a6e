#pragma once
/// Segments that cannot block (DESIGN.md §4: "a closed convex room does no
/// visibility work at all", and a room's walls are no one's blockers).
///
/// A segment on the boundary of the convex hull of all the segments lies on
/// a supporting line with the whole scene on one side. The open segment
/// joining two points of the scene then meets that line at most at an end
/// (or lies on it, where both points' segments are collinear and exchange
/// nothing): no line of exchange crosses the segment, so it never blocks.
/// The visibility module skips such segments (Hierarchy::set_blockers), and
/// when every segment is one, the solver asks it nothing.
#include <vector>

#include "engine/scene.h"

namespace flatrad {

/// Per segment: 1 when it lies on the boundary of the convex hull of all of
/// `segments`, up to the rounding of coordinates read from text (1e-12 of
/// the coordinates' size where the hull meets the segment's line; local,
/// so that one huge wall does not blur the rest of the scene). Conservative:
/// 0 when unsure (zero length, all points collinear). O(N log N): the hull,
/// then a binary search of each segment's supporting direction among the
/// hull's edges.
std::vector<char> segments_on_hull(const std::vector<Segment>& segments);

/// Per segment of `scene`: 1 when it may block light between two others
/// (not on the hull's boundary).
std::vector<char> possible_blockers(const Scene& scene);

/// True when no segment of `scene` may block (every one on the hull's
/// boundary).
bool no_segment_can_block(const Scene& scene);

}  // namespace flatrad
