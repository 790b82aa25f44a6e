#include "engine/box_intrusion.h"

#include <algorithm>
#include <cmath>

namespace flatrad {

double chord_through_box(const Segment& s, const Box& b) {
    if (b.empty()) return 0;
    const Vec2 e = b.extent();
    if (!(e.x > 0 && e.y > 0)) return 0;  // no interior
    double t0, t1;
    if (!clip_to_box(s.a, s.b, b, t0, t1) || !(t0 < t1)) return 0;
    const double scale = std::max({b.diagonal(), std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.hi.x),
                                   std::abs(b.hi.y), std::abs(s.a.x), std::abs(s.a.y), std::abs(s.b.x),
                                   std::abs(s.b.y)});
    const Vec2 d = s.b - s.a;
    const Vec2 p0 = s.a + d * t0, p1 = s.a + d * t1, m = (p0 + p1) * 0.5;
    const double depth = std::min({m.x - b.lo.x, b.hi.x - m.x, m.y - b.lo.y, b.hi.y - m.y});
    return depth > 1e-9 * scale ? distance(p0, p1) : 0.0;
}

bool box_intruded_by_blocker(const Hierarchy& h, const Box& box, int32_t skip_first, int32_t skip_count,
                             double min_length, double min_chord, std::vector<int32_t>& stack) {
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
            if (!(s.length() >= min_length)) continue;
            const double chord = chord_through_box(s, box);
            if (chord > 0 && chord >= min_chord) return true;
        }
    }
    return false;
}

}  // namespace flatrad
