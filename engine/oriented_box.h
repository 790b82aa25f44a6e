#pragma once
/// A box aligned with the segments it holds, per node of the cluster
/// hierarchy. An axis-aligned box of a slanted arc pokes out from it by up
/// to half its length (a wall at 45 degrees fills a square); the box along
/// the segments' own direction is as thin as the arc's sagitta. The
/// hierarchical solver asks it whether an element's line really cuts a
/// cluster (solver/hierarchical_solver.cpp), where the axis-aligned box
/// forced clusters tens of segments away from a curved wall to be split.
///
/// Axis: the segments' principal direction, the length-weighted mean of
/// their direction angles doubled (so that a segment and its reverse
/// agree). Extents: exact over the segments' endpoints at hierarchy
/// leaves; at inner nodes over the children's corners (conservative: a
/// child's box is inside its corners' hull, so the parent's holds it).
#include <array>
#include <vector>

#include "engine/geometry.h"
#include "engine/hierarchy.h"

namespace flatrad {

struct OrientedBox {
    Vec2 axis{1, 0};  ///< unit; the second axis is rot90(axis)
    double lo_u = 0, hi_u = -1, lo_v = 0, hi_v = -1;  ///< projections onto axis and rot90(axis)

    bool empty() const { return lo_u > hi_u; }
    std::array<Vec2, 4> corners() const {
        const Vec2 v = rot90(axis);
        return {axis * lo_u + v * lo_v, axis * hi_u + v * lo_v, axis * hi_u + v * hi_v, axis * lo_u + v * hi_v};
    }
    /// Lowest and highest of dot(p - origin, n) over the box.
    std::pair<double, double> range_along(Vec2 origin, Vec2 n) const;
};

/// One box per hierarchy node (same indices).
std::vector<OrientedBox> oriented_boxes(const Hierarchy& h);

}  // namespace flatrad
