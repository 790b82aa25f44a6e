#pragma once
/// Point and segment against a polygon, with a rounding margin (for the
/// room and sink rules, solver/rooms.h and solver/sink_visibility.h).
#include <cmath>
#include <limits>
#include <vector>

#include "engine/geometry.h"

namespace flatrad {

enum class Where { Inside, Outside, Unsure };

// Crossing number of p against the polygon, with a rounding margin: a point
// whose orientation against some edge it projects onto is within `tol` of
// zero is Unsure.
inline Where locate(Vec2 p, const std::vector<Vec2>& poly) {
    bool inside = false;
    const size_t n = poly.size();
    for (size_t k = 0; k < n; ++k) {
        const Vec2 a = poly[k], b = poly[(k + 1) % n];
        const double o = orient(a, b, p);
        const double tol = 8 * std::numeric_limits<double>::epsilon() * (std::abs(b.x - a.x) + std::abs(b.y - a.y)) *
                           (std::abs(p.x - a.x) + std::abs(p.y - a.y) + 1e-300);
        const bool within_x = std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x);
        const bool within_y = std::min(a.y, b.y) <= p.y && p.y <= std::max(a.y, b.y);
        if (std::abs(o) <= tol && within_x && within_y) return Where::Unsure;  // on (or at) the edge
        if ((a.y > p.y) != (b.y > p.y)) {
            // The edge crosses p's horizontal line: count it when it does so right of p.
            const bool right = (b.y > a.y) ? o > 0 : o < 0;
            if (right) inside = !inside;
        }
    }
    return inside ? Where::Inside : Where::Outside;
}

// Whether segment s properly crosses or touches some edge of the polygon.
inline bool meets(const Segment& s, const std::vector<Vec2>& poly) {
    const size_t n = poly.size();
    for (size_t k = 0; k < n; ++k) {
        const Vec2 a = poly[k], b = poly[(k + 1) % n];
        const double o1 = orient(a, b, s.a), o2 = orient(a, b, s.b);
        const double o3 = orient(s.a, s.b, a), o4 = orient(s.a, s.b, b);
        if ((o1 <= 0 || o2 <= 0) && (o1 >= 0 || o2 >= 0) && (o3 <= 0 || o4 <= 0) && (o3 >= 0 || o4 >= 0)) return true;
    }
    return false;
}


}  // namespace flatrad
