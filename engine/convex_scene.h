#pragma once
/// Scenes in which no segment can block another (DESIGN.md §4: "a closed
/// convex room does no visibility work at all").
///
/// If every segment lies on the boundary of the convex hull of all the
/// segments, no segment can stand between two others: the open segment
/// joining two boundary points of a convex set lies in its interior (or on
/// one boundary edge, where both points' segments are collinear and
/// exchange nothing). So every form factor is the unoccluded one and the
/// solver asks the visibility module nothing.
#include "engine/scene.h"

namespace flatrad {

/// True when every segment of `scene` lies on its convex hull's boundary
/// (within a relative 1e-12 of the extent, for coordinates read from text).
/// Conservative: false when unsure. O(N log N): the hull, then a binary
/// search of each segment's supporting direction among the hull's edges.
bool no_segment_can_block(const Scene& scene);

}  // namespace flatrad
