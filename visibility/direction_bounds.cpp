#include "visibility/direction_bounds.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "engine/compensated_sum.h"
#include "visibility/shaft.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace flatrad {

namespace {

// One hop's pass (gaps_in_window): over the m shadows, the farthest end b
// of those starting at or before `reach` (at least `reach`) and the
// nearest start a of the others (+infinity if none). Maxima and minima
// are exact, so any order of the items gives the same two numbers, bit
// for bit; a NaN end or start is never taken (as the scalar comparisons
// below, which fail on NaN). With SSE2, two items per lane pair and two
// pairs per step: four running maxima and minima instead of one chain of
// dependent selects, which bound the scalar loop (on the 1000-segment
// forest at eps 16, gaps_in_window was 16% of a one-thread run's samples).
void hop_pass(const OffsetInterval* shadows, size_t m, double reach, double& far_out, double& next_out) {
    constexpr double none = std::numeric_limits<double>::infinity();
    double far = reach, next = none;
    size_t it = 0;
#if defined(__SSE2__)
    static_assert(sizeof(OffsetInterval) == 2 * sizeof(double), "a, b packed");
    // (An item's a and b in one load; only items that exist are touched.)
    auto load = [&](size_t k) { return _mm_loadu_pd(&shadows[k].a); };
    const __m128d r = _mm_set1_pd(reach), inf = _mm_set1_pd(none), minus_inf = _mm_set1_pd(-none);
    __m128d far0 = _mm_set1_pd(reach), far1 = far0, next0 = inf, next1 = inf;
    // _mm_max_pd(x, y) / _mm_min_pd(x, y) return y when x is NaN: the
    // candidate goes first, the running value second.
    for (; it + 4 <= m; it += 4) {
        const __m128d s0 = load(it), s1 = load(it + 1), s2 = load(it + 2), s3 = load(it + 3);
        const __m128d a01 = _mm_unpacklo_pd(s0, s1), b01 = _mm_unpackhi_pd(s0, s1);
        const __m128d a23 = _mm_unpacklo_pd(s2, s3), b23 = _mm_unpackhi_pd(s2, s3);
        const __m128d st01 = _mm_cmple_pd(a01, r), st23 = _mm_cmple_pd(a23, r);  // started (false on NaN)
        // Started: b, else -inf (never a maximum); not started: a, else +inf.
        const __m128d fb01 = _mm_or_pd(_mm_and_pd(st01, b01), _mm_andnot_pd(st01, minus_inf));
        const __m128d fb23 = _mm_or_pd(_mm_and_pd(st23, b23), _mm_andnot_pd(st23, minus_inf));
        const __m128d na01 = _mm_or_pd(_mm_andnot_pd(st01, a01), _mm_and_pd(st01, inf));
        const __m128d na23 = _mm_or_pd(_mm_andnot_pd(st23, a23), _mm_and_pd(st23, inf));
        far0 = _mm_max_pd(fb01, far0);
        far1 = _mm_max_pd(fb23, far1);
        next0 = _mm_min_pd(na01, next0);
        next1 = _mm_min_pd(na23, next1);
    }
    const __m128d fm = _mm_max_pd(far0, far1), nm = _mm_min_pd(next0, next1);
    double f2[2], n2[2];
    _mm_storeu_pd(f2, fm);
    _mm_storeu_pd(n2, nm);
    far = std::max(f2[0], f2[1]);
    next = std::min(n2[0], n2[1]);
#endif
    for (; it < m; ++it) {
        const OffsetInterval& sh = shadows[it];
        const bool started = sh.a <= reach;
        far = started && sh.b > far ? sh.b : far;
        next = !started && sh.a < next ? sh.a : next;
    }
    far_out = far;
    next_out = next;
}

}  // namespace

double gaps_in_window(OffsetInterval window, OffsetInterval* shadows, size_t m, double budget) {
    double reach = window.a, free = 0;
    // First by hops, without sorting: from `reach`, the farthest end of the
    // shadows that start at or before it extends the union; where none
    // does, the nearest start beyond it ends a gap. The gaps are the sweep's
    // below (from the union's end to the next start, in the same order), so
    // the sum is the same bit for bit, returned at the same points. A band's
    // section is covered in a few hops of a shadow's length each, one
    // branch-free pass over the shadows each, where sorting them compares
    // each ~log2(m) times; a section with many gaps takes many hops, so
    // past hop_budget the sweep takes over from where the hops stopped (a
    // shadow starting at or before `reach` only extends the union there, as
    // it would have in the sweep).
    constexpr int hop_budget = 12;
    constexpr double none = std::numeric_limits<double>::infinity();
    for (int hop = 0; hop < hop_budget; ++hop) {
        double far, next;
        hop_pass(shadows, m, reach, far, next);
        if (far > reach) {
            reach = far;
            if (reach >= window.b) return free;
            continue;
        }
        if (next == none) return free + (window.b - reach);
        free += next - reach;
        if (free > budget) return free;
        reach = next;  // (the next hop extends it over the shadows starting there)
    }
    std::sort(shadows, shadows + m, [](const OffsetInterval& x, const OffsetInterval& y) { return x.a < y.a; });
    for (const OffsetInterval& sh : std::span<const OffsetInterval>(shadows, m)) {
        if (sh.a > reach) {
            free += sh.a - reach;
            if (free > budget) return free;
        }
        reach = std::max(reach, sh.b);
        if (reach >= window.b) return free;
    }
    return free + (window.b - reach);
}

