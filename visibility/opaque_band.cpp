#include "visibility/opaque_band.h"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__AVX__)
#include <immintrin.h>
#endif

#include "visibility/shaft.h"

namespace flatrad {

size_t held_in_window(const OpaqueBandScratch::Item* items, size_t count, Vec2 n, double h, OffsetInterval window,
                      OffsetInterval* kept) {
    const double nx = n.x, ny = n.y;
    size_t m = 0;
    size_t it = 0;
#if defined(__AVX__)
    // Four items a step, each with the scalar loop's operations below in
    // the same order (products, then their sum; _mm256_min_pd(y, x) is
    // std::min(x, y) and _mm256_max_pd(y, x) std::max(x, y), NaN and signed
    // zeros included), so the shadows kept are the same bit for bit, in the
    // same order. (This loop was about a third of band_bound's samples on
    // the 10^6 forest, whose proofs' sections hold tens of pieces.)
    static_assert(sizeof(OpaqueBandScratch::Item) == 6 * sizeof(double), "p.x p.y q.x q.y rp rq, packed");
    static_assert(sizeof(OffsetInterval) == 2 * sizeof(double), "a, b packed");
    {
        const __m256d vnx = _mm256_set1_pd(nx), vny = _mm256_set1_pd(ny), vh = _mm256_set1_pd(h);
        const __m256d wa = _mm256_set1_pd(window.a), wb = _mm256_set1_pd(window.b);
        for (; it + 4 <= count; it += 4) {
            const double* e = &items[it].p.x;
            // Four items' (p.x, p.y, q.x, q.y) as rows, transposed.
            const __m256d r0 = _mm256_loadu_pd(e), r1 = _mm256_loadu_pd(e + 6);
            const __m256d r2 = _mm256_loadu_pd(e + 12), r3 = _mm256_loadu_pd(e + 18);
            const __m256d x01 = _mm256_unpacklo_pd(r0, r1), y01 = _mm256_unpackhi_pd(r0, r1);  // px0 px1 qx0 qx1
            const __m256d x23 = _mm256_unpacklo_pd(r2, r3), y23 = _mm256_unpackhi_pd(r2, r3);
            const __m256d px = _mm256_permute2f128_pd(x01, x23, 0x20), qx = _mm256_permute2f128_pd(x01, x23, 0x31);
            const __m256d py = _mm256_permute2f128_pd(y01, y23, 0x20), qy = _mm256_permute2f128_pd(y01, y23, 0x31);
            // Their (rp, rq).
            const __m256d s02 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(e + 4)), _mm_loadu_pd(e + 16), 1);
            const __m256d s13 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(e + 10)), _mm_loadu_pd(e + 22), 1);
            const __m256d rp = _mm256_unpacklo_pd(s02, s13), rq = _mm256_unpackhi_pd(s02, s13);
            const __m256d pp = _mm256_add_pd(_mm256_mul_pd(vnx, px), _mm256_mul_pd(vny, py));
            const __m256d pq = _mm256_add_pd(_mm256_mul_pd(vnx, qx), _mm256_mul_pd(vny, qy));
            const __m256d dp = _mm256_mul_pd(rp, vh), dq = _mm256_mul_pd(rq, vh);
            // held(): {min(pp + dp, pq + dq), max(pp - dp, pq - dq)}.
            const __m256d a = _mm256_min_pd(_mm256_add_pd(pq, dq), _mm256_add_pd(pp, dp));
            const __m256d b = _mm256_max_pd(_mm256_sub_pd(pq, dq), _mm256_sub_pd(pp, dp));
            const __m256d keep = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(b, a, _CMP_GT_OQ), _mm256_cmp_pd(b, wa, _CMP_GT_OQ)),
                                               _mm256_cmp_pd(a, wb, _CMP_LT_OQ));
            const int bits = _mm256_movemask_pd(keep);
            const __m256d ab02 = _mm256_unpacklo_pd(a, b), ab13 = _mm256_unpackhi_pd(a, b);  // a0 b0 a2 b2, a1 b1 a3 b3
            _mm_storeu_pd(&kept[m].a, _mm256_castpd256_pd128(ab02));
            m += static_cast<size_t>(bits & 1);
            _mm_storeu_pd(&kept[m].a, _mm256_castpd256_pd128(ab13));
            m += static_cast<size_t>((bits >> 1) & 1);
            _mm_storeu_pd(&kept[m].a, _mm256_extractf128_pd(ab02, 1));
            m += static_cast<size_t>((bits >> 2) & 1);
            _mm_storeu_pd(&kept[m].a, _mm256_extractf128_pd(ab13, 1));
            m += static_cast<size_t>((bits >> 3) & 1);
        }
    }
