#pragma once
/// Guaranteed bounds on the line-space integral of one shaft by direction
/// bins: a cheaper answer than the exact integral (exact_visibility.h) when
/// the shaft holds many blocker pieces and the caller's tolerance is loose.
///
/// L_i F_ij = 1/2 Integral_phi free(phi) dphi, free(phi) the length of the
/// overlap window (lines of direction phi meeting both patches) left by the
/// union of the pieces' shadows (DESIGN.md §1). Over a bin of directions
/// [c - h, c + h], every point's projection n(phi) . P moves by at most
/// |P - O| h from its value at c (O any fixed centre; the free length
/// depends only on differences of projections, so O is the shaft's centre).
/// Widening each shadow by its ends' drift and narrowing the window gives a
/// free length no larger than at any phi of the bin; narrowing the shadows
/// and widening the window, one no smaller. So
///   2h lower(c, h) <= Integral_bin free <= 2h upper(c, h),
/// each side one sort and sweep of the pieces, O(n log n). The gap shrinks
/// as h^2 per bin (the drift times the bin's width), and only where shadow
/// ends lie in the window: bins are halved worst first until the bounds are
/// within the tolerance, or a budget of evaluations is spent.
///
/// Exact integral: O(n^2) critical directions or more. This: O(n log n)
/// per bin, and a dense forest's window is mostly covered (few shadow ends
/// in it), so few bins. Neither samples: the bounds hold, up to rounding.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "engine/geometry.h"

namespace flatrad {

struct DirectionBounds {
    double lo = 0, hi = 0;  ///< bounds on L_i F_ij (lo <= hi)
    /// With DirectionBoundsOptions::estimate: the midpoint rule over the
    /// final bins (each bin's free length at its centre direction, without
    /// drift), clamped to [lo, hi]; else NaN. An estimate, not a bound: it
    /// tends to the integral as the bins narrow, while the bounds' midpoint
    /// stays halfway up their gap, which through a dense forest is a bias
    /// (the drift takes the lower bound to 0 where the truth is near it).
    double estimate = std::numeric_limits<double>::quiet_NaN();
    long evaluations = 0;   ///< bins evaluated
    bool converged = false; ///< hi - lo <= 2 tol reached within the budget
};

/// An interval of line offsets n(phi) . P along a bin's normal.
struct OffsetInterval {
    double a, b;
};

/// The drift bound (above), for a segment whose ends are at offsets p and
/// q at the bin's centre and move by at most dp and dq within the bin:
/// swept() holds every offset the segment covers at some direction of the
/// bin; held() is covered at every direction of it (empty, b <= a, when
/// no offset is). Shared by the bounds here and opaque_band.h.
inline OffsetInterval swept(double p, double dp, double q, double dq) {
    return {std::min(p - dp, q - dq), std::max(p + dp, q + dq)};
}
inline OffsetInterval held(double p, double dp, double q, double dq) {
    return {std::min(p + dp, q + dq), std::max(p - dp, q - dq)};
}

/// The length of `window` that the first m `shadows` (each with b > a and
/// meeting the window) leave uncovered, summed gap by gap from left to
/// right; once the sum exceeds `budget`, that partial sum (> budget). The
/// same number, bit for bit, as sorting the shadows by start and sweeping
/// (which it does past a few gaps; the shadows may be reordered). A bin's
/// free lengths here (budget +infinity) and a band section's check
/// (opaque_band.h), where a dense forest covers the window in a few hops.
double gaps_in_window(OffsetInterval window, OffsetInterval* shadows, size_t m, double budget);

/// Scratch memory of one thread.
struct DirectionBoundsScratch {
    std::vector<Vec2> points;
    std::vector<double> radius;
    using Interval = OffsetInterval;
    std::vector<Interval> intervals, narrow_intervals, centre_intervals;
    struct Bin {
        double c, h, lower, upper, centre;
    };
    std::vector<Bin> bins;
};

/// Bins a call starts with by default (equal, over the whole range of
/// directions).
inline constexpr int direction_bounds_initial_bins = 16;

struct DirectionBoundsOptions {
    int initial_bins = direction_bounds_initial_bins;
    bool estimate = false;  ///< also DirectionBounds::estimate (a third sweep per bin)
};

/// Bounds on L_i F_ij for a mutually clipped facing pair (ci, cj), lit on the
/// left, with `count` blocker pieces inside its shaft, refined until
/// hi - lo <= 2 tol or `max_evaluations` bins have been evaluated (at least
/// the initial ones).
DirectionBounds direction_bounds(const Segment& ci, const Segment& cj, const Segment* pieces, size_t count,
                                 double tol, long max_evaluations, DirectionBoundsScratch& scratch,
                                 const DirectionBoundsOptions& how = {});

}  // namespace flatrad
