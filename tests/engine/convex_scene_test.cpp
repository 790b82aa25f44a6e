// Scenes in which no segment can block another (engine/convex_scene.h),
// checked against the definition: every segment on the convex hull's
// boundary, i.e. every other endpoint on one side of its line.
#include "engine/convex_scene.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>
#include <fmt/format.h>
#include <numbers>
#include <random>
#include <string>

using namespace flatrad;

namespace {

std::string polygon_scene(const std::vector<std::array<double, 2>>& pts, const std::string& extra = "") {
    std::string p;
    for (const auto& q : pts) p += fmt::format("{}[{},{}]", p.empty() ? "" : ",", q[0], q[1]);
    return fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5, "emission": 1}}}},
        "surfaces": [{{"name": "room", "material": "m", "closed": true, "side": "in", "points": [{}]}}{}]}})",
                       p, extra);
}

// The definition, O(N^2): no endpoint strictly on both sides of any segment's line.
bool oracle(const Scene& s) {
    for (const SceneSegment& a : s.segments) {
        bool left = false, right = false;
        for (const SceneSegment& b : s.segments)
            for (Vec2 v : {b.seg.a, b.seg.b}) {
                const double o = orient(a.seg.a, a.seg.b, v);
                const double tol = 1e-9 * a.seg.length();
                left = left || o > tol;
                right = right || o < -tol;
            }
        if (left && right) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("no segment can block: convex rooms yes, anything inside or a reflex corner no") {
    const Scene square = parse_scene(polygon_scene({{0, 0}, {2, 0}, {2, 1}, {0, 1}}), "sq");
    CHECK(no_segment_can_block(square));
    // A room made of two polylines meeting end to end (a lamp as part of the floor).
    const Scene two_parts = parse_scene(R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5}},
        "surfaces": [{"name": "lamp", "material": "m", "points": [[0,0],[1,0]]},
                     {"name": "walls", "material": "m", "points": [[1,0],[2,0],[2,1],[0,1],[0,0]]}]})",
                                        "two");
    CHECK(no_segment_can_block(two_parts));
    const Scene inside = parse_scene(
        polygon_scene({{0, 0}, {2, 0}, {2, 1}, {0, 1}},
                      R"(, {"name": "plate", "material": "m", "points": [[0.5, 0.5], [1, 0.6]], "side": "both"})"),
        "in");
    CHECK_FALSE(no_segment_can_block(inside));
    const Scene l_shape = parse_scene(polygon_scene({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}), "L");
    CHECK_FALSE(no_segment_can_block(l_shape));
}

TEST_CASE("no segment can block: agrees with the quadratic definition on random polygons and circles") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    int convex = 0;
    for (int trial = 0; trial < 200; ++trial) {
        // Star-shaped polygons: angles sorted, radii random (convex when the
        // radii are equal, often not otherwise).
        const int n = 3 + static_cast<int>(u(rng) * 40);
        const bool round = trial % 2 == 0;
        std::vector<std::array<double, 2>> pts;
        for (int k = 0; k < n; ++k) {
            const double a = 2 * std::numbers::pi * k / n;
            const double r = round ? 1.0 : 0.5 + u(rng);
            pts.push_back({1e3 * (trial % 3) + r * std::cos(a), r * std::sin(a)});
        }
        const Scene s = parse_scene(polygon_scene(pts), "p");
        CAPTURE(trial);
        CHECK(no_segment_can_block(s) == oracle(s));
        convex += oracle(s) ? 1 : 0;
    }
    CHECK(convex >= 100);  // every regular polygon, so both answers were tested
    CHECK(convex < 200);
}
