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

std::vector<char> segments_on_hull(const std::vector<Segment>& segments) {
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
    // unit normal n (either sign), no hull vertex lies beyond the line on
    // n's side. The vertex furthest along n is found by binary search on the
    // hull's outward edge normals, whose angles increase around a
    // counter-clockwise hull (O(log H) per segment, O(N log N) in all).
    const size_t H = hull.size();
    std::vector<double> angle(H);
    for (size_t i = 0; i < H; ++i) {
        const Vec2 e = hull[(i + 1) % H] - hull[i];
        angle[i] = std::atan2(-e.x, e.y);  // outward normal (e rotated clockwise)
        if (i > 0)
            while (angle[i] < angle[i - 1]) angle[i] += 2 * std::numbers::pi;
    }
    auto furthest = [&](Vec2 n) {
        double t = std::atan2(n.y, n.x);
        while (t < angle[0]) t += 2 * std::numbers::pi;
        while (t >= angle[0] + 2 * std::numbers::pi) t -= 2 * std::numbers::pi;
        // Vertex j = first edge whose normal angle >= t: edges j-1 and j bracket n.
        size_t best = static_cast<size_t>(std::lower_bound(angle.begin(), angle.end(), t) - angle.begin()) % H;
        // Neighbours too: the angles are rounded.
        for (size_t k : {(best + 1) % H, (best + H - 1) % H})
            if (dot(n, hull[k]) > dot(n, hull[best])) best = k;
        return best;
    };
    for (size_t k = 0; k < segments.size(); ++k) {
        const Segment& s = segments[k];
        const Vec2 d = s.b - s.a;
        const double L = norm(d);
        if (!(L > 0)) continue;
        // Offset of v beyond the line on n's side, measured from the nearer
        // end (a far end would add its own rounding), against what rounding
        // coordinates read from text (1e-12 relative) moves v or the line
        // there: the line near v's foot t is (1 - t) a + t b, known to
        // 1e-12 (|1 - t| |a| + |t| |b|). Local, not the scene's extent: a
        // wall 1e12 long beside a pillar of size 1 must still see the pillar
        // stick out by 0.8 (a fuzzed scene whose far wall was taken for a
        // hull wall, so that nothing blocked through it).
        auto beyond = [&](Vec2 n, Vec2 v) {
            const double t = dot(v - s.a, d) / (L * L);
            const double offset = dot(n, v - (t < 0.5 ? s.a : s.b));
            const double scale = std::max(norm(v), std::abs(1 - t) * norm(s.a) + std::abs(t) * norm(s.b));
            return offset > 1e-12 * scale;
        };
        // The vertices on n's side of the line form one arc of the hull
        // around the furthest one (convexity). Walk it both ways while the
        // offset is positive: a vertex within rounding of the line must not
        // hide a nearer one that sticks out by more than its own rounding.
        auto side_clear = [&](Vec2 n) {
            const size_t j = furthest(n);
            if (beyond(n, hull[j])) return false;
            for (const size_t step : {size_t{1}, H - 1})
                for (size_t m = (j + step) % H; m != j; m = (m + step) % H) {
                    const Vec2 v = hull[m];
                    if (dot(n, v - s.a) <= 0 && dot(n, v - s.b) <= 0) break;
                    if (beyond(n, v)) return false;
                }
            return true;
        };
        const Vec2 n = rot90(d) / L;
        on[k] = side_clear(n) || side_clear(-n);
    }
    return on;
}

std::vector<char> possible_blockers(const Scene& scene) {
    std::vector<char> on = segments_on_hull(scene.segment_geometry());
    for (char& c : on) c = !c;
    return on;
}

bool no_segment_can_block(const Scene& scene) {
    const std::vector<char> b = possible_blockers(scene);
    return std::find(b.begin(), b.end(), 1) == b.end();
}

}  // namespace flatrad
