#pragma once
/// The shaft of a facing pair (DESIGN.md §1): the convex hull of the two
/// mutually clipped patches, and the clipping of blockers to it. Shared by
/// the exact and the multi-scale visibility. Internal to visibility/.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/geometry.h"

namespace flatrad::shaft_detail {

// A blocker piece closer than this to the line of a patch, relative to the
// local scale, lies along the patch (overlapping or touching segments): it
// cannot stop a line that crosses the shaft's interior, so it is dropped.
// The local scale of a piece end x is that of the numbers its distance is
// made of: |x| and |p| (p the nearer end of the patch; clipping rounds
// points by a few ulps of their coordinates) and |x - p| (orient's own
// rounding). Not the shaft's size: beside a 1e33-long wall, a lamp 1 away
// from the other patch is not on its line. 1e-13 is a hundred times the
// rounding and still far below any real gap.
inline constexpr double on_edge_tolerance = 1e-13;

// Slack, relative to the overlap width, when deciding whether a critical
// direction happens inside the overlap of the two patches' projections.
// Keeping an event that did not need to be kept costs time, never accuracy,
// so this errs wide.
inline constexpr double event_slack = 1e-9;

// A culling test may err towards "overlaps" (a node visited for nothing,
// a piece clipped to nothing), never the other way. Its plain products (no
// FMA) are within ~6e-16 of |n|_1 (|c| + |r| + |h|) of the exact value (n
// an edge's normal, r a point's offset from the edge's start, c, h a box's
// centre and half extent: each a single rounding from the inputs); this
// many times that magnitude is the margin kept, a hundred times more, far
// below any real gap.
inline constexpr double culling_slack = 1e-13;

// The shaft: the convex hull of the clipped pair, A0 A1 C0 C1 counter-clockwise
// (i = A0 -> A1 and j = C0 -> C1 both lit on the left and facing each other).
struct Shaft {
    std::array<Vec2, 4> v;        // A0, A1, C0, C1
    std::array<bool, 4> edge_ok;  // false for a zero-length side (shared endpoint)
    // Edge e (v[e] -> v[e + 1]): rot90 of its direction, so that
    // orient(v[e], v[e + 1], x) = dot(normal[e], x - v[e]) (the same
    // rounded difference); its L1 norm; and |v[e]| + |v[e + 1]| (max norms).
    std::array<Vec2, 4> normal;
    std::array<double, 4> normal_l1, ends;
    Box box;

    Shaft(const Segment& i, const Segment& j) : v{i.a, i.b, j.a, j.b} {
        const auto magnitude = [](Vec2 w) { return std::max(std::abs(w.x), std::abs(w.y)); };
        for (size_t e = 0; e < 4; ++e) {
            const Vec2 p = v[e], q = v[(e + 1) % 4];
            edge_ok[e] = !(p == q);
            normal[e] = rot90(q - p);
            normal_l1[e] = std::abs(normal[e].x) + std::abs(normal[e].y);
            ends[e] = magnitude(p) + magnitude(q);
            box.add(p);
        }
    }

    // Separating-axis test: the box's axes (bounding boxes overlap) and the
    // shaft's edge normals (all four corners outside one edge: the corner
    // furthest along the edge's normal, n . (centre - p) + |n| . half
    // extent, is outside by more than culling_slack of the magnitudes). A
    // box within that margin of an edge counts as overlapping.
    bool overlaps(const Box& b) const { return where(b) != Where::outside; }

    // The same test, telling also a box surely inside: for every edge, the
    // corner furthest against its normal, n . (centre - p) - |n| . half
    // extent, is inside by more than the margin. (Surely: then so is every
    // box within it, which need not be tested again.)
    enum class Where { outside, across, inside };
    Where where(const Box& b) const {
        if (b.hi.x < box.lo.x || b.lo.x > box.hi.x || b.hi.y < box.lo.y || b.lo.y > box.hi.y) return Where::outside;
        const Vec2 c = b.center();
        const Vec2 h = 0.5 * b.extent();
        const double size = std::max(std::abs(c.x), std::abs(c.y)) + h.x + h.y;
        bool inside = true;
        for (size_t e = 0; e < 4; ++e) {
            if (!edge_ok[e]) continue;
            const Vec2 n = normal[e], r = c - v[e];
            const double mid = n.x * r.x + n.y * r.y, spread = std::abs(n.x) * h.x + std::abs(n.y) * h.y;
            const double margin = culling_slack * normal_l1[e] * (size + std::max(std::abs(r.x), std::abs(r.y)));
            if (mid + spread < -margin) return Where::outside;
            inside = inside && mid - spread > margin;
        }
        return inside ? Where::inside : Where::across;
    }

