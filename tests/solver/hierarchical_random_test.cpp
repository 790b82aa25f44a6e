// The clustered hierarchical solver against the exact solver on random
// closed rooms with random two-sided plates (tests/support/random_rooms.h):
// the accuracy the data scenes show must not be a property of those scenes.
#include <doctest/doctest.h>

#include <cmath>
#include <fmt/format.h>
#include <random>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "support/random_rooms.h"

using namespace flatrad;

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

double relative_l2(const Scene& scene, const Solution& h, const Solution& e) {
    double num = 0, den = 0;
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const double L = scene.patches[p].length;
        const double d = h.patches[p].radiosity[0] - e.patches[p].radiosity[0];
        num += L * d * d;
        den += L * e.patches[p].radiosity[0] * e.patches[p].radiosity[0];
    }
    return std::sqrt(num / den);
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
