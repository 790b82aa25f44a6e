#include "engine/oriented_box.h"

#include <algorithm>
#include <cmath>

namespace flatrad {

std::pair<double, double> OrientedBox::range_along(Vec2 origin, Vec2 n) const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (Vec2 p : corners()) {
        const double o = dot(p - origin, n);
        lo = std::min(lo, o);
        hi = std::max(hi, o);
    }
    return {lo, hi};
}

namespace {

OrientedBox around(Vec2 axis, const Vec2* points, size_t count) {
    OrientedBox b;
    b.axis = axis;
    const Vec2 v = rot90(axis);
    b.lo_u = b.lo_v = std::numeric_limits<double>::infinity();
    b.hi_u = b.hi_v = -b.lo_u;
    for (size_t k = 0; k < count; ++k) {
        const double pu = dot(points[k], axis), pv = dot(points[k], v);
        b.lo_u = std::min(b.lo_u, pu);
        b.hi_u = std::max(b.hi_u, pu);
        b.lo_v = std::min(b.lo_v, pv);
        b.hi_v = std::max(b.hi_v, pv);
    }
    return b;
}

}  // namespace

std::vector<OrientedBox> oriented_boxes(const Hierarchy& h) {
    const auto& nodes = h.nodes();
    std::vector<OrientedBox> out(nodes.size());
    // Doubled-angle direction sums, children before parents (a child's
    // index is above its parent's: the hierarchy is built top-down).
    std::vector<Vec2> dir(nodes.size(), Vec2{0, 0});
    for (size_t k = nodes.size(); k-- > 0;) {
        const ClusterNode& n = nodes[k];
        if (n.leaf()) {
            std::vector<Vec2> pts;
            for (int32_t i = n.first; i < n.first + n.count; ++i) {
                const Segment& s = h.segments()[static_cast<size_t>(h.order()[static_cast<size_t>(i)])];
                const Vec2 d = s.b - s.a;
                const double L = norm(d);
                if (L > 0) {
                    // (cos 2t, sin 2t) L from the direction d / L = (cos t, sin t).
                    dir[k] = dir[k] + Vec2{(d.x * d.x - d.y * d.y) / L, 2 * d.x * d.y / L};
                }
                pts.push_back(s.a);
                pts.push_back(s.b);
            }
            const double t = 0.5 * std::atan2(dir[k].y, dir[k].x);
            out[k] = around({std::cos(t), std::sin(t)}, pts.data(), pts.size());
        } else {
            const size_t a = static_cast<size_t>(n.child[0]), b = static_cast<size_t>(n.child[1]);
            dir[k] = dir[a] + dir[b];
            const double t = 0.5 * std::atan2(dir[k].y, dir[k].x);
            std::array<Vec2, 8> pts{};
            const auto ca = out[a].corners(), cb = out[b].corners();
            std::copy(ca.begin(), ca.end(), pts.begin());
            std::copy(cb.begin(), cb.end(), pts.begin() + 4);
            out[k] = around({std::cos(t), std::sin(t)}, pts.data(), pts.size());
        }
    }
    return out;
}

}  // namespace flatrad
