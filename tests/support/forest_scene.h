#pragma once
// Forest scenes for the solver's tests: the forests of `scripts/make-scene
// N --density D` in small, written as scene JSON.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/geometry.h"
#include "engine/scene.h"

namespace flatrad::test {

inline double point_segment_distance(Vec2 p, const Segment& s) {
    const Vec2 d = s.b - s.a;
    const double t = std::clamp(dot(p - s.a, d) / norm_squared(d), 0.0, 1.0);
    return distance(p, lerp(s.a, s.b, t));
}

// 0 where they cross, else the least distance from an end to the other.
inline double segment_distance(const Segment& s, const Segment& q) {
    const double o1 = orient(s.a, s.b, q.a), o2 = orient(s.a, s.b, q.b);
    const double o3 = orient(q.a, q.b, s.a), o4 = orient(q.a, q.b, s.b);
    if ((o1 > 0) != (o2 > 0) && (o3 > 0) != (o4 > 0)) return 0;
    return std::min({point_segment_distance(s.a, q), point_segment_distance(s.b, q), point_segment_distance(q.a, s),
                     point_segment_distance(q.b, s)});
}

// A room of width x height (reflectance 0.7, lit inside), a lamp under the
// ceiling at [0.4, 0.6] of its width (emission 10, lit downwards) and
// `sticks` two-sided sticks 0.05-0.15 long (reflectance 0.3) at random
// positions and angles, none within 0.01 of another, 0.1 from the walls
// and below the lamp. A grid of cells of side 0.2 finds the neighbours.
inline std::string forest_json(int sticks, double width, double height, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Segment> placed;
    std::string surfaces = fmt::format(
        R"({{"name": "room", "material": "wall", "closed": true, "side": "in", "points": [[0,0],[{0},0],[{0},{1}],[0,{1}]]}},)"
        R"({{"name": "lamp", "material": "lamp", "side": "right", "points": [[{2},{3}],[{4},{3}]]}})",
        width, height, 0.4 * width, height - 0.03, 0.6 * width);
    const double margin = 0.1, cell = 0.2;
    const int nx = static_cast<int>(width / cell) + 1, ny = static_cast<int>(height / cell) + 1;
    std::vector<std::vector<int>> grid(static_cast<size_t>(nx * ny));
    auto cell_of = [&](Vec2 p) {
        return std::pair{std::clamp(static_cast<int>(p.x / cell), 0, nx - 1), std::clamp(static_cast<int>(p.y / cell), 0, ny - 1)};
    };
    int tries = 0;
    while (static_cast<int>(placed.size()) < sticks && ++tries < 10000000) {
        const double len = 0.05 + 0.1 * U(rng), a = 2 * std::numbers::pi * U(rng);
        const Vec2 c{margin + (width - 2 * margin) * U(rng), margin + (height - 2 * margin - 0.1) * U(rng)};
        const Vec2 d{0.5 * len * std::cos(a), 0.5 * len * std::sin(a)};
        const Segment s{c - d, c + d};
        // A stick is at most 0.15 long: its neighbours within 0.01 have
        // their midpoints within 0.16 of its own, in the 3 x 3 cells around.
        const auto [cx, cy] = cell_of(c);
        bool clear = true;
        for (int gx = std::max(0, cx - 1); gx <= std::min(nx - 1, cx + 1) && clear; ++gx)
            for (int gy = std::max(0, cy - 1); gy <= std::min(ny - 1, cy + 1) && clear; ++gy)
                for (int q : grid[static_cast<size_t>(gx * ny + gy)])
                    if (segment_distance(s, placed[static_cast<size_t>(q)]) < 0.01) {
                        clear = false;
                        break;
                    }
        if (!clear) continue;
        grid[static_cast<size_t>(cx * ny + cy)].push_back(static_cast<int>(placed.size()));
        placed.push_back(s);
        surfaces += fmt::format(R"(,{{"name": "t{}", "material": "tree", "side": "both", "points": [[{:.17g},{:.17g}],[{:.17g},{:.17g}]]}})",
                                placed.size(), s.a.x, s.a.y, s.b.x, s.b.y);
    }
    REQUIRE(static_cast<int>(placed.size()) == sticks);
    return R"({"flatrad": 1, "materials": {"wall": {"reflectance": 0.7}, "tree": {"reflectance": 0.3},
        "lamp": {"reflectance": 0, "emission": 10}}, "surfaces": [)" + surfaces + "]}";
}

// The 900-stick forest in a 3 x 3 room that several solver tests compare
// options on, for a seed.
inline Scene forest900(unsigned seed) {
    return parse_scene(forest_json(900, 3, 3, seed), fmt::format("forest900-{}.json", seed));
}

}  // namespace flatrad::test