    // The box lies wholly inside the closed shaft (all four corners).
    bool contains(const Box& b) const {
        const std::array<Vec2, 4> corner{b.lo, Vec2{b.hi.x, b.lo.y}, b.hi, Vec2{b.lo.x, b.hi.y}};
        for (size_t e = 0; e < 4; ++e) {
            if (!edge_ok[e]) continue;
            const Vec2 p = v[e], q = v[(e + 1) % 4];
            for (const Vec2& c : corner)
                if (orient(p, q, c) < 0) return false;
        }
        return true;
    }

    // Clips s to the closed shaft (Cyrus-Beck). Returns false when nothing of
    // positive length is left. `enter` and `leave` receive the edges that
    // cut the piece's ends (-1 when an end is an original endpoint).
    bool clip(const Segment& s, Segment& out, int& enter, int& leave) const {
        double t0 = 0, t1 = 1;
        enter = leave = -1;
        for (size_t e = 0; e < 4; ++e) {
            if (!edge_ok[e]) continue;
            const Vec2 p = v[e], q = v[(e + 1) % 4];
            const double fa = orient(p, q, s.a), fb = orient(p, q, s.b);
            if (fa < 0 && fb < 0) return false;
            if (fa >= 0 && fb >= 0) continue;
            const double t = fa / (fa - fb);
            if (fa < 0) {
                if (t > t0) { t0 = t; enter = static_cast<int>(e); }
            } else {
                if (t < t1) { t1 = t; leave = static_cast<int>(e); }
            }
        }
        if (!(t1 > t0)) return false;
        out = {t0 > 0 ? lerp(s.a, s.b, t0) : s.a, t1 < 1 ? lerp(s.a, s.b, t1) : s.b};
        return !(out.a == out.b);
    }
};

// Adds s, clipped to the shaft, to the blockers. Returns true when the piece
// alone closes the shaft: it runs from one side edge (A1 -> C0, edge 1) to
// the other (C1 -> A0, edge 3), so every line from i to j crosses it.
// `size` (the shaft's diagonal) is no longer used: tolerances are local.
inline bool add_blocker(const Shaft& shaft, const Segment& s, [[maybe_unused]] double size,
                        std::vector<Segment>& blockers) {
    const auto magnitude = [](Vec2 v) { return std::max(std::abs(v.x), std::abs(v.y)); };
    // On the inner side of edge e's line by more than `bar`, in plain
    // arithmetic: dot(n, x - p), as orient(p, q, x) computes it but with
    // every product rounded, so within culling_slack |n|_1 (|x| + |p| +
    // |q|) of the exact value (see culling_slack).
    const auto clearly_inside = [&](size_t e, Vec2 x, double bar) {
        const Vec2 n = shaft.normal[e], p = shaft.v[e];
        return n.x * (x.x - p.x) + n.y * (x.y - p.y) > bar;
    };
    // The margins: for the side edges (1, 3) the rounding above, so that
    // orient is >= 0 (Cyrus-Beck keeps the whole segment, cut by no edge);
    // for the patches' edges (0, 2) on_line's plain bound below, past which
    // an end is surely off the patch's line (it also exceeds the rounding).
    const auto bar = [&](size_t e, double mx) {
        const double slack = culling_slack * (mx + shaft.ends[e]);
        if (e % 2 == 1) return slack * shaft.normal_l1[e];
        return (on_edge_tolerance * 4 * std::max(mx, shaft.ends[e]) + slack) * shaft.normal_l1[e];
    };
    // Wholly and clearly inside the shaft (most pieces of a long shaft
    // through a forest): the exact path below would keep s whole, find
    // neither end on a patch's line and no edge cutting it, so s itself is
    // the piece, bit for bit, without the exact orientations. (A
    // zero-length edge has a zero normal: the test fails, the exact path
    // decides.)
    if (!(s.a == s.b)) {
        const double ma = magnitude(s.a), mb = magnitude(s.b);
        bool inside = true;
        for (size_t e = 0; e < 4 && inside; ++e)
            inside = clearly_inside(e, s.a, bar(e, ma)) && clearly_inside(e, s.b, bar(e, mb));
        if (inside) {
            blockers.push_back(s);
            return false;
        }
    }
    Segment piece;
    int enter = -1, leave = -1;
    if (!shaft.clip(s, piece, enter, leave)) return false;
    // Drop pieces lying along patch i (edge 0) or patch j (edge 2); note
    // whether either end touches a patch's line. The distance of x to the
    // line is measured from the patch's nearer end (orient(p, q, x) is
    // |q - p| times that distance; from q it is -orient(q, p, x)).
    // (p, q: patch edge e's ends, shaft.v[e] and shaft.v[e + 1].)
    const auto on_line = [&](size_t e, Vec2 p, Vec2 q, Vec2 x) {
        // Clearly off the line first, in plain arithmetic: the test below
        // is o <= tol local |pq| with local <= 4 max(|x|, |p|, |q|) (max
        // norms; the distance to the nearer end is at most 2 sqrt 2 of
        // that) and |pq| <= |n|_1; o is dot(n, x - p) within culling_slack
        // of |n|_1 (|x| + |p| + |q|), whether taken from p or from q. Above
        // that bound the answer is false for sure.
        if (clearly_inside(e, x, bar(e, magnitude(x)))) return false;
        const bool from_p = distance(x, p) <= distance(x, q);
        const Vec2 near = from_p ? p : q;
        const double o = from_p ? orient(p, q, x) : -orient(q, p, x);
        const double local = std::max(magnitude(x), magnitude(near)) + distance(x, near);
        return o <= on_edge_tolerance * local * distance(p, q);
    };
    bool end_on_patch_line = false;
    for (size_t e : {size_t{0}, size_t{2}}) {
        const Vec2 p = shaft.v[e], q = shaft.v[e + 1];
        const bool a_on = on_line(e, p, q, piece.a), b_on = on_line(e, p, q, piece.b);
        if (a_on && b_on) return false;
        end_on_patch_line = end_on_patch_line || a_on || b_on;
    }
    // From side to side closes the shaft; but when a side edge is collinear
    // with a patch (a clipped corner), the edge labels of Cyrus-Beck cannot
    // tell the side from the patch, so ends on a patch's line never count.
    if (!end_on_patch_line && ((enter == 1 && leave == 3) || (enter == 3 && leave == 1))) return true;
    blockers.push_back(piece);
    return false;
}

// The frame of a facing pair (DESIGN §1, directions measured from the
// pair's own axis): origin at the shorter patch's midpoint, axis u bisecting the range of
// directions of lines meeting both, so that the range is
// [-delta_theta, delta_theta] with delta_theta < pi/2 and the slope
// tan(phi) is a monotone, well-conditioned parameter inside it.
struct PairFrame {
    Vec2 origin, u;
    double theta_u = 0;      // absolute direction of u
    double delta_theta = 0;  // half the range of directions