#endif
    for (; it < count; ++it) {
        const OpaqueBandScratch::Item& e = items[it];
        const OffsetInterval sh = held(nx * e.p.x + ny * e.p.y, e.rp * h, nx * e.q.x + ny * e.q.y, e.rq * h);
        kept[m] = sh;
        // (& on the comparisons, not &&: no branch, which the data would
        // make unpredictable.)
        m += static_cast<size_t>((sh.b > sh.a) & (sh.b > window.a) & (sh.a < window.b));
    }
    return m;
}

namespace {

using Interval = OpaqueBandScratch::Interval;
using Band = OpaqueBandScratch::Band;

constexpr double not_shown = std::numeric_limits<double>::infinity();

// Points of a section before its pieces' ends (Band::head): its own two
// ends, two points of the lower side and two of the upper, then the ends of
// patch i and of patch j; about the section's midpoint.
constexpr size_t section_head = 10;

// The y at depth t of the line through p and q (a side of the shaft, whose
// ends lie on either side of every depth between the patches).
double y_at(double t, Vec2 p, Vec2 q) { return p.y + (t - p.x) / (q.x - p.x) * (q.y - p.y); }

// Upper bound on the free length of section s of the band at every
// direction of [c - h, c + h]: the length, among the lines that cross the
// section, stay inside the shaft over the band's depths and meet both
// patches, of those the pieces bucketed to it may leave open. Each point's
// offset n(phi) . P (about the section's midpoint) is within |P| h of its
// value at c; the lines to stop are widened by that, each piece's shadow
// narrowed by it (what it shadows at every direction of the bin). Stops
// once the free length exceeds `budget` (and returns what it has, >
// budget). Anything not finite gives +infinity.
double uncovered(const Band& band, int s, Vec2 n, double h, const OpaqueBandScratch::Item* items, size_t count,
                 double budget, OpaqueBandScratch& ws) {
    const double nx = n.x, ny = n.y;
    const Vec2* P = ws.points.data() + band.head + section_head * static_cast<size_t>(s);
    const double* R = ws.radius.data() + band.head + section_head * static_cast<size_t>(s);
    auto proj = [&](size_t k) { return nx * P[k].x + ny * P[k].y; };
    auto wide = [&](size_t k) { return swept(proj(k), R[k] * h, proj(k + 1), R[k + 1] * h); };
    // Lines across the section (points 0, 1), above the lower side at the
    // band's outer depths (points 2, 3), below the upper side there (4, 5),
    // meeting patch i (6, 7) and patch j (8, 9). The section's own ends are
    // widened too: the sections tile X at the bin's centre direction only,
    // and elsewhere in the bin a line through a boundary between two
    // sections can fall outside both unwidened windows.
    Interval window = wide(0);
    for (const size_t k : {size_t{2}, size_t{3}}) window.a = std::max(window.a, proj(k) - R[k] * h);
    for (const size_t k : {size_t{4}, size_t{5}}) window.b = std::min(window.b, proj(k) + R[k] * h);
    for (const size_t k : {size_t{6}, size_t{8}}) {
        const Interval patch = wide(k);
        window = {std::max(window.a, patch.a), std::min(window.b, patch.b)};
    }
    if (!(window.b > window.a)) return window.b <= window.a ? 0 : not_shown;  // no line to stop, or not finite
    // The pieces' shadows, about the section's midpoint (bucket_band made
    // the items' ends relative to it).
    auto& shadows = ws.shadows;
    if (shadows.size() < count) shadows.resize(count);
    const size_t m = held_in_window(items, count, n, h, window, shadows.data());
    // The gaps between the shadows, summed (not the window less the covered
    // length: a covered window gives exactly 0).
    return gaps_in_window(window, shadows.data(), m, budget);
}

// Buckets band k's pieces by section for every direction of [c_lo, c_hi]
// (a group of consecutive bins of half-width h), a filter only: a piece
// left out of a section only leaves more free, one put in needlessly
// costs a look. About X's midpoint (t0, ym) a point (t0, y) of X is at
// cos(c) (y - ym) at direction c, so section s spans [s - S/2, s + 1 -
// S/2] cos(c) w, widened by its ends' drift w h / 2 within a bin; a
// piece's shadow at c lies between its ends' offsets n(c) . (P - M) (its
// held shadow within that), each within |P - M| |c - cm| of its value at
// the group's middle direction cm (a rotation by c - cm moves a
// projection by at most the vector's length times the angle), and cos(c)
// lies between its least and largest over the group.
void bucket_band(const Band& band, OpaqueBandScratch::Buckets& bb, double c_lo, double c_hi, double h,
                 OpaqueBandScratch& ws) {
    const double cm = 0.5 * (c_lo + c_hi), hr = 0.5 * (c_hi - c_lo);
    const double nx = -std::sin(cm), ny = std::cos(cm), pad = 0.5 * band.w * h;
    const double cos_least = std::min(std::cos(c_lo), std::cos(c_hi));
    const double cos_most = c_lo <= 0 && c_hi >= 0 ? 1.0 : std::max(std::cos(c_lo), std::cos(c_hi));
    const double span_lo = cos_least * band.w, span_hi = cos_most * band.w;
    const int S = band.sections;
    const Vec2 M{band.t0, band.ya + 0.5 * S * band.w};
    auto& first_of = bb.first;
    auto& items = bb.items;
    auto& range = ws.bucket_range;
    first_of.assign(static_cast<size_t>(S) + 1, 0);
    range.resize(band.last - band.first);
    // (The band's ends in run order: build_band. Each item keeps its
    // piece's ends about its section's midpoint.)
    const Vec2* end = ws.run_ends.data() + band.ends_first;
    for (size_t r = band.first; r < band.last; ++r, end += 2) {
        const Vec2 p = end[0] - M, q = end[1] - M;
        const double pp = nx * p.x + ny * p.y, pq = nx * q.x + ny * q.y;
        const double turn = std::sqrt(std::max(norm_squared(p), norm_squared(q))) * hr;  // (the larger norm)
        const double L = std::min(pp, pq) - turn - pad, H = std::max(pp, pq) + turn + pad;
        const double lo = std::floor(std::min(L / span_lo, L / span_hi) + 0.5 * S);
        const double hi = std::floor(std::max(H / span_lo, H / span_hi) + 0.5 * S);
        const int a = static_cast<int>(std::clamp(lo, 0.0, static_cast<double>(S)));
        const int b = static_cast<int>(std::clamp(hi, -1.0, S - 1.0));
        range[r - band.first] = {a, b};
        for (int sct = a; sct <= b; ++sct) ++first_of[static_cast<size_t>(sct) + 1];
    }
    for (int sct = 0; sct < S; ++sct) first_of[static_cast<size_t>(sct) + 1] += first_of[static_cast<size_t>(sct)];
    items.resize(first_of[static_cast<size_t>(S)]);
    auto& fill = ws.bucket_fill;
    fill.assign(first_of.begin(), first_of.end() - 1);
    const Vec2* ends = ws.run_ends.data() + band.ends_first;
    for (size_t r = band.first; r < band.last; ++r) {
        const auto [a, b] = range[r - band.first];
        const size_t item = r - band.first;
        for (int sct = a; sct <= b; ++sct) {
            const Vec2 O{band.t0, band.ya + (sct + 0.5) * band.w};  // section sct's midpoint (uncovered's)
            const Vec2 p = ends[2 * item] - O, q = ends[2 * item + 1] - O;
            items[fill[static_cast<size_t>(sct)]++] = {p, q, norm(p), norm(q)};
        }
    }
}

// How far (in sections' widths) a piece may turn within one bucketing's
// group of bins. Bucketing costs about as much per piece as a section's
// check, and a wider turn puts a piece in a section or two more: replaying
// the 15 495 band_bound calls of the 10^4 forest at eps 10 (one thread,
// medians of 5, the same answers at every value) took 1.07 s at 0.5, 0.97
// s at 1, 0.94 s at 2, 0.95 s at 3, 1.00 s at 4, 1.02 s with one
// bucketing per call; the 952 calls of the 1000-segment forest at eps 5
// 27 / 24 / 22 / 23 ms at 0.5 / 1 / 2 / 3.
constexpr double bucket_group_turn = 2;

// Bins per bucketing of band k: as many as keep each piece's turn within
// the group (|P - M| times half the group's angle) under bucket_group_turn
// sections' widths, so that a piece lands in at most about twice that many
// sections more than at the group's middle direction (that many on either
// side). (Bucketing every bin anew took a third of band_bound's samples on
// the 10^5 forest, where the bins of a long shaft's proof barely turn; once
// per group, with the ends' distances kept for uncovered: band_bound 8.4%
// fewer instructions on a 3x10^4 forest at eps 10, the same answers.)
int bucket_group_size(const Band& band, double h, int bins, const OpaqueBandScratch& ws) {
    const Vec2 M{band.t0, band.ya + 0.5 * band.sections * band.w};
    double reach2 = 0;  // the largest |P - M|^2 (one root below, as bucket_band's turn)
    const Vec2* end = ws.run_ends.data() + band.ends_first;
    for (size_t r = band.first; r < band.last; ++r, end += 2)
        reach2 = std::max({reach2, norm_squared(end[0] - M), norm_squared(end[1] - M)});
    const double reach = std::sqrt(reach2);
    const double g = std::floor(bucket_group_turn * band.w / (reach * h));
    return std::isfinite(g) ? static_cast<int>(std::clamp(g, 1.0, static_cast<double>(bins))) : (g > 0 ? bins : 1);
}

// The band's free length at every direction of [c - hh, c + hh], a part
// of bin b (of `bins`, half-width h, over [-delta, delta]; the whole bin
// or one of its halves), summed over its sections; more than `bar` (and
// so stopped early, the sum unfinished) when it exceeds bar. The pieces
// are bucketed for b's group of bins, which holds every direction of the
// part; a part narrower than the bin drifts less, which only narrows what
// the buckets must hold.
double band_free(const Band& band, OpaqueBandScratch::Buckets& bb, int b, int bins, double delta, double h, double c,
                 double hh, double bar, OpaqueBandScratch& ws) {
    if (bb.group_size == 0) bb.group_size = bucket_group_size(band, h, bins, ws);
    const int group = b / bb.group_size;
    if (bb.group != group) {
        const int b0 = group * bb.group_size, b1 = std::min(bins, b0 + bb.group_size);
        bucket_band(band, bb, -delta + 2 * b0 * h, -delta + 2 * b1 * h, h, ws);
        bb.group = group;
    }
    const Vec2 n{-std::sin(c), std::cos(c)};  // the part's centre direction's normal, for every section
    const int S = band.sections;
    double sum = 0;
    for (int sct = 0; sct < S && sum <= bar; ++sct) {
        const size_t f = bb.first[static_cast<size_t>(sct)], l = bb.first[static_cast<size_t>(sct) + 1];
        sum += uncovered(band, sct, n, hh, bb.items.data() + f, l - f, bar - sum, ws);
    }
    return sum;
}

}  // namespace

