#pragma once
// The slow obvious version of occlusion inside a set of segments (the
// oracle of solver/self_occlusion.h's visible_fraction and
// solver/front_envelopes.h), exactly, for segments that do not cross: per
// side facing u, its interval across u minus the overlaps with blockers in
// front of it (which one is in front is the same all over an overlap, so
// its midpoint decides).
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "engine/geometry.h"
#include "solver/self_occlusion.h"

namespace flatrad::test {

// Whether segments p and q cross or touch (orientation tests).
inline bool meet(const Segment& p, const Segment& q) {
    auto side = [](Vec2 a, Vec2 b, Vec2 c) { return cross(b - a, c - a); };
    const double d1 = side(q.a, q.b, p.a), d2 = side(q.a, q.b, p.b);
    const double d3 = side(p.a, p.b, q.a), d4 = side(p.a, p.b, q.b);
    return (d1 * d2 <= 0) && (d3 * d4 <= 0);
}

// One segment seen from far along u: the projected width of its side
// facing u (0 if that side does not exist), the width of it seen, the
// integral of its depth dot(x, u) over the seen part, and in how many
// disjoint runs it is seen.
struct SeenSegment {
    double facing_width = 0, seen = 0, depth_integral = 0;
    int runs = 0;
};

inline std::vector<SeenSegment> seen_segments(const std::vector<Segment>& segs, const std::vector<uint8_t>& sides,
                                              Vec2 u) {
    const Vec2 v{-u.y, u.x};
    struct Proj {
        double lo, hi, dlo, dhi;
    };
    std::vector<Proj> pr;
    for (const Segment& s : segs) {
        double pa = dot(s.a, v), pb = dot(s.b, v), da = dot(s.a, u), db = dot(s.b, u);
        if (pa > pb) {
            std::swap(pa, pb);
            std::swap(da, db);
        }
        pr.push_back({pa, pb, da, db});
    }
    auto depth_at = [&](size_t i, double p) {
        const Proj& q = pr[i];
        return q.hi > q.lo ? q.dlo + (p - q.lo) / (q.hi - q.lo) * (q.dhi - q.dlo) : q.dlo;
    };
    std::vector<SeenSegment> out(segs.size());
    for (size_t i = 0; i < segs.size(); ++i) {
        const double c = dot(segs[i].left_normal(), u);
        const uint8_t side = c > 0 ? left_side : c < 0 ? right_side : 0;
        if (!(sides[i] & side)) continue;
        out[i].facing_width = pr[i].hi - pr[i].lo;
        std::vector<std::pair<double, double>> hidden;
        for (size_t j = 0; j < segs.size(); ++j) {
            if (j == i || !(sides[j] & blocks)) continue;
            const double lo = std::max(pr[i].lo, pr[j].lo), hi = std::min(pr[i].hi, pr[j].hi);
            if (hi <= lo) continue;
            const double mid = 0.5 * (lo + hi);
            if (depth_at(j, mid) > depth_at(i, mid)) hidden.push_back({lo, hi});
        }
        std::sort(hidden.begin(), hidden.end());
        double at = pr[i].lo;
        auto run = [&](double a, double b) {
            out[i].seen += b - a;
            out[i].depth_integral += (b - a) * depth_at(i, 0.5 * (a + b));
            ++out[i].runs;
        };
        for (const auto& [lo, hi] : hidden) {
            if (lo > at) run(at, lo);
            at = std::max(at, hi);
        }
        if (pr[i].hi > at) run(at, pr[i].hi);
    }
    return out;
}

// The whole set's share seen (1 where nothing faces u), its facing width
// and its visible runs.
struct SeenShare {
    double fraction = 1;
    double facing_width = 0;
    int runs = 0;
};

inline SeenShare seen_share(const std::vector<Segment>& segs, const std::vector<uint8_t>& sides, Vec2 u) {
    SeenShare e;
    double seen = 0;
    for (const SeenSegment& s : seen_segments(segs, sides, u)) {
        e.facing_width += s.facing_width;
        seen += s.seen;
        e.runs += s.runs;
    }
    if (e.facing_width > 0) e.fraction = seen / e.facing_width;
    return e;
}

}  // namespace flatrad::test
