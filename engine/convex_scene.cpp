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

std::vector<char> segments_on_hull(const std::vector<Segment>& segments, double extent) {
    std::vector<char> on(segments.size(), 0);
    if (segments.size() <= 2) {  // two segments: nothing else to block them
        on.assign(segments.size(), 1);
        return on;
    }
    std::vector<Vec2> pts;
    pts.reserve(2 * segments.size());
    for (const Segment& s : segments) {
        pts.push_back(s.a);
        pts.push_back(s.b);
    }
    const std::vector<Vec2> hull = convex_hull(pts);
    if (hull.size() < 3) return on;  // all collinear: collinear segments face nothing anyway, but say "unsure"
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
    const double tol = 1e-12 * extent;
    for (size_t k = 0; k < segments.size(); ++k) {
        const Segment& s = segments[k];
        const double L = s.length();
        if (!(L > 0)) continue;
        const Vec2 n = rot90(s.b - s.a) / L;
        const double h = dot(n, s.a);
        on[k] = support(n) <= h + tol || support(-n) <= -h + tol;
    }
    return on;
}

std::vector<char> possible_blockers(const Scene& scene) {
    std::vector<char> on = segments_on_hull(scene.segment_geometry(), scene.extent());
    for (char& c : on) c = !c;
    return on;
}

bool no_segment_can_block(const Scene& scene) {
    const std::vector<char> b = possible_blockers(scene);
    return std::find(b.begin(), b.end(), 1) == b.end();
}

}  // namespace flatrad
