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

// The definition, O(N^2): segment a is on the hull's boundary when no
// endpoint lies strictly on both sides of its line.
bool on_hull_oracle(const Scene& s, const SceneSegment& a) {
    bool left = false, right = false;
    for (const SceneSegment& b : s.segments)
        for (Vec2 v : {b.seg.a, b.seg.b}) {
            const double o = orient(a.seg.a, a.seg.b, v);
            const double tol = 1e-9 * a.seg.length();
            left = left || o > tol;
            right = right || o < -tol;
        }
    return !(left && right);
}

// Star-shaped polygons: angles evenly spaced, radii random in [0.5, 1.5)
// (convex when `round`: all radii 1, often not otherwise), 3 to 42
// vertices, shifted by x_offset.
std::vector<std::array<double, 2>> star_polygon(std::mt19937& rng, bool round, double x_offset) {
    std::uniform_real_distribution<double> u(0, 1);
    const int n = 3 + static_cast<int>(u(rng) * 40);
    std::vector<std::array<double, 2>> pts;
    for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * k / n;
        const double r = round ? 1.0 : 0.5 + u(rng);
        pts.push_back({x_offset + r * std::cos(a), r * std::sin(a)});
    }
    return pts;
}

bool oracle(const Scene& s) {
    for (const SceneSegment& a : s.segments)
        if (!on_hull_oracle(s, a)) return false;
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
    int convex = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const Scene s = parse_scene(polygon_scene(star_polygon(rng, trial % 2 == 0, 1e3 * (trial % 3))), "p");
        CAPTURE(trial);
        CHECK(no_segment_can_block(s) == oracle(s));
        convex += oracle(s) ? 1 : 0;
    }
    CHECK(convex >= 100);  // every regular polygon, so both answers were tested
    CHECK(convex < 200);
}

TEST_CASE("possible blockers: per segment, the quadratic definition, on polygons with plates inside") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    long hull = 0, inner = 0;
    for (int trial = 0; trial < 100; ++trial) {
        const std::vector<std::array<double, 2>> pts = star_polygon(rng, trial % 2 == 0, 0.0);
        // A few short plates well inside (radius < 0.3 of a polygon whose
        // radii are >= 0.5, so inside it whatever its shape).
        std::string plates;
        const int m = trial % 4;
        for (int k = 0; k < m; ++k) {
            const double cx = -0.2 + 0.1 * k, cy = 0.3 * (u(rng) - 0.5);
            plates += fmt::format(R"(, {{"name": "p{}", "material": "m", "side": "both", "points": [[{},{}],[{},{}]]}})", k,
                                  cx, cy, cx + 0.05, cy + 0.05 * u(rng));
        }
        const Scene s = parse_scene(polygon_scene(pts, plates), "p");
        const std::vector<char> blockers = possible_blockers(s);
        REQUIRE(blockers.size() == s.segments.size());
        for (size_t k = 0; k < s.segments.size(); ++k) {
            CAPTURE(trial);
            CAPTURE(k);
            const bool on = on_hull_oracle(s, s.segments[k]);
            CHECK(blockers[k] == (on ? 0 : 1));
            (on ? hull : inner) += 1;
        }
        CHECK(no_segment_can_block(s) == oracle(s));
    }
    // Both answers were tested many times.
    CHECK(hull > 500);
    CHECK(inner > 200);
}

TEST_CASE("possible blockers: a circle's walls block nothing, a lamp inside it does") {
    const Scene s = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}, "l": {"emission": 1}},
        "surfaces": [{"name": "wall", "material": "w", "side": "in", "circle": {"center": [0, 0], "radius": 1, "segments": 999}},
                     {"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]}]})",
                                "circle");
    const std::vector<char> b = possible_blockers(s);
    REQUIRE(b.size() == 1000);
    long count = 0;
    for (char c : b) count += c;
    CHECK(count == 1);
    CHECK(b.back() == 1);  // the lamp, read last
}

TEST_CASE("possible blockers: a wall 1e12 long is no hull wall when a pillar beside it sticks out past its line") {
    // Reduced from a fuzzed scene (fuzz/corpus/regress_far_wall_hull_tolerance.json):
    // the tolerance was 1e-12 of the scene's extent, here 1 unit, so the
    // pillar's 0.8 past the long wall went unseen; the wall blocked nothing
    // and the exact solver's rows summed to 2.6 (negative radiosity).
    const auto scene = [](double far) {
        return parse_scene(fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}},
            "surfaces": [{{"name": "room", "material": "m", "closed": true, "side": "in", "points": [[1,3],[3,0],[0,{}]]}},
                         {{"name": "pillar", "material": "m", "side": "out", "circle": {{"center": [2.5,0.4], "radius": 1.3, "segments": 44}}}}]}})",
                                       far),
                           "far");
    };
    for (double far : {10.0, 1e6, 1e12, 1e15}) {
        CAPTURE(far);
        const Scene s = scene(far);
        const std::vector<char> b = possible_blockers(s);
        for (size_t k = 0; k < s.segments.size(); ++k) {
            CAPTURE(k);
            CHECK(b[k] == (on_hull_oracle(s, s.segments[k]) ? 0 : 1));
        }
        // The long wall from (3, 0) crosses the pillar at any length: it blocks.
        CHECK(b[1] == 1);
    }
}

TEST_CASE("possible blockers: a slanted wall split at rounded points stays a hull wall, far from the origin too") {
    // Thirds are not doubles: the middle corner of the split wall is off the
    // line of its neighbour by a rounding of its coordinates' size, which the
    // text tolerance (1e-12 relative) must absorb at any offset.
    for (double x0 : {0.0, 1e3, 1e6, 1e9}) {
        CAPTURE(x0);
        const Scene s = parse_scene(
            polygon_scene({{x0, 0}, {x0 + 1, 1.0 / 3}, {x0 + 2, 2.0 / 3}, {x0 + 3, 1}, {x0 + 3, 5}, {x0, 5}}), "slant");
        CHECK(no_segment_can_block(s));
    }
}
