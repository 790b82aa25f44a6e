// The hierarchical solver pays for light only where the solution puts it
// (solver/hierarchical_solver.h, "The first round" and "Deferred
// visibility"): in a scene where something can block, the first refinement
// is against the emission alone, and a link whose error with its
// transmittance unknown is within a share of the bar never asks the
// visibility module. Both against the oracle that has neither (the
// closed-room guess, every surviving link asked) and the exact solver.
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
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "support/forest_scene.h"
#include "support/relative_l2.h"

using namespace flatrad;
using flatrad::test::forest_json;
using flatrad::test::relative_l2;

namespace {

HierarchicalOptions oracle_options(double eps) {
    HierarchicalOptions o;
    o.eps = eps;
    o.emission_first = false;
    o.defer_visibility = false;
    return o;
}

}  // namespace

TEST_CASE("hierarchical dim light: a forest's dim links ask nothing, and the error is the oracle's") {
    // 300 sticks in a room of side 3.2 (data/forest.json's density), against
    // the exact solve at K = 2 (1210 elements). Every link, deferred or
    // not, is kept within its share of eps, so the error may differ from
    // the oracle's only as two solutions of one tolerance do: at most 1.25x
    // plus 1e-5 (as for chain links, hierarchical_random_test.cpp; measured
    // 0.99x-1.01x). With deferred links given the whole bar instead of a
    // tenth (deferred_share 1) eps 2 gives 1.52x: the density's estimate
    // errs the same way on every deferred link.
    constexpr double same_error_ratio = 1.25, same_error_floor = 1e-5;
    // The balance (closed room: the transport's own energy error) may not
    // be worse than the oracle's by more than 5e-3, half the oracle's own
    // at eps 0.1 (1.0e-2). Measured: 2.0e-3 / 1.2e-2 / 9.7e-3 against
    // 5.8e-3 / 1.3e-2 / 1.0e-2 at eps 2 / 0.5 / 0.1; with the whole bar
    // 4.1e-2 at eps 2.
    constexpr double balance_slack = 5e-3;
    const Scene scene = parse_scene(forest_json(300, 3.2, 3.2, 7), "forest300.json");
    const Solution exact = solve_exact(scene, {2, 0});
    for (double eps : {2.0, 0.5, 0.1}) {
        CAPTURE(eps);
        HierarchicalOptions o;
        o.eps = eps;
        const Solution h = solve_hierarchical(scene, o);
        const Solution oracle = solve_hierarchical(scene, oracle_options(eps));
        HierarchicalOptions first_only = oracle_options(eps);
        first_only.emission_first = true;
        const Solution f = solve_hierarchical(scene, first_only);
        const double err = relative_l2(scene, h, exact), err_oracle = relative_l2(scene, oracle, exact),
                     err_first = relative_l2(scene, f, exact);
        MESSAGE(fmt::format("eps {}: L2 {:.3e} / {:.3e} / {:.3e} (default / emission first only / oracle), balance {:.2e} / {:.2e} / {:.2e}, links {} / {} / {}, queries {} / {} / {}, unqueried {}, passes {} / {} / {}",
                            eps, err, err_first, err_oracle, h.totals.balance[0], f.totals.balance[0], oracle.totals.balance[0],
                            h.stats.links, f.stats.links, oracle.stats.links, h.stats.visibility.queries,
                            f.stats.visibility.queries, oracle.stats.visibility.queries, h.stats.unqueried_links,
                            h.stats.passes, f.stats.passes, oracle.stats.passes));
        CHECK(err <= same_error_ratio * err_oracle + same_error_floor);
        CHECK(err_first <= same_error_ratio * err_oracle + same_error_floor);
        CHECK(h.totals.balance[0] <= oracle.totals.balance[0] + balance_slack);
        CHECK(f.totals.balance[0] <= oracle.totals.balance[0] + balance_slack);
        // What it is for: fewer queries (measured 0.43x-0.69x of the
        // oracle's), links carried at the estimate, none in the oracle.
        CHECK(h.stats.visibility.queries < oracle.stats.visibility.queries);
        CHECK(f.stats.visibility.queries < oracle.stats.visibility.queries);
        CHECK(h.stats.unqueried_links > 0);
        CHECK(oracle.stats.unqueried_links == 0);
        CHECK(f.stats.unqueried_links == 0);
        CHECK(h.stats.emission_first);  // 6 layers of shadow across
        CHECK(!oracle.stats.emission_first);
        CHECK(h.stats.passes >= 2);  // from the emission alone: at least one more round
        CHECK(h.stats.passes <= HierarchicalOptions{}.max_passes);
    }
}