bool narrower_at_i(const Segment& ci, const Segment& cj) {
    const shaft_detail::PairFrame frame(ci, cj);
    const Vec2 A0 = frame.local(ci.a), A1 = frame.local(ci.b), C0 = frame.local(cj.a), C1 = frame.local(cj.b);
    const auto width_at = [&](double t) { return std::abs(y_at(t, A1, C0) - y_at(t, C1, A0)); };
    return width_at(std::max(A0.x, A1.x)) <= width_at(std::min(C0.x, C1.x));
}

double band_bound(const Segment& ci, const Segment& cj, const Segment* blockers, size_t count,
                  const BandOptions& options, OpaqueBandScratch& ws) {
    const double limit = options.limit;
    if (count == 0 || !(limit >= 0)) return not_shown;
    const shaft_detail::PairFrame frame(ci, cj);
    const double delta = frame.delta_theta;
    if (!(delta > 0) || !std::isfinite(delta)) return not_shown;
    // The shaft A0 A1 C0 C1 in the frame, x the depth along the pair's axis.
    const Vec2 A0 = frame.local(ci.a), A1 = frame.local(ci.b), C0 = frame.local(cj.a), C1 = frame.local(cj.b);
    const double xi = std::max(A0.x, A1.x), xj = std::min(C0.x, C1.x);
    if (!(xj > xi) || !std::isfinite(xj - xi)) return not_shown;  // no transversal x = t0 between them

    // The blockers clipped to the slab xi <= x <= xj: a line from ci to
    // cj is at those depths only between its ends on the patches (its depth
    // grows along it, |phi| < pi/2), so a blocker there stops it wherever
    // the line meets it.
    auto& local = ws.local;
    local.clear();
    for (size_t q = 0; q < count; ++q) {
        const Vec2 P = frame.local(blockers[q].a), Q = frame.local(blockers[q].b);
        if (!(std::isfinite(P.x) && std::isfinite(P.y) && std::isfinite(Q.x) && std::isfinite(Q.y))) continue;
        double t_lo = 0, t_hi = 1;
        if (P.x != Q.x) {
            const double ta = (xi - P.x) / (Q.x - P.x), tb = (xj - P.x) / (Q.x - P.x);
            t_lo = std::max(t_lo, std::min(ta, tb));
            t_hi = std::min(t_hi, std::max(ta, tb));
        } else if (!(P.x >= xi && P.x <= xj)) {
            continue;
        }
        if (!(t_hi > t_lo)) continue;
        local.push_back(lerp(P, Q, t_lo));
        local.push_back(lerp(P, Q, t_hi));
    }
    const size_t n = local.size() / 2;
    if (n == 0) return not_shown;
    {
        // Layers over the whole slab: the pieces' shadows across the axis
        // over the shaft's mean width. A band holds a share of them; with
        // few in all, no band closes the shaft and the attempt is skipped.
        double across = 0;
        for (size_t q = 0; q < n; ++q) across += std::abs(local[2 * q + 1].y - local[2 * q].y);
        // Where the caller chose the bands' depths it passed the pieces
        // around them alone: enough layers for one band at its section,
        // the narrowest of theirs.
        const auto width_at = [&](double t) { return std::abs(y_at(t, A1, C0) - y_at(t, C1, A0)); };
        double width = 0.5 * (width_at(xi) + width_at(xj));
        if (options.depths) {
            width = not_shown;
            for (int k = 0; k < opaque_band_count; ++k)
                width = std::min(width, width_at(std::clamp(options.depths[k], xi, xj)));
        }
        if (!(across >= opaque_band_min_layers * width)) return not_shown;
    }
    // The pieces by the depth of their midpoints: a band is a run of them
    // around its depth. Only the runs are needed in order (a band takes a
    // few hundred pieces of a shaft's thousands): the pieces go to buckets
    // of depth (a counting sort), and a bucket is sorted when a band first
    // reads a place in it. A bucket's pieces lie between those of the
    // buckets before and after it, so every place a band reads holds what
    // the whole array sorted at once would (up to the order of equal
    // depths, which std::sort leaves unspecified anyway). (Sorting all of
    // them was 3% of the 3x10^4 forest's samples at eps 10.)
    auto& by_depth = ws.by_depth;
    by_depth.resize(n);
    const size_t wanted_buckets = std::max<size_t>(1, n / std::max<size_t>(1, options.depth_bucket));
    const double to_bucket = static_cast<double>(wanted_buckets) / (xj - xi);
    const size_t buckets = std::isfinite(to_bucket) ? wanted_buckets : 1;
    const double top = static_cast<double>(buckets - 1);
    // Non-decreasing in the depth (each step is), so the buckets keep the
    // depths' order.
    auto bucket_of = [&](double mid) {
        return buckets == 1 ? size_t{0} : static_cast<size_t>(std::clamp((mid - xi) * to_bucket, 0.0, top));
    };
    auto& first_of = ws.depth_first;
    first_of.assign(buckets + 1, 0);
    auto& mids = ws.depth_mid;
    mids.resize(n);
    for (size_t q = 0; q < n; ++q) {
        mids[q] = 0.5 * (local[2 * q].x + local[2 * q + 1].x);
        ++first_of[bucket_of(mids[q]) + 1];
    }
    for (size_t b = 0; b < buckets; ++b) first_of[b + 1] += first_of[b];
    {
        auto& fill = ws.depth_fill;
        fill.assign(first_of.begin(), first_of.end() - 1);
        for (size_t q = 0; q < n; ++q) by_depth[fill[bucket_of(mids[q])]++] = {mids[q], q};
    }
    auto& sorted = ws.depth_sorted;
    sorted.assign(buckets, 0);
    auto sort_bucket = [&](size_t b) {
        if (sorted[b]) return;
        std::sort(by_depth.begin() + static_cast<std::ptrdiff_t>(first_of[b]),
                  by_depth.begin() + static_cast<std::ptrdiff_t>(first_of[b + 1]),
                  [](const auto& x, const auto& y) { return x.mid < y.mid; });
        sorted[b] = 1;
    };
    // The piece at place p of the sorted order.
    auto at = [&](size_t p) -> const OpaqueBandScratch::Depth& {
        sort_bucket(bucket_of(by_depth[p].mid));
        return by_depth[p];
    };

    ws.points.clear();
    ws.radius.clear();
    ws.run_ends.clear();
    auto& bands = ws.bands;
    bands.clear();
    // Band k (the middle one first); returns the widest bin half-width at
    // which its pieces drift by at most options.drift of their mean shadow
    // (0: no piece).
    auto build_band = [&](int k) {
        const double t0 = options.depths ? std::clamp(options.depths[k], xi, xj) : band_depth(k, xi, xj);
        // The shaft's sides are the edges A1 -> C0 and C1 -> A0, the only
        // two that cross x = t for t between the patches.
        const bool side1_low = y_at(t0, A1, C0) <= y_at(t0, C1, A0);
        auto low_side = [&](double t) { return side1_low ? y_at(t, A1, C0) : y_at(t, C1, A0); };
        auto high_side = [&](double t) { return side1_low ? y_at(t, C1, A0) : y_at(t, A1, C0); };
        const double ya = low_side(t0), yb = high_side(t0);
        // Pieces nearest in depth, until their shadows across the axis add
        // up to opaque_band_layers times the section X (or to
        // opaque_band_max_pieces).
        const double needed = opaque_band_layers * (yb - ya);
        // The first place at or past t0: in t0's bucket (the buckets before
        // it hold only depths below t0, those after only depths above).
        const size_t b0 = bucket_of(t0);
        sort_bucket(b0);
        size_t right = static_cast<size_t>(
            std::lower_bound(by_depth.begin() + static_cast<std::ptrdiff_t>(first_of[b0]),
                             by_depth.begin() + static_cast<std::ptrdiff_t>(first_of[b0 + 1]), t0,
                             [](const auto& d, double t) { return d.mid < t; }) -
            by_depth.begin());
        size_t left = right;                  // the run taken is by_depth[left, right)
        double across = 0, before = 0, after = 0;  // before, after: the run's reach in depth
        auto take_piece = [&](size_t q) {
            across += std::abs(local[2 * q + 1].y - local[2 * q].y);
            before = std::max({before, t0 - local[2 * q].x, t0 - local[2 * q + 1].x});
            after = std::max({after, local[2 * q].x - t0, local[2 * q + 1].x - t0});
        };
        while (across < needed && right - left < opaque_band_max_pieces && (left > 0 || right < n)) {
            const bool take_left = right == n || (left > 0 && t0 - at(left - 1).mid < at(right).mid - t0);
            take_piece(take_left ? at(--left).piece : at(right++).piece);
        }
        // Pieces as near in depth as the farthest taken (a row of them at
        // one depth, as in a blind) are taken too: which of a row's ties
        // came first depends on the last bits of the coordinates, and a run
        // cut inside the row would make the bound depend on them (on how
        // the scene is scaled or placed).
        if (right > left) {
            const double reach = std::max(t0 - at(left).mid, at(right - 1).mid - t0);
            const double tie = reach + 1e-9 * (xj - xi);
            while (left > 0 && t0 - at(left - 1).mid <= tie) take_piece(at(--left).piece);
            while (right < n && at(right).mid - t0 <= tie) take_piece(at(right++).piece);
        }
        const size_t taken = right - left;
        if (taken == 0 || !(across > 0)) return 0.0;
        // The run's ends, in run order, for band_free's bins and their
        // sections: read in sequence there, bin after bin.
        const size_t ends_first = ws.run_ends.size();
        for (size_t r = left; r < right; ++r) {
            const size_t q = by_depth[r].piece;
            for (size_t end = 0; end < 2; ++end)
                ws.run_ends.push_back(local[2 * q + end]);
        }
        // X in sections a few mean shadows wide, each turned about its own
        // midpoint: the drift grows with the distance to the centre.
        const double mean_shadow = across / static_cast<double>(taken);
        const double wanted = std::ceil((yb - ya) / (opaque_band_section_shadows * mean_shadow));
        const int S = static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(opaque_band_max_sections)));
        const double w = (yb - ya) / S;
        bands.push_back({t0, ya, w, S, left, right, ws.points.size(), ends_first});
        for (int s = 0; s < S; ++s) {
            const double y0 = ya + w * s, y1 = ya + w * (s + 1);
            const Vec2 O{t0, 0.5 * (y0 + y1)};
            auto add = [&](Vec2 p) {
                ws.points.push_back(p - O);
                ws.radius.push_back(norm(p - O));
            };
            add({t0, y0});
            add({t0, y1});
            // A line from ci to cj stays inside the shaft at every depth of
            // the slab, so at the run's outer depths it passes above the
            // lower side and below the upper: lines outside those (which
            // pieces inside the shaft need not stop) are not asked for.
            for (const double t : {t0 - before, t0 + after}) add({t, low_side(t)});
            for (const double t : {t0 - before, t0 + after}) add({t, high_side(t)});
            for (const Vec2 end : {A0, A1, C0, C1}) add(end);
        }
        // A piece's ends are within the band's depth of t0, and (where they
        // matter) about a section's width of its midpoint.
        const double reach = std::hypot(std::max(before, after), 0.5 * w + mean_shadow);
        return reach > 0 ? options.drift * mean_shadow / reach : 0.0;
    };

    // The bins: at least opaque_band_initial_bins, narrow enough for the
    // middle band. Each bin takes the least of the bands' free lengths (each
    // band alone stops all but its own free lines); the other bands are
    // built when a bin needs them. The first bin that takes the sum past
    // the limit, even in halves (below), ends the attempt (an open shaft
    // usually shows it within a few bins).
    const double h_band = build_band(0);
    if (!(h_band > 0)) return not_shown;
    const double bins_wanted = std::max<double>(opaque_band_initial_bins, std::ceil(delta / h_band));
    if (!(bins_wanted <= opaque_band_max_bins)) return not_shown;  // too costly (or not finite)
    if (!(bins_wanted * bands[0].sections <= options.max_checks)) return not_shown;
    const int bins = static_cast<int>(bins_wanted);
    const double h = delta / bins;
    double total = 0;  // the sum over bins of h times the bin's free length
    for (auto& bb : ws.buckets) {
        bb.group = -1;  // none made for these bands yet
        bb.group_size = 0;
    }
    // settle(b, c, hh, d, room): the part [c - hh, c + hh] of bin b, hh
    // times the least of the bands' free lengths there (each band alone
    // stops all but its own free lines), building the next band only when
    // the ones before leave some free. Where that exceeds room, the part is
    // checked again in halves (a gap may be the drift's, not the bands':
    // opaque_band_halvings), each half that exceeds what is left halved
    // again, d times at most: the sum over the halves. not_shown when it
    // exceeds room.
    int tried = 1;  // bands built or found empty (band 0 above)
    auto settle = [&](auto&& self, int b, double c, double hh, int d, double room) -> double {
        const double allowance = room / hh;  // the most the part may leave free
        double least = not_shown;
        for (int k = 0; k < opaque_band_count && least > 0; ++k) {
            if (k == static_cast<int>(bands.size())) {
                if (k < tried) break;  // no piece
                ++tried;
                if (!(build_band(k) > 0)) break;
            }
            const double bar = std::min(least, allowance);
            const double free = band_free(bands[static_cast<size_t>(k)], ws.buckets[static_cast<size_t>(k)], b, bins, delta, h, c,
                                          hh, bar, ws);
            if (free <= bar) least = free;  // finished, and the least so far
        }
        if (least <= allowance) return hh * least;
        if (d <= 0) return not_shown;
        const double h2 = 0.5 * hh;
        const double lower = self(self, b, c - h2, h2, d - 1, room);
        if (lower == not_shown) return not_shown;
        const double upper = self(self, b, c + h2, h2, d - 1, room - lower);
        if (upper == not_shown) return not_shown;
        return lower + upper;
    };
    for (int b = 0; b < bins; ++b) {
        const double part = settle(settle, b, -delta + (2 * b + 1) * h, h, options.halvings, limit - total);
        if (part == not_shown) return not_shown;
        total += part;
    }
    return total;
}

}  // namespace flatrad
