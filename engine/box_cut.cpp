#include "engine/box_cut.h"

#include <algorithm>
#include <cmath>

namespace flatrad {

bool segment_cuts_box(const Segment& s, const Box& b) {
    if (b.empty()) return false;
    const Vec2 e = b.extent();
    if (!(e.x > 0 && e.y > 0)) return false;  // no interior to cut
    const double scale = std::max({b.diagonal(), std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.hi.x),
                                   std::abs(b.hi.y), std::abs(s.a.x), std::abs(s.a.y), std::abs(s.b.x),
                                   std::abs(s.b.y)});
    const double tol = 1e-9 * scale;
    // The part of s inside b: parameters [t0, t1], of some length.
    double t0, t1;
    if (!clip_to_box(s.a, s.b, b, t0, t1) || !(t0 < t1)) return false;
    const Vec2 d = s.b - s.a;
    // How far inside b a point is (<= tol: on its boundary).
    auto depth = [&](Vec2 p) { return std::min({p.x - b.lo.x, b.hi.x - p.x, p.y - b.lo.y, b.hi.y - p.y}); };
    const Vec2 p0 = s.a + d * t0, p1 = s.a + d * t1;
    // An end clipped by a slab lies on that slab's side; an end of s itself
    // may lie on the boundary too (a face that starts at the box's corner).
    const bool from_boundary = t0 > 0 || depth(p0) <= tol;
    const bool to_boundary = t1 < 1 || depth(p1) <= tol;
    return from_boundary && to_boundary && depth((p0 + p1) * 0.5) > tol;
}

bool box_cut_by_blocker(const Hierarchy& h, const Box& box, int32_t skip_first, int32_t skip_count,
                        std::vector<int32_t>& stack, double min_length) {
    if (h.root() < 0 || box.empty()) return false;
    const int32_t skip_end = skip_first + skip_count;
    stack.clear();
    stack.push_back(h.root());
    while (!stack.empty()) {
        const ClusterNode& n = h.node(stack.back());
        stack.pop_back();
        if (n.blockers == 0 || boxes_apart(n.box, box)) continue;
        if (n.first >= skip_first && n.first + n.count <= skip_end) continue;  // all of it skipped
        if (!n.leaf()) {
            stack.push_back(n.child[1]);
            stack.push_back(n.child[0]);
            continue;
        }
        for (int32_t q = n.first; q < n.first + n.count; ++q) {
            if ((q >= skip_first && q < skip_end) || !h.can_block_at(q)) continue;
            const Segment& s = h.segment_at(q);
            if (s.length() >= min_length && segment_cuts_box(s, box)) return true;
        }
    }
    return false;
}

}  // namespace flatrad
