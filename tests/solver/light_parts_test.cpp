// Independent sub-scenes (solver/light_parts.h) and the hierarchical solver
// solving them apart: the same solution as one Krylov run over everything.
#include "solver/light_parts.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "support/relative_l2.h"

using namespace flatrad;

TEST_CASE("connected parts: components of a small graph, isolated vertices alone") {
    // 0-1-2, 3-4, 5 alone, 6-6 (a loop on itself).
    const LightParts p = connected_parts(7, {{0, 1}, {2, 1}, {4, 3}, {6, 6}});
    CHECK(p.count == 4);
    CHECK(p.part[0] == p.part[1]);
    CHECK(p.part[1] == p.part[2]);
    CHECK(p.part[3] == p.part[4]);
    CHECK(p.part[0] != p.part[3]);
    CHECK(p.part[5] != p.part[0]);
    CHECK(p.part[5] != p.part[3]);
    CHECK(p.part[6] != p.part[5]);
    // Numbered in order of first vertex.
    CHECK(p.part[0] == 0);
    CHECK(p.part[3] == 1);
    CHECK(p.part[5] == 2);
    CHECK(p.part[6] == 3);
    CHECK(connected_parts(0, {}).count == 0);
}

namespace {

// Two closed rooms side by side (a wall apart), each with its own lamp and
// furniture, and a third, dark room: no light passes between them.
std::string three_rooms(double rho_b) {
    return R"({"flatrad": 1, "name": "three rooms",
  "materials": {"wall": {"reflectance": [0.6, 0.5, 0.4]}, "lamp": {"emission": [4, 3, 2]},
                "b": {"reflectance": [)" +
           std::to_string(rho_b) + R"(, 0.9, 0.2]}, "lamp2": {"emission": [1, 2, 3], "reflectance": 0.1}},
  "surfaces": [
    {"name": "room a", "material": "wall", "closed": true, "side": "in", "points": [[0,0],[2,0],[2,1],[0,1]]},
    {"name": "lamp a", "material": "lamp", "points": [[0.8,0.95],[1.2,0.95]], "side": "right"},
    {"name": "plate a", "material": "b", "points": [[0.4,0.3],[0.9,0.5]], "side": "both"},
    {"name": "room b", "material": "b", "closed": true, "side": "in", "points": [[3,0],[4,0],[4,2],[3,2]]},
    {"name": "lamp b", "material": "lamp2", "points": [[3.2,0.1],[3.2,0.6]], "side": "left"},
    {"name": "pillar b", "material": "wall", "circle": {"center": [3.6, 1.2], "radius": 0.2, "segments": 12}, "side": "out"},
    {"name": "room c", "material": "wall", "closed": true, "side": "in", "points": [[5,0],[6,0],[6,1],[5,1]]}
  ]})";
}

// GMRES stops at ||r||_2 <= 1e-12 ||E||_2 in either run (per part, or over
// everything), and ||E||_2 <= sqrt(n) max E with n ~ 1000 leaves here; with
// reflectances <= 0.9 the operator's inverse is at most ~10 in norm, so the
// two solutions agree to ~3e-10 of the largest radiosity (not of each
// patch's: a dim patch's own digits are not what the residual controls):
// allowed 1e-9 of the largest.
constexpr double same_solution_tol = 1e-9;

}  // namespace

TEST_CASE("hierarchical solver: independent rooms are solved apart, to the same solution") {
    for (double rho_b : {0.3, 0.9}) {
        const Scene scene = parse_scene(three_rooms(rho_b), "three.json");
        HierarchicalOptions apart, together;
        together.solve_parts_apart = false;
        const Solution a = solve_hierarchical(scene, apart);
        const Solution t = solve_hierarchical(scene, together);
        CAPTURE(rho_b);
        CHECK(a.stats.independent_parts == 2);  // the dark room has no links
        CHECK(t.stats.independent_parts == 1);
        CHECK(a.stats.patches_left_out > 0);    // room c
        CHECK(a.stats.links == t.stats.links);
        CHECK(a.stats.residual <= 1e-11);
        double worst = 0, largest = 0;
        for (size_t p = 0; p < scene.patches.size(); ++p)
            for (int c = 0; c < scene.channels; ++c) {
                const double x = a.patches[p].radiosity[static_cast<size_t>(c)];
                const double y = t.patches[p].radiosity[static_cast<size_t>(c)];
                worst = std::max(worst, std::abs(x - y));
                largest = std::max(largest, std::abs(y));
                if (y == 0) CHECK(x == 0);
            }
        REQUIRE(largest > 0);
        CHECK(worst <= same_solution_tol * largest);
        for (int c = 0; c < scene.channels; ++c)
            CHECK(std::abs(a.totals.absorbed[static_cast<size_t>(c)] - t.totals.absorbed[static_cast<size_t>(c)]) <=
                  same_solution_tol * t.totals.absorbed[static_cast<size_t>(c)]);
    }
}

