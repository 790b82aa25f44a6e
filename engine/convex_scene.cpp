#include "engine/convex_scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace flatrad {

namespace {

// Andrew's monotone chain: the hull's vertices counter-clockwise, collinear
// points dropped.
std::vector<Vec2> convex_hull(std::vector<Vec2> p) {
    std::sort(p.begin(), p.end(), [](Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<Vec2> h(2 * p.size());
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && orient(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && orient(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

}  // namespace

bool no_segment_can_block(const Scene& scene) {
    if (scene.segments.size() <= 2) return true;  // two segments: nothing else to block them
    std::vector<Vec2> pts;
    pts.reserve(2 * scene.segments.size());
    for (const SceneSegment& s : scene.segments) {
        pts.push_back(s.seg.a);
        pts.push_back(s.seg.b);
    }
    const std::vector<Vec2> hull = convex_hull(pts);
    if (hull.size() < 3) return false;  // all collinear: collinear segments face nothing anyway, but say "unsure"
    // A segment is on the boundary when its line supports the hull: for its
    // unit normal n (either sign), max over the hull of n . v equals n . a.
    // The maximising vertex is found by binary search on the hull's outward
    // edge normals, whose angles increase around a counter-clockwise hull
    // (O(log H) per segment, O(N log N) in all).
    const size_t H = hull.size();
    std::vector<double> angle(H);
    for (size_t i = 0; i < H; ++i) {
        const Vec2 e = hull[(i + 1) % H] - hull[i];
        angle[i] = std::atan2(-e.x, e.y);  // outward normal (e rotated clockwise)
        if (i > 0)
            while (angle[i] < angle[i - 1]) angle[i] += 2 * std::numbers::pi;
    }
    auto support = [&](Vec2 n) {
        double t = std::atan2(n.y, n.x);
        while (t < angle[0]) t += 2 * std::numbers::pi;
        while (t >= angle[0] + 2 * std::numbers::pi) t -= 2 * std::numbers::pi;
        // Vertex j = first edge whose normal angle >= t: edges j-1 and j bracket n.
        const size_t j = static_cast<size_t>(std::lower_bound(angle.begin(), angle.end(), t) - angle.begin()) % H;
        double best = dot(n, hull[j]);
        // Neighbours too: the angles are rounded.
        best = std::max({best, dot(n, hull[(j + 1) % H]), dot(n, hull[(j + H - 1) % H])});
        return best;
    };
    const double extent = scene.extent();
    for (const SceneSegment& s : scene.segments) {
        const double L = s.seg.length();
        if (!(L > 0)) return false;
        const Vec2 n = rot90(s.seg.b - s.seg.a) / L;
        const double tol = 1e-12 * extent;
        const double h = dot(n, s.seg.a);
        const bool supports = support(n) <= h + tol || support(-n) <= -h + tol;
        if (!supports) return false;
    }
    return true;
}

}  // namespace flatrad