    // The origin sits at the shorter patch's midpoint: local coordinates
    // carry rounding of the size of their distance to the origin, and the
    // differences that decide the result are those near the shorter patch
    // (beside a 5e14-long wall, a 0.04 patch's points taken relative to the
    // wall's midpoint would be off by 0.03: the fuzzer's case).
    PairFrame(const Segment& ci, const Segment& cj)
        : origin(norm_squared(ci.b - ci.a) <= norm_squared(cj.b - cj.a) ? ci.midpoint() : cj.midpoint()) {
        Vec2 u0 = cj.midpoint() - ci.midpoint();
        u0 = u0 / norm(u0);
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (Vec2 A : {ci.a, ci.b})
            for (Vec2 C : {cj.a, cj.b}) {
                const Vec2 w = C - A;
                if (w == Vec2{}) continue;
                const double phi = std::atan2(cross(u0, w), dot(u0, w));
                lo = std::min(lo, phi);
                hi = std::max(hi, phi);
            }
        const double mid = 0.5 * (lo + hi);
        u = {u0.x * std::cos(mid) - u0.y * std::sin(mid), u0.x * std::sin(mid) + u0.y * std::cos(mid)};
        theta_u = std::atan2(u.y, u.x);
        delta_theta = 0.5 * (hi - lo);
    }
    Vec2 local(Vec2 P) const {
        const Vec2 d = P - origin;
        return {dot(d, u), dot(d, rot90(u))};
    }
};

// Clips the candidate pieces to the shaft into `out`. Returns true when one
// of them closes the shaft on its own (the answer is then 0).
inline bool clip_candidates(const Shaft& shaft, const Segment* candidates, size_t count, std::vector<Segment>& out) {
    const double size = shaft.box.diagonal();
    out.clear();
    for (size_t k = 0; k < count; ++k) {
        Box bb;
        bb.add(candidates[k]);
        if (!shaft.overlaps(bb)) continue;
        if (add_blocker(shaft, candidates[k], size, out)) return true;
    }
    return false;
}

}  // namespace flatrad::shaft_detail
