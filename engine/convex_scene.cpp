#include "engine/convex_scene.h"

#include <algorithm>
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
    if (static_cast<double>(hull.size()) * static_cast<double>(scene.segments.size()) > 1e8) return false;
    const double extent = scene.extent();
    // A segment is on the boundary when no hull vertex lies on one side of
    // its line while another lies on the other (all hull vertices on one
    // side: the line supports the hull, and both endpoints are on it).
    for (const SceneSegment& s : scene.segments) {
        const double tol = 1e-12 * s.seg.length() * extent;
        bool left = false, right = false;
        for (const Vec2& v : hull) {
            const double o = orient(s.seg.a, s.seg.b, v);
            left = left || o > tol;
            right = right || o < -tol;
            if (left && right) return false;
        }
    }
    return true;
}

}  // namespace flatrad
