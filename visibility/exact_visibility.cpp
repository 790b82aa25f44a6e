#include "visibility/exact_visibility.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/error.h"
#include "engine/formfactor.h"
#include "visibility/shaft.h"

namespace flatrad {

namespace {
using namespace shaft_detail;

// The line-space integral over the shaft (DESIGN.md §1) with the given
// blocker pieces, all inside the shaft. Returns L_i F_ij.
double integrate(const Segment& ci, const Segment& cj, const std::vector<Segment>& blockers, ExactWorkspace& ws,
                 VisibilityStats& stats) {
    // 1. Frame (shaft.h): directions measured from the pair's own axis.
    const PairFrame frame(ci, cj);
    const Vec2 origin = frame.origin, u = frame.u, v = rot90(u);

    // 2. Points in the frame: A0 A1 C0 C1, then blocker endpoints.
    auto& pts = ws.points;
    pts.clear();
    auto local = [&](Vec2 P) {
        const Vec2 d = P - origin;
        return Vec2{dot(d, u), dot(d, v)};
    };
    pts.push_back(local(ci.a));
    pts.push_back(local(ci.b));
    pts.push_back(local(cj.a));
    pts.push_back(local(cj.b));
    for (const Segment& b : blockers) {
        pts.push_back(local(b.a));
        pts.push_back(local(b.b));
    }
    const size_t npts = pts.size();
    const size_t nblk = blockers.size();
    // The blocker endpoints again, one array per coordinate, for the inner
    // loops over blockers.
    auto& soa = ws.soa;
    soa.resize(4 * nblk);
    double* const bx0 = soa.data();
    double* const by0 = bx0 + nblk;
    double* const bx1 = by0 + nblk;
    double* const by1 = bx1 + nblk;
    for (size_t q = 0; q < nblk; ++q) {
        bx0[q] = pts[4 + 2 * q].x;
        by0[q] = pts[4 + 2 * q].y;
        bx1[q] = pts[5 + 2 * q].x;
        by1[q] = pts[5 + 2 * q].y;
    }

    // Range of slopes: the extreme patch-to-patch directions. An end the
    // two patches share (a room's corner) gives none; in the frame its two
    // copies may differ by a rounding (the frame's dot products contracted
    // differently at each call), so it is recognised by its world point.
    const Vec2 world[4] = {ci.a, ci.b, cj.a, cj.b};
    double s_lo = std::numeric_limits<double>::infinity(), s_hi = -s_lo;
    for (size_t a = 0; a < 2; ++a)
        for (size_t c = 2; c < 4; ++c) {
            const Vec2 w = pts[c] - pts[a];
            if (w == Vec2{} || world[a] == world[c]) continue;
            FLATRAD_ASSERT(w.x > 0, "patch-to-patch direction outside the bisected range");
            const double s = w.y / w.x;
            s_lo = std::min(s_lo, s);
            s_hi = std::max(s_hi, s);
        }
    if (!(s_hi > s_lo)) return 0;

    // p of point k on the line of slope s, up to the positive factor
    // 1/sqrt(1 + s^2) (normal (-s, 1)): enough to compare positions.
    auto overlap_at = [&](double nx, double ny, double& lo, double& hi) {
        double p[4];
        for (size_t k = 0; k < 4; ++k) p[k] = nx * pts[k].x + ny * pts[k].y;
        lo = std::max(std::min(p[0], p[1]), std::min(p[2], p[3]));
        hi = std::min(std::max(p[0], p[1]), std::max(p[2], p[3]));
    };

    // 3. Critical directions: lines through two points, with slope inside
    //    the range, whose crossing happens inside the overlap (elsewhere the
    //    order of what lies in the overlap does not change).
    auto& dirs = ws.directions;
    dirs.clear();
    dirs.push_back(s_lo);
    dirs.push_back(s_hi);
    size_t last_hider = nblk;
    for (size_t a = 0; a < npts; ++a) {
        // Pairs inside one patch never matter: i's own direction is outside
        // the range, and so is j's.
        for (size_t b = std::max(a + 1, a < 4 ? size_t{4} : a + 1); b < npts; ++b) {
            const Vec2 w = pts[b] - pts[a];
            if (w.x == 0) continue;  // direction perpendicular to the axis: outside the range
            const double s = w.y / w.x;
            if (!(s > s_lo && s < s_hi)) continue;
            double lo, hi;
            overlap_at(-s, 1.0, lo, hi);
            const double p = -s * pts[a].x + pts[a].y;
            const double slack = event_slack * (std::abs(hi - lo) + std::abs(p));
            if (p < lo - slack || p > hi + slack) continue;
            // A swap hidden strictly inside a third blocker's shadow changes
            // nothing: near (p, s) every line is stopped by that blocker
            // before and after. Checking the blocker that hid the last one
            // first makes this cheap in dense shafts.
            const size_t own_a = a < 4 ? nblk : (a - 4) / 2, own_b = (b - 4) / 2;
            // (All points lie in the shaft, so their p are of the size of
            // the overlap and p: `slack` serves as the margin.)
            auto hides = [&](size_t q) {
                if (q == own_a || q == own_b) return false;
                const double da = -s * bx0[q] + by0[q] - p;
                const double db = -s * bx1[q] + by1[q] - p;
                return da * db < 0 && std::min(std::abs(da), std::abs(db)) > slack;
            };
            if (last_hider < nblk && hides(last_hider)) continue;
            bool hidden = false;
            for (size_t q = 0; q < nblk && !hidden; ++q)
                if (q != last_hider && hides(q)) {
                    hidden = true;
                    last_hider = q;
                }
            if (hidden) continue;
            dirs.push_back(s);
        }
    }
    // The patch-to-patch pairs (a < 2 <= b < 4) are the range's own ends or
    // the switches of which endpoints bound the overlap.
    for (size_t a = 0; a < 2; ++a)
        for (size_t b = 2; b < 4; ++b) {
            const Vec2 w = pts[b] - pts[a];
            if (w.x <= 0) continue;
            const double s = w.y / w.x;
            if (s > s_lo && s < s_hi) dirs.push_back(s);
        }
    std::sort(dirs.begin(), dirs.end());
    stats.events += static_cast<long>(dirs.size());

    // 4. Integrate arc by arc: on (s0, s1) the free measure is W . n(phi), so
    //    Integral = W . (d(phi1) - d(phi0)) = 2 sin(dphi / 2) m(phi_mid).
    auto& order = ws.order;
    order.resize(nblk);
    for (size_t k = 0; k < nblk; ++k) order[k] = static_cast<int32_t>(k);
    ws.proj.resize(2 * nblk);
    double* const iv_start = ws.proj.data();
    double* const iv_end = iv_start + nblk;
    double total = 0, comp = 0;  // Kahan-compensated sum over arcs
    for (size_t k = 0; k + 1 < dirs.size(); ++k) {
        const double s0 = dirs[k], s1 = dirs[k + 1];
        if (!(s1 > s0)) continue;
        // dphi from the slopes: tan(dphi) = (s1 - s0) / (1 + s0 s1); the
        // difference of slopes stays accurate when the range is tiny.
        const double dphi = std::atan2(s1 - s0, 1 + s0 * s1);
        const double r0 = 1 / std::sqrt(1 + s0 * s0), r1 = 1 / std::sqrt(1 + s1 * s1);
        Vec2 dm{r0 + r1, s0 * r0 + s1 * r1};  // bisector of the unit directions
        dm = dm / norm(dm);
        const double nx = -dm.y, ny = dm.x;
        double lo, hi;
        overlap_at(nx, ny, lo, hi);
        if (!(hi > lo)) continue;
        double blocked = 0;
        if (nblk > 0) {
            double* const start = iv_start;
            double* const end = iv_end;
            for (size_t q = 0; q < nblk; ++q) {
                const double pa = nx * bx0[q] + ny * by0[q];
                const double pb = nx * bx1[q] + ny * by1[q];
                start[q] = std::max(std::min(pa, pb), lo);
                end[q] = std::min(std::max(pa, pb), hi);
            }
            // Insertion sort by start: the order changes little between arcs.
            for (size_t q = 1; q < nblk; ++q) {
                const int32_t key = order[q];
                const double ks = start[key];
                size_t r = q;
                while (r > 0 && start[order[r - 1]] > ks) {
                    order[r] = order[r - 1];
                    --r;
                }
                order[r] = key;
            }
            double reach = lo;
            for (size_t q = 0; q < nblk; ++q) {
                const double bs = start[order[q]], be = end[order[q]];
                if (be <= reach || be <= bs) continue;  // covered already, or outside the overlap
                blocked += be - std::max(bs, reach);
                reach = be;
            }
        }
        const double free_len = std::max(0.0, (hi - lo) - blocked);
        const double term = 2 * std::sin(dphi / 2) * free_len - comp;
        const double t = total + term;
        comp = (t - total) - term;
        total = t;
    }
    return total / 2;
}

// Shafts holding more than this many blocker pieces are split in two (the
// longer patch halved) before integrating: the critical directions grow as
// the square of the pieces, and halves hold fewer pieces, see a narrower
// range of directions and are often closed by one blocker. Measured on the
// 1840-patch room benchmark; any value gives the same answer.
constexpr size_t split_threshold = 16;
// A split whose halves keep more than this share of the pieces stops.
constexpr double split_keep_ratio = 0.8;
// Depth cap of the splitting (2^12 sub-shafts at most per pair).
constexpr int max_split_depth = 12;

// L_i F_ij for a mutually facing pair (ci, cj) whose shaft contains no
// blocker piece other than `candidates` (pieces of the parent shaft).
double solve_shaft(const Segment& ci, const Segment& cj, const Segment* candidates, size_t count, int depth,
                   ExactWorkspace& ws, VisibilityStats& stats) {
    // `count` is also the parent's number of pieces: a split that kept most
    // of them did not pay, so this level integrates instead of splitting on.
    auto& mine = ws.levels[static_cast<size_t>(depth)];
    if (clip_candidates(Shaft(ci, cj), candidates, count, mine)) {
        ++stats.separated;
        return 0;
    }
    if (mine.empty()) return exchange_crossed_strings(ci, cj);
    const bool no_progress = depth > 0 && static_cast<double>(mine.size()) > split_keep_ratio * static_cast<double>(count);
    if (mine.size() <= split_threshold || depth == max_split_depth || no_progress) {
        stats.blockers += static_cast<long>(mine.size());
        return integrate(ci, cj, mine, ws, stats);
    }
    // Split one patch at its midpoint; the halves' shafts lie inside this
    // one, so this shaft's pieces are all they can meet. Which patch: a piece
    // at relative position t along the shaft (0 at i, 1 at j) stays in a half
    // of i's shaft with odds about the half-shaft's width over the shaft's
    // width there, ((1-t) L_i / 2 + t L_j) / ((1-t) L_i + t L_j); halve the
    // patch that leaves fewer pieces by that count.
    ++stats.subshafts;
    const Segment* pieces = mine.data();
    const size_t n = mine.size();
    const double Li = ci.length(), Lj = cj.length();
    const Vec2 mi = ci.midpoint(), axis = cj.midpoint() - mi;
    const double axis2 = norm_squared(axis);
    double keep_i = 0, keep_j = 0;
    for (size_t k = 0; k < n; ++k) {
        const double t = std::clamp(dot(pieces[k].midpoint() - mi, axis) / axis2, 0.0, 1.0);
        const double w = (1 - t) * Li + t * Lj;
        keep_i += ((1 - t) * Li / 2 + t * Lj) / w;
        keep_j += ((1 - t) * Li + t * Lj / 2) / w;
    }
    if (keep_i <= keep_j) {
        const Vec2 m = ci.midpoint();
        return solve_shaft({ci.a, m}, cj, pieces, n, depth + 1, ws, stats) +
               solve_shaft({m, ci.b}, cj, pieces, n, depth + 1, ws, stats);
    }
    const Vec2 m = cj.midpoint();
    return solve_shaft(ci, {cj.a, m}, pieces, n, depth + 1, ws, stats) +
           solve_shaft(ci, {m, cj.b}, pieces, n, depth + 1, ws, stats);
}

}  // namespace

double ExactVisibility::exchange(const Segment& i, const Segment& j, int skip_i, int skip_j, ExactWorkspace& ws,
                                 VisibilityStats& stats) const {
    const auto clipped = clip_to_lit_halfplanes(i, j);
    if (!clipped) {
        ++stats.culled;
        return 0;
    }
    const auto& [ci, cj] = *clipped;
    const Shaft shaft(ci, cj);
    const double size = shaft.box.diagonal();
    ws.blockers.clear();
    bool separated = false;
    stats.clusters_visited += m_hierarchy->query_blockers(
        [&](const Box& b) { return !separated && shaft.overlaps(b); },
        [&](int s, const Segment& seg) {
            if (s == skip_i || s == skip_j || separated) return;
            separated = add_blocker(shaft, seg, size, ws.blockers);
        },
        ws.stack);
    if (separated) {
        ++stats.queries;
        ++stats.separated;
        return 0;
    }
    if (ws.blockers.empty()) {
        ++stats.unoccluded;
        return exchange_crossed_strings(ci, cj);
    }
    ++stats.queries;
    ws.levels.resize(max_split_depth + 1);
    return solve_shaft(ci, cj, ws.blockers.data(), ws.blockers.size(), 0, ws, stats);
}

double ExactVisibility::exchange_with_blockers(const Segment& i, const Segment& j, const std::vector<Segment>& blockers,
                                               ExactWorkspace& ws, VisibilityStats& stats) {
    const auto clipped = clip_to_lit_halfplanes(i, j);
    if (!clipped) {
        ++stats.culled;
        return 0;
    }
    const auto& [ci, cj] = *clipped;
    const Shaft shaft(ci, cj);
    const double size = shaft.box.diagonal();
    ws.blockers.clear();
    for (const Segment& b : blockers) {
        if (!shaft.overlaps([&] { Box bb; bb.add(b); return bb; }())) continue;
        if (add_blocker(shaft, b, size, ws.blockers)) {
            ++stats.queries;
            ++stats.separated;
            return 0;
        }
    }
    if (ws.blockers.empty()) {
        ++stats.unoccluded;
        return exchange_crossed_strings(ci, cj);
    }
    ++stats.queries;
    ws.levels.resize(max_split_depth + 1);
    return solve_shaft(ci, cj, ws.blockers.data(), ws.blockers.size(), 0, ws, stats);
}

}  // namespace flatrad