TEST_CASE("hierarchical dim light: where nothing can block, the first round and every link are as before") {
    // A convex room: no segment can block, so no link is deferred and the
    // first refinement is against the closed-room guess whatever the
    // options: the same links and the same radiosity, bit for bit.
    const Scene convex = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.6},
        "lamp": {"emission": 1}}, "surfaces": [
        {"name": "lamp", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
        {"name": "walls", "material": "w", "points": [[1,0],[2,0.5],[2,2],[0.5,2.5],[-0.5,1],[0,0]], "side": "left"}]})",
                                     "convex.json");
    HierarchicalOptions o;
    o.eps = 1e-3;
    const Solution a = solve_hierarchical(convex, o);
    o.emission_first = false;
    o.defer_visibility = false;
    const Solution b = solve_hierarchical(convex, o);
    CHECK(a.stats.visibility.queries == 0);
    CHECK(a.stats.unqueried_links == 0);
    CHECK(!a.stats.emission_first);
    CHECK(a.stats.links == b.stats.links);
    CHECK(a.stats.passes == b.stats.passes);
    REQUIRE(a.patches.size() == b.patches.size());
    for (size_t p = 0; p < a.patches.size(); ++p) CHECK(a.patches[p].radiosity == b.patches[p].radiosity);
}

TEST_CASE("hierarchical dim light: a few blockers keep the closed room's first round") {
    // A round room of 400 walls with a lamp inside (0.13 layers of shadow
    // across): most patches see the lamp, the closed room's guess is near
    // the truth, and starting from the emission would cost a round (a
    // 1000-wall room: 0.74 s instead of 0.34 s). The option does not matter
    // there: the same links as with it off.
    const Scene scene = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5},
        "l": {"reflectance": 0.5, "emission": 1}}, "surfaces": [
        {"name": "wall", "material": "w", "side": "in", "circle": {"center": [0, 0], "radius": 1, "segments": 400}},
        {"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]}]})",
                                    "round_lamp.json");
    HierarchicalOptions o;
    const Solution a = solve_hierarchical(scene, o);
    o.emission_first = false;
    const Solution b = solve_hierarchical(scene, o);
    CHECK(a.stats.visibility.queries > 0);
    CHECK(!a.stats.emission_first);
    CHECK(a.stats.links == b.stats.links);
}

TEST_CASE("hierarchical dim light: light behind a screen of sticks is still found") {
    // A lamp in the left third of a long room (walls cut every 0.25, so
    // that the exact solver's uniform mesh resolves them), a screen of
    // sticks across it (eight staggered columns of short slanted sticks,
    // with gaps; 5.2 layers of shadow across the room by its density, so
    // the first round is the emission's) and a plate facing it at the far
    // end. The first round refines nothing beyond the screen, and links
    // there carry the density's estimate until their senders are lit. The
    // light that passes must still be found, as the oracle finds it.
    std::string walls;
    auto point = [&](double x, double y) { walls += fmt::format("{}[{},{}]", walls.empty() ? "" : ",", x, y); };
    for (int k = 0; k < 24; ++k) point(0.25 * k, 0);
    for (int k = 0; k < 4; ++k) point(6, 0.25 * k);
    for (int k = 24; k > 0; --k) point(0.25 * k, 1);
    for (int k = 4; k > 0; --k) point(0, 0.25 * k);
    std::string surfaces = fmt::format(R"({{"name": "room", "material": "wall", "closed": true, "side": "in", "points": [{}]}},
        {{"name": "lamp", "material": "lamp", "side": "right", "points": [[0.4,0.95],[1.2,0.95]]}},
        {{"name": "far", "material": "wall", "side": "left", "points": [[5.9,0.05],[5.9,0.95]]}})", walls);
    int n = 0;
    for (int col = 0; col < 8; ++col)
        for (int k = 0; k < 12; ++k) {
            const double x = 2.0 + 0.08 * col, y = 0.06 + 0.075 * k + 0.025 * (col % 3);
            surfaces += fmt::format(R"(,{{"name": "s{}", "material": "tree", "side": "both", "points": [[{},{}],[{},{}]]}})", n++,
                                    x - 0.02, y, x + 0.02, y + 0.04);
        }
    const Scene scene = parse_scene(R"({"flatrad": 1, "materials": {"wall": {"reflectance": 0.7}, "tree": {"reflectance": 0.3},
        "lamp": {"reflectance": 0, "emission": 10}}, "surfaces": [)" + surfaces + "]}", "screen.json");
    const int far_surface = scene.find_surface("far");
    size_t far = 0;
    while (scene.patches[far].surface != far_surface) ++far;
    // The exact reference at K = 4: the far plate's radiosity there is
    // 1.5789e-2, at K = 8 1.5778e-2 (0.07% apart), far below the bars.
    const Solution exact = solve_exact(scene, {4, 0});
    // One patch at eps 1e-3: the data scenes' relative L2 there is 3e-4 to
    // 2e-3 (README), a single patch may be several times that: 2%
    // (measured 0.13%). Against the oracle the same 2% (measured 0.8%).
    constexpr double exact_tol = 0.02, oracle_tol = 0.02;
    HierarchicalOptions o;
    o.eps = 1e-3;
    const Solution h = solve_hierarchical(scene, o);
    const Solution oracle = solve_hierarchical(scene, oracle_options(o.eps));
    const double want = exact.patches[far].radiosity[0];
    const double got = h.patches[far].radiosity[0], got_oracle = oracle.patches[far].radiosity[0];
    MESSAGE(fmt::format("far plate: exact K = 4 {:.4e}, default {:.4e}, oracle {:.4e}; unqueried links {}, passes {}", want,
                        got, got_oracle, h.stats.unqueried_links, h.stats.passes));
    REQUIRE(want > 0);
    CHECK(h.stats.emission_first);
    CHECK(!oracle.stats.emission_first);
    CHECK(h.stats.unqueried_links > 0);
    CHECK(std::abs(got - want) <= exact_tol * want);
    CHECK(std::abs(got - got_oracle) <= oracle_tol * got_oracle);
}

