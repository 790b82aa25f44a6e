// The clustered hierarchical solver against the exact solver on random
// closed rooms with random two-sided plates (tests/support/random_rooms.h):
// the accuracy the data scenes show must not be a property of those scenes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <random>
#include <vector>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "support/relative_l2.h"
#include "support/random_rooms.h"

using namespace flatrad;
using flatrad::test::relative_l2;

namespace {

std::string room_json(const test::RandomRoom& room, int per_wall, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> U(0, 1);
    std::string walls, surfaces, materials = R"("wall": {"reflectance": 0.6}, "lamp": {"reflectance": 0.2, "emission": 4})";
    for (int k = 0; k < 4 * per_wall; ++k)
        walls += fmt::format("{}[{},{}]", k ? "," : "", room.segments[static_cast<size_t>(k)].a.x,
                             room.segments[static_cast<size_t>(k)].a.y);
    surfaces = fmt::format(R"({{"name": "room", "material": "wall", "closed": true, "side": "in", "points": [{}]}})", walls);
    for (size_t s = static_cast<size_t>(4 * per_wall), i = 0; s < room.segments.size(); ++s, ++i) {
        const std::string mat = i == 0 ? "lamp" : fmt::format("m{}", i);
        if (i > 0) materials += fmt::format(R"(, "{}": {{"reflectance": {}}})", mat, 0.1 + 0.8 * U(rng));
        surfaces += fmt::format(R"(, {{"name": "p{}", "material": "{}", "side": "both", "points": [[{},{}],[{},{}]]}})", i, mat,
                                room.segments[s].a.x, room.segments[s].a.y, room.segments[s].b.x, room.segments[s].b.y);
    }
    return fmt::format(R"({{"flatrad": 1, "materials": {{{}}}, "surfaces": [{}]}})", materials, surfaces);
}

}  // namespace

TEST_CASE("hierarchical: random occluded rooms agree with the exact solver at eps 1e-3") {
    // The data scenes give 2e-3 (default.json) and 3e-4 (closed_box) at eps
    // 1e-3 (README); the bar is the worse of those with a 2.5x margin for
    // random geometry (measured: 8.1e-4 worst over these 12 rooms).
    constexpr double l2_tol = 5e-3;
    // The exact reference at K = 16 is itself ~1e-3 from the converged
    // answer (compare's estimate on data/default.json: 1.2e-3 at K = 16),
    // under l2_tol.
    constexpr int reference_subdivide = 16;
    std::mt19937_64 rng(11);
    double worst = 0, worst_balance = 0;
    for (int trial = 0; trial < 12; ++trial) {
        const int per_wall = 2 + trial % 3;
        const test::RandomRoom room = test::make_random_room(rng, per_wall, 3 + trial % 5);
        const Scene scene = parse_scene(room_json(room, per_wall, rng), fmt::format("room{}.json", trial));
        CAPTURE(trial);
        HierarchicalOptions o;
        o.eps = 1e-3;
        const Solution h = solve_hierarchical(scene, o);
        const Solution e = solve_exact(scene, {reference_subdivide, 0});
        const double err = relative_l2(scene, h, e);
        CHECK(err <= l2_tol);
        worst = std::max(worst, err);
        worst_balance = std::max(worst_balance, h.totals.balance[0]);
        CHECK(std::isfinite(h.totals.balance[0]));
    }
    MESSAGE(fmt::format("worst relative L2 {:.2e}, worst energy balance {:.2e} over 12 rooms", worst, worst_balance));
}

TEST_CASE("hierarchical: random convex rooms with chain links agree with the exact solver at eps 1e-3") {
    // Chain links (solver/hierarchical_solver.h) on rooms that are one
    // convex loop: random polygons on ellipses (walls of uneven length,
    // some nearly flat turns), three wall materials and a lamp among the
    // walls, and 0 to 3 two-sided plates inside (chain links only where no
    // plate meets the two arcs' hull). Against exact at K = 4 (on a
    // 150-wall room of this kind `flatrad compare` measured the
    // hierarchical error at 2.3e-5 and K = 8 within 9e-7 of K = 16: the
    // mesh's own error is far under the bar), the same bar as the rooms
    // above (measured: 2.5e-4 worst), and with chain links off as well:
    // the error with them
    // at most 1.25x the error without plus 1e-5 (each link, chain or not,
    // is kept within the same share of eps; 1e-5 absorbs rounding-level
    // differences where both are tiny).
    constexpr double l2_tol = 5e-3;
    constexpr double same_error_ratio = 1.25, same_error_floor = 1e-5;
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> U(0, 1);
    long chain_links = 0;
    double worst = 0;
    for (int trial = 0; trial < 10; ++trial) {
        const int n = 40 + static_cast<int>(U(rng) * 160);
        const double rx = 0.5 + 2 * U(rng), ry = 0.5 + 2 * U(rng);
        std::vector<double> t(static_cast<size_t>(n));
        for (double& a : t) a = 2 * std::numbers::pi * U(rng);
        std::sort(t.begin(), t.end());
        std::string walls, lamp;
        for (int k = 0; k <= n; ++k) {
            const double a = t[static_cast<size_t>(k % n)];
            const std::string p = fmt::format("[{:.17g},{:.17g}]", rx * std::cos(a), ry * std::sin(a));
            if (k <= 1) lamp += (k ? "," : "") + p;
            if (k >= 1) walls += (k > 1 ? "," : "") + p;
        }
        std::string surfaces = fmt::format(R"({{"name": "lamp", "material": "lamp", "side": "left", "points": [{}]}})", lamp);
        // The other walls in three runs of materials.
        surfaces += fmt::format(R"(, {{"name": "walls", "material": "w{}", "side": "left", "points": [{}]}})", trial % 3, walls);
        const int plates = trial % 4;
        for (int k = 0; k < plates; ++k) {
            const double cx = 0.5 * rx * (U(rng) - 0.5), cy = 0.5 * ry * (U(rng) - 0.5), h = 0.05 + 0.1 * U(rng), a = U(rng) * 3;
            surfaces += fmt::format(R"(, {{"name": "plate{}", "material": "w1", "side": "both", "points": [[{},{}],[{},{}]]}})", k,
                                    cx - h * std::cos(a), cy - h * std::sin(a), cx + h * std::cos(a), cy + h * std::sin(a));
        }
        const Scene scene = parse_scene(
            fmt::format(R"({{"flatrad": 1, "materials": {{"lamp": {{"reflectance": 0.3, "emission": 2}},
                "w0": {{"reflectance": 0.8}}, "w1": {{"reflectance": 0.45}}, "w2": {{"reflectance": 0.95}}}},
                "surfaces": [{}]}})",
                        surfaces),
            fmt::format("convex{}.json", trial));
        CAPTURE(trial);
        CAPTURE(n);
        HierarchicalOptions with, without;
        with.eps = without.eps = 1e-3;
        without.chain_links = false;
        const Solution h = solve_hierarchical(scene, with);
        const Solution p = solve_hierarchical(scene, without);
        const Solution e = solve_exact(scene, {4, 0});
        const double err = relative_l2(scene, h, e), err_p = relative_l2(scene, p, e);
        CHECK(err <= l2_tol);
        CHECK(err <= same_error_ratio * err_p + same_error_floor);
        CHECK(std::isfinite(h.totals.balance[0]));
        chain_links += h.stats.chain_links;
        worst = std::max(worst, err);
    }
    MESSAGE(fmt::format("worst relative L2 {:.2e} over 10 convex rooms, {} chain links in all", worst, chain_links));
    CHECK(chain_links > 0);
}
