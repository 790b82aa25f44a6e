#pragma once
/// Exact occluded exchange between two segments by line space (DESIGN.md §1).
///
/// L_i F_ij = 1/2 Integral_theta |{p : line (p, theta) meets i and j and no
/// blocker between them}| dtheta. Steps:
///  1. mutual lit-half-plane clipping of i and j;
///  2. shaft culling: blockers are the scene segments (other than i's and
///     j's own) meeting the convex hull of the clipped pair, found through
///     the cluster hierarchy and clipped to the hull; inside the hull every
///     blocker piece lies between the two crossings of a line;
///  3. critical directions: the directions of lines through two of the
///     endpoints involved (patches and blocker pieces), within the range of
///     directions of lines meeting both patches;
///  4. between consecutive critical directions the free measure is
///     m(theta) = W . n(theta) for a fixed vector W, so its integral over
///     [theta0, theta1] is exactly 2 sin((theta1 - theta0)/2) m(theta_mid).
/// No sampling and no quadrature: the only error is rounding. Directions are
/// measured from the pair's own axis, so that far-apart patches (a tiny
/// range of directions) keep full relative precision.
#include <cstdint>
#include <vector>

#include "engine/geometry.h"
#include "engine/hierarchy.h"
#include "visibility/direction_bounds.h"
#include "visibility/opaque_band.h"
#include "visibility/stats.h"

namespace flatrad {

/// Scratch memory for one thread; reuse it across queries.
struct ExactWorkspace {
    std::vector<int32_t> stack;
    std::vector<Segment> blockers;
    std::vector<std::vector<Segment>> levels;  // blocker pieces per sub-shaft depth
    std::vector<Vec2> points;
    std::vector<double> directions;
    std::vector<double> proj;
    std::vector<int32_t> order;
    std::vector<double> soa;
    DirectionBoundsScratch bounds;  // visibility/direction_bounds.h (multi-scale queries)
    OpaqueBandScratch band;         // visibility/opaque_band.h (multi-scale queries)
};

class ExactVisibility {
public:
    /// `hierarchy` is built over the scene's segments (every one a blocker);
    /// it must outlive this object.
    explicit ExactVisibility(const Hierarchy& hierarchy) : m_hierarchy(&hierarchy) {}

    /// L_i F_ij (= L_j F_ji) between lit-left segments i and j, every
    /// hierarchy segment except numbers `skip_i` and `skip_j` (their own
    /// segments; -1 for none) an occluder. Pieces of segments (elements) are
    /// fine: pass the parent segment's number as skip.
    double exchange(const Segment& i, const Segment& j, int skip_i, int skip_j, ExactWorkspace& ws,
                    VisibilityStats& stats) const;

    /// Same with blockers given explicitly (no hierarchy): for tests and for
    /// callers that already culled. Blockers need not lie inside the shaft.
    static double exchange_with_blockers(const Segment& i, const Segment& j,
                                         const std::vector<Segment>& blockers, ExactWorkspace& ws,
                                         VisibilityStats& stats);

    /// F_ij = exchange / L_i.
    double form_factor(const Segment& i, const Segment& j, int skip_i, int skip_j, ExactWorkspace& ws,
                       VisibilityStats& stats) const {
        return exchange(i, j, skip_i, skip_j, ws, stats) / i.length();
    }

private:
    const Hierarchy* m_hierarchy;
};

}  // namespace flatrad