TEST_CASE("hierarchical dim light: faint overlapping neighbours are not split, at the oracle's error") {
    // A forest's first solve lights its dark part faintly (1e-15 and up);
    // links between overlapping nodes used to split whenever their sender
    // sent anything, down to the segments. Now they stay unsplit while what
    // they may leave out, B_max(s) min(L(s), L(r)), is within a thousandth
    // of the bar. Against the exact solve at K = 2 the error may differ from
    // the oracle's (faint_overlaps_kept off) only as two solutions of one
    // tolerance do: the same 1.25x plus 1e-5 as above. Each kept link loses
    // at most 1e-3 eps_abs, one-signed, so the balance may not be worse
    // than the oracle's by more than the slack above (5e-3).
    constexpr double same_error_ratio = 1.25, same_error_floor = 1e-5, balance_slack = 5e-3;
    const Scene scene = parse_scene(forest_json(600, 4.5, 4.5, 11), "forest600.json");
    const Solution exact = solve_exact(scene, {2, 0});
    for (double eps : {5.0, 1.0}) {
        CAPTURE(eps);
        HierarchicalOptions o;
        o.eps = eps;
        HierarchicalOptions oracle = o;
        oracle.faint_overlaps_kept = false;
        const Solution h = solve_hierarchical(scene, o);
        const Solution ho = solve_hierarchical(scene, oracle);
        const double err = relative_l2(scene, h, exact), err_oracle = relative_l2(scene, ho, exact);
        MESSAGE(fmt::format("eps {}: L2 {:.3e} / {:.3e} (kept / oracle), balance {:.2e} / {:.2e}, links {} / {}", eps,
                            err, err_oracle, h.totals.balance[0], ho.totals.balance[0], h.stats.links, ho.stats.links));
        CHECK(err <= same_error_ratio * err_oracle + same_error_floor);
        CHECK(std::abs(h.totals.balance[0]) <= std::abs(ho.totals.balance[0]) + balance_slack);
        // What it is for: fewer links.
        CHECK(h.stats.links < ho.stats.links);
    }
}

TEST_CASE("hierarchical dim light: vis_eps 0 asks exact visibility of every link, none deferred") {
    // --vis-eps 0 is a request for exact visibility: no link may carry the
    // density's estimate then, so the links the default defers are asked
    // (more queries). A tiny but non-zero tolerance still defers: only 0
    // means "exact", the deferred links' bound being eps's, not vis_eps's.
    const Scene scene = parse_scene(forest_json(300, 3.2, 3.2, 7), "forest300.json");
    HierarchicalOptions o;
    o.eps = 0.5;
    const Solution deferred = solve_hierarchical(scene, o);
    REQUIRE(deferred.stats.unqueried_links > 0);  // (so that the checks below can fail)
    o.vis_eps = 0;
    const Solution exact_vis = solve_hierarchical(scene, o);
    CHECK(exact_vis.stats.unqueried_links == 0);
    CHECK(exact_vis.vis_eps == 0);
    CHECK(exact_vis.stats.visibility.queries > deferred.stats.visibility.queries);
    o.vis_eps = 1e-12;
    CHECK(solve_hierarchical(scene, o).stats.unqueried_links > 0);
}
