#include "visibility/closure_screen.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>

namespace flatrad {

namespace {

// Signed distances are computed as dot(p - t0, n) with |n| = 1: each term
// carries a rounding error of a few ulps of the coordinates involved.
// Points closer to a line than this many ulps of the largest magnitude are
// treated as on it (so never strictly in front or behind).
constexpr double rounding_ulps = 64;
// A crossing must lie this share of the screen's length inside its ends
// (the crossing's own rounding is far smaller: a few ulps of the
// coordinates over the screen's length, which is at least 1e-6 of them in
// any use here).
constexpr double end_margin = 1e-9;

// The distance from a line below which a point counts as on it: rounding_ulps
// ulps of the largest coordinate among `points` (infinite if any is not
// finite, so that nothing passes).
double rounding_margin(std::initializer_list<Vec2> points) {
    double scale = 0;
    for (const Vec2& p : points) scale = std::max({scale, std::abs(p.x), std::abs(p.y)});
    return std::isfinite(scale) ? rounding_ulps * std::numeric_limits<double>::epsilon() * scale
                                : std::numeric_limits<double>::infinity();
}

}  // namespace

std::optional<Segment> closure_screen(const Segment& a, Vec2 toward, double depth, double half_width) {
    const Vec2 m = a.midpoint();
    const double d = distance(m, toward);
    if (!(d > 0) || !(depth > 0) || !(half_width > 0) || !std::isfinite(depth + half_width)) return std::nullopt;
    const Vec2 u = (toward - m) / d, v = rot90(u);
    const Vec2 c = m + u * depth;
    // Left normal of [c - v h, c + v h] is rot90(v) = -u: toward a.
    const Segment t{c - v * half_width, c + v * half_width};
    const double margin = rounding_margin({a.a, a.b, t.a, t.b});
    // t's ends strictly on a's lit side (orient is scaled by |a|).
    const Vec2 na = a.left_normal();
    if (!(dot(t.a - a.a, na) > margin && dot(t.b - a.a, na) > margin)) return std::nullopt;
    // a's ends strictly in front of t.
    if (!(dot(a.a - t.a, -u) > margin && dot(a.b - t.a, -u) > margin)) return std::nullopt;
    return t;
}

bool screen_covers(const Segment& screen, const Segment& a, const Box& region) {
    if (region.empty()) return false;
    const Vec2 dir = screen.direction();
    const double len2 = norm_squared(dir);
    if (!(len2 > 0) || !std::isfinite(len2)) return false;
    const Vec2 n = rot90(dir) / std::sqrt(len2);  // toward a
    const Vec2 corners[4] = {region.lo, {region.hi.x, region.lo.y}, region.hi, {region.lo.x, region.hi.y}};
    const double margin = rounding_margin({screen.a, screen.b, a.a, a.b, corners[0], corners[1], corners[2], corners[3]});
    if (!std::isfinite(margin)) return false;
    auto side = [&](Vec2 p) { return dot(p - screen.a, n); };  // > 0: a's side
    const Vec2 ends[2] = {a.a, a.b};
    double se[2];
    for (int k = 0; k < 2; ++k) {
        se[k] = side(ends[k]);
        if (!(se[k] > margin)) return false;
    }
    for (const Vec2& c : corners) {
        const double sc = side(c);
        if (!(sc < -margin)) return false;
        for (int k = 0; k < 2; ++k) {
            // Where the line from ends[k] to c crosses the screen's line
            // (se > margin > -sc: the denominator exceeds 2 margins).
            const Vec2 x = ends[k] + (c - ends[k]) * (se[k] / (se[k] - sc));
            const double lambda = dot(x - screen.a, dir) / len2;
            if (!(lambda >= end_margin && lambda <= 1 - end_margin)) return false;
        }
    }
    return true;
}

}  // namespace flatrad
