// Reachability from the emitters (solver/reachability.h) and its use by the
// hierarchical solver: surfaces no emitter can reach are left out.
#include "solver/reachability.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "engine/scene.h"
#include "solver/hierarchical_solver.h"

using namespace flatrad;

TEST_CASE("reachability: what a breadth-first search from the sources reaches, along edge directions") {
    // 0 -> 1 -> 2, 3 -> 0 (3 not reached from 0), 4 alone, 5 -> 6; sources 0 and 5.
    const std::vector<DirectedEdge> edges{{0, 1}, {1, 2}, {3, 0}, {5, 6}};
    const std::vector<char> r = reachable_directed(7, edges, {1, 0, 0, 0, 0, 1, 0});
    CHECK(r == std::vector<char>{1, 1, 1, 0, 0, 1, 1});
    CHECK(reachable_directed(3, {}, {0, 0, 0}) == std::vector<char>{0, 0, 0});
    CHECK(reachable_directed(3, {{0, 1}, {1, 2}, {2, 0}}, {0, 0, 1}) == std::vector<char>{1, 1, 1});
}

TEST_CASE("hierarchical: a dark closed box beside a lit one is left out, the lit one unchanged") {
    const std::string lit_box = R"(
        {"name": "lit", "material": "white", "closed": true, "side": "in", "points": [[0,0],[1,0],[1,1],[0,1]]},
        {"name": "lamp", "material": "lamp", "points": [[0.3,0.9],[0.7,0.9]], "side": "right"})";
    const std::string dark_box = R"(,
        {"name": "dark", "material": "white", "closed": true, "side": "in", "points": [[3,0],[4,0],[4,1],[3,1]]})";
    auto scene_text = [&](bool with_dark) {
        return std::string(R"({"flatrad": 1, "materials": {"white": {"reflectance": 0.6},
            "lamp": {"reflectance": 0, "emission": 1}}, "surfaces": [)") +
               lit_box + (with_dark ? dark_box : "") + "]}";
    };
    const Scene both = parse_scene(scene_text(true), "both.json");
    const Scene alone = parse_scene(scene_text(false), "alone.json");
    HierarchicalOptions opt;
    opt.eps = 1e-2;
    const Solution s_both = solve_hierarchical(both, opt);
    const Solution s_alone = solve_hierarchical(alone, opt);
    // The dark box's 4 inner patches: no links, radiosity 0, counted.
    CHECK(s_both.stats.patches_left_out == 4);
    CHECK(s_alone.stats.patches_left_out == 0);
    for (size_t p = 0; p < both.patches.size(); ++p)
        if (both.surfaces[static_cast<size_t>(both.patches[p].surface)].name == "dark")
            CHECK(s_both.patches[p].radiosity[0] == 0);
    // The lit box's radiosity is what it is alone, to the solver's accuracy:
    // eps is relative to the scene's power per patch, so the extra patches
    // refine the lit box a little differently; both are within ~eps of the
    // exact answer, hence 1e-2 relative.
    for (size_t p = 0; p < alone.patches.size(); ++p)
        CHECK(s_both.patches[p].radiosity[0] ==
              doctest::Approx(s_alone.patches[p].radiosity[0]).epsilon(1e-2));
}