namespace {

using Interval = DirectionBoundsScratch::Interval;
using Bin = DirectionBoundsScratch::Bin;

// Bins the range starts with (direction_bounds.h): enough to see where the
// shadows' ends are. The refinement then halves the bins with the widest
// gaps, so a coarse start can close the bounds with some bins still wide,
// where the midpoint of the bounds is least accurate. Measured on the 1000-segment forest of
// `scripts/bench versus` (eps 2 / 1 / 0.1, medians of 3): 8 bins 0.40 /
// 0.60 / 2.05 s at relative L2 1.8e-2 / 1.0e-2 / 2.2e-3; 16 bins 0.43 /
// 0.63 / 2.04 s at 9.5e-3 / 6.0e-3 / 1.8e-3 (the same errors as exact
// visibility at half the eps); 32 bins 0.53 / 0.74 / 2.26 s at 8.8e-3 /
// 5.5e-3 / 1.8e-3; 4 bins 2.0e-2 at eps 1. (Those were tight queries,
// where bins are halved anyway; loose ones, DirectionBoundsOptions, start
// from fewer.)

// Length of w left by the first m `shadows` (reordered). By hops first
// (gaps_in_window): a bin's shadows in a dense forest cover its window in
// a few, where a sort compares each ~log2(n) times, with branches it
// mispredicts. The 1000-segment forest of `scripts/bench versus` at eps
// 12, in-process medians of 9 runs, 15 rounds alternating: 87-91 ms
// against 91-93 ms on one thread (the rounds the machine did not slow),
// ~1% on two, with 1.2% more instructions (callgrind) than with std::sort
// and a sweep; the answers within rounding (1e-14 relative).
double free_length(Interval w, Interval* shadows, size_t m) {
    if (!(w.b > w.a)) return 0;  // (also not finite)
    return gaps_in_window(w, shadows, m, std::numeric_limits<double>::infinity());
}

struct Evaluator {
    const std::vector<Vec2>& pts;       // shaft-centred frame: A0 A1 C0 C1, then pieces' ends
    const std::vector<double>& radius;  // |P| of each
    std::vector<Interval>& wide_shadows;
    std::vector<Interval>& narrow_shadows;
    std::vector<Interval>& centre_shadows;
    bool estimate;  // also the free length at c itself (bin.centre)

    // lower and upper bounds of free(phi) over [c - h, c + h].
    void operator()(Bin& bin) const {
        const double nx = -std::sin(bin.c), ny = std::cos(bin.c), h = bin.h;
        const size_t n = pts.size();
        const Vec2* P = pts.data();
        const double* R = radius.data();
        auto proj = [&](size_t k) { return nx * P[k].x + ny * P[k].y; };
        // The interval between points k and k + 1 at any direction of the
        // bin: always inside `wide`, always containing `narrow` (if any).
        auto wide = [&](size_t k) { return swept(proj(k), R[k] * h, proj(k + 1), R[k + 1] * h); };
        auto narrow = [&](size_t k) { return held(proj(k), R[k] * h, proj(k + 1), R[k + 1] * h); };
        const Interval ai = wide(0), aj = wide(2), ni = narrow(0), nj = narrow(2);
        const Interval window_wide{std::max(ai.a, aj.a), std::min(ai.b, aj.b)};
        const Interval window_narrow{std::max(ni.a, nj.a), std::min(ni.b, nj.b)};
        // At the bin's centre direction itself (no drift): the midpoint
        // rule's sample (DirectionBounds::estimate), asked for or not.
        auto at_centre = [](double p, double q) { return Interval{std::min(p, q), std::max(p, q)}; };
        Interval window_centre{0, 0};
        if (estimate) {
            const Interval ci = at_centre(proj(0), proj(1)), cj = at_centre(proj(2), proj(3));
            window_centre = {std::max(ci.a, cj.a), std::min(ci.b, cj.b)};
        }
        // Fewest free lines: the narrow window, wide shadows; most: the
        // wide window, narrow shadows. Each piece's two shadows are written
        // in place and kept by advancing the count (no branch on whether
        // they meet the window, about half do, unpredictably: & on the
        // comparisons, not &&, which compiles to branches), in the same
        // order as before. The 1000-segment forest at eps 12, in-process
        // medians of 7 runs, 5 rounds alternating, one thread: 75.8-77.3
        // ms against 77.6-78.2 ms with push_back (callgrind: the bins'
        // evaluation 55 -> 42 M instructions over two solves), the same
        // answers bit for bit; on two threads within the noise.
        const size_t pieces = n > 4 ? (n - 4) / 2 : 0;
        if (wide_shadows.size() < pieces) wide_shadows.resize(pieces);
        if (narrow_shadows.size() < pieces) narrow_shadows.resize(pieces);
        if (estimate && centre_shadows.size() < pieces) centre_shadows.resize(pieces);
        Interval* ws = wide_shadows.data();
        Interval* ns = narrow_shadows.data();
        Interval* cs = centre_shadows.data();
        size_t mw = 0, mn = 0, mc = 0;
        for (size_t k = 4; k + 1 < n; k += 2) {
            const double p = proj(k), q = proj(k + 1), dp = R[k] * h, dq = R[k + 1] * h;
            const Interval sw = swept(p, dp, q, dq), sn = held(p, dp, q, dq);
            ws[mw] = sw;
            mw += static_cast<size_t>((sw.b > window_narrow.a) & (sw.a < window_narrow.b));
            ns[mn] = sn;
            mn += static_cast<size_t>((sn.b > sn.a) & (sn.b > window_wide.a) & (sn.a < window_wide.b));
            if (estimate) {  // (the same way for every piece of a call)
                const Interval sc = at_centre(p, q);
                cs[mc] = sc;
                mc += static_cast<size_t>((sc.b > window_centre.a) & (sc.a < window_centre.b));
            }
        }
        bin.centre = estimate ? free_length(window_centre, cs, mc) : 0.0;
        bin.lower = free_length(window_narrow, ws, mw);
        bin.upper = free_length(window_wide, ns, mn);
        bin.lower = std::min(bin.lower, bin.upper);
    }
};

// The bin whose gap h (upper - lower) is largest on top.
bool smaller_gap(const Bin& x, const Bin& y) { return x.h * (x.upper - x.lower) < y.h * (y.upper - y.lower); }

}  // namespace