TEST_CASE("hierarchical solver: a convex room skips the light-flow check, with what the check would find") {
    // Closed convex rooms (every wall on the hull, every patch escape-free,
    // every patch reflecting in some channel): the first one has a wall on
    // the lamp's own line (reached only by reflection), the second is a
    // round room with the lamp among its walls and a channel that only some
    // walls reflect.
    const std::string collinear = R"({"flatrad": 1, "materials": {"w": {"reflectance": [0.6, 0.2, 0.05]},
        "lamp": {"emission": [1, 0.5, 2], "reflectance": 0.1}}, "surfaces": [
        {"name": "lamp", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
        {"name": "walls", "material": "w", "points": [[1,0],[1.5,0],[2,0.5],[2,2],[0.5,2.5],[-0.5,1],[0,0]], "side": "left"}]})";
    const std::string round = R"({"flatrad": 1, "materials": {"w": {"reflectance": [0.5, 0, 0.7]},
        "v": {"reflectance": [0.5, 0.8, 0]}, "l": {"reflectance": 0.5, "emission": [1, 2, 3]}}, "surfaces": [
        {"name": "arc", "material": "w", "side": "left", "points": [[1,0],[0.7071,0.7071],[0,1],[-0.7071,0.7071],[-1,0]]},
        {"name": "lamp", "material": "l", "side": "left", "points": [[-1,0],[-0.7071,-0.7071]]},
        {"name": "rest", "material": "v", "side": "left", "points": [[-0.7071,-0.7071],[0,-1],[0.7071,-0.7071],[1,0]]}]})";
    for (const std::string& text : {collinear, round}) {
        const Scene scene = parse_scene(text, "convex.json");
        for (double eps : {1e-2, 1e-4}) {
            HierarchicalOptions shortcut, checked;
            shortcut.eps = checked.eps = eps;
            checked.convex_room_shortcut = false;
            const Solution a = solve_hierarchical(scene, shortcut);
            const Solution b = solve_hierarchical(scene, checked);
            CAPTURE(scene.name);
            CAPTURE(eps);
            CHECK(b.stats.patches_left_out == 0);
            CHECK(b.stats.independent_parts == 1);
            CHECK(a.stats.patches_left_out == b.stats.patches_left_out);
            CHECK(a.stats.independent_parts == b.stats.independent_parts);
            CHECK(a.stats.links == b.stats.links);
            // With nothing dark and one part, both runs apply the same
            // unrestricted operator in the same order, and a convex room asks
            // no visibility (no thread-order effect): the same bits.
            for (size_t p = 0; p < scene.patches.size(); ++p)
                CHECK(a.patches[p].radiosity == b.patches[p].radiosity);
        }
    }
}

TEST_CASE("hierarchical solver: a room without an emitter starts dark and is not refined") {
    // Room c of three_rooms holds no emitting side, so no light can reach
    // it (solver/rooms.h): the first round starts it at 0 and splits none of
    // its links. The oracle (dark_rooms_start_dark off) starts it at the
    // closed room's guess and cuts its sides into elements, all of them 0
    // after the solve. Both against the exact solver: the lit rooms' error
    // is the oracle's, as two solutions of one tolerance are (at most 1.25x
    // plus 1e-5, as hierarchical_dim_light_test.cpp allows for its own
    // oracle).
    constexpr double same_error_ratio = 1.25, same_error_floor = 1e-5;
    const Scene scene = parse_scene(three_rooms(0.3), "three.json");
    HierarchicalOptions on, off;
    on.eps = off.eps = 1e-3;
    off.dark_rooms_start_dark = false;
    const Solution a = solve_hierarchical(scene, on);
    const Solution o = solve_hierarchical(scene, off);
    const Solution exact = solve_exact(scene, {8, 0});
    size_t dark = 0, oracle_elements = 0;
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        if (scene.surfaces[static_cast<size_t>(scene.patches[p].surface)].name != "room c") continue;
        ++dark;
        CHECK(a.patches[p].elements.size() == 1);
        oracle_elements += o.patches[p].elements.size();
        for (double b : a.patches[p].radiosity) CHECK(b == 0);
    }
    REQUIRE(dark == 4);
    CHECK(oracle_elements > dark);  // the oracle does cut them (so that the check above can fail)
    CHECK(a.stats.elements < o.stats.elements);
    const double err = flatrad::test::relative_l2(scene, a, exact), oracle = flatrad::test::relative_l2(scene, o, exact);
    CAPTURE(err);
    CAPTURE(oracle);
    CHECK(err <= same_error_ratio * oracle + same_error_floor);
}