DirectionBounds direction_bounds(const Segment& ci, const Segment& cj, const Segment* pieces, size_t count,
                                 double tol, long max_evaluations, DirectionBoundsScratch& ws,
                                 const DirectionBoundsOptions& how) {
    DirectionBounds out;
    const shaft_detail::PairFrame frame(ci, cj);
    auto& pts = ws.points;
    pts.clear();
    for (Vec2 P : {ci.a, ci.b, cj.a, cj.b}) pts.push_back(frame.local(P));
    for (size_t q = 0; q < count; ++q) {
        pts.push_back(frame.local(pieces[q].a));
        pts.push_back(frame.local(pieces[q].b));
    }
    // The range of directions of lines meeting both patches, in the frame
    // (shaft.h): [-delta_theta, delta_theta].
    const double phi_lo = -frame.delta_theta, phi_hi = frame.delta_theta;
    if (!(phi_hi > phi_lo)) {
        out.converged = true;
        return out;
    }
    // Rotate about the centre of the patches' box: the smallest drifts.
    Box box;
    for (size_t k = 0; k < 4; ++k) box.add(pts[k]);
    const Vec2 centre = box.center();
    auto& radius = ws.radius;
    radius.resize(pts.size());
    for (size_t k = 0; k < pts.size(); ++k) {
        pts[k] = pts[k] - centre;
        radius[k] = norm(pts[k]);
    }

    const Evaluator eval{pts, radius, ws.intervals, ws.narrow_intervals, ws.centre_intervals, how.estimate};
    auto& bins = ws.bins;
    bins.clear();
    double lo = 0, hi = 0;  // running sums: they only steer the refinement
    auto add = [&](Bin bin) {
        eval(bin);
        ++out.evaluations;
        lo += bin.h * bin.lower;
        hi += bin.h * bin.upper;
        bins.push_back(bin);
        std::push_heap(bins.begin(), bins.end(), smaller_gap);
    };
    const int initial_bins = std::max(1, how.initial_bins);
    const double h0 = (phi_hi - phi_lo) / (2 * initial_bins);
    for (int b = 0; b < initial_bins; ++b) add({phi_lo + (2 * b + 1) * h0, h0, 0, 0, 0});
    while (hi - lo > 2 * tol && out.evaluations + 2 <= max_evaluations) {
        std::pop_heap(bins.begin(), bins.end(), smaller_gap);
        const Bin worst = bins.back();
        bins.pop_back();
        lo -= worst.h * worst.lower;
        hi -= worst.h * worst.upper;
        add({worst.c - 0.5 * worst.h, 0.5 * worst.h, 0, 0, 0});
        add({worst.c + 0.5 * worst.h, 0.5 * worst.h, 0, 0, 0});
    }
    // The sums again, compensated, from the bins themselves.
    CompensatedSum l, u, m;
    for (const Bin& b : bins) {
        l.add(b.h * b.lower);
        u.add(b.h * b.upper);
        m.add(b.h * b.centre);
    }
    out.lo = std::max(0.0, l.value());
    out.hi = std::max(out.lo, u.value());
    if (how.estimate) out.estimate = std::clamp(m.value(), out.lo, out.hi);
    out.converged = out.hi - out.lo <= 2 * tol;
    return out;
}

}  // namespace flatrad
