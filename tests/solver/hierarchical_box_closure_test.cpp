// Whole-box closure in the hierarchical solver (visibility/box_closure.h,
// HierarchicalOptions::box_closure): a dense forest whose lamp sees
// clusters many layers of shadow away, whose links were split on their
// geometry down to pieces that were each asked and found closed. Against
// the oracle that splits them and asks the pieces (box closure off).
#include <doctest/doctest.h>

#include <fmt/format.h>

#include "engine/scene.h"
#include "solver/hierarchical_solver.h"
#include "support/forest_scene.h"
#include "support/relative_l2.h"

using namespace flatrad;
using flatrad::test::forest_json;
using flatrad::test::relative_l2;

TEST_CASE("hierarchical box closure: links shown closed whole are dropped unsplit, and the solution is the oracle's") {
    // The forest of hierarchical_screens_test.cpp: 6400 sticks in a room of
    // side 8. A link dropped whole carries an exact 0 where the oracle's
    // pieces carry their own answers, 0 or bounds within the visibility
    // tolerance of it: the two solutions may differ only by such bounds
    // and by the links those answers refine differently. The bars are that
    // file's: a relative L2 difference of 1e-3 (a tenth of the 1% error of
    // the 1000-segment forest at eps 5, README "versus"), the balance (a
    // closed room) no worse than the oracle's by more than 5e-3.
    constexpr double same_solution = 1e-3, balance_slack = 5e-3;
    const Scene scene = parse_scene(forest_json(6400, 8, 8, 3), "forest6400.json");
    HierarchicalOptions o;
    o.eps = 10;
    const Solution with = solve_hierarchical(scene, o);
    o.box_closure = false;
    const Solution oracle = solve_hierarchical(scene, o);
    const double diff = relative_l2(scene, with, oracle);
    MESSAGE(fmt::format("relative L2 between them {:.3e}; balance {:.2e} / {:.2e}; links {} / {}; queries {} / {}; "
                        "links dropped whole {}; time {:.2f} / {:.2f} s",
                        diff, with.totals.balance[0], oracle.totals.balance[0], with.stats.links, oracle.stats.links,
                        with.stats.visibility.queries, oracle.stats.visibility.queries, with.stats.visibility.boxed,
                        with.stats.time_s, oracle.stats.time_s));
    CHECK(with.stats.visibility.boxed > 0);
    CHECK(oracle.stats.visibility.boxed == 0);
    CHECK(diff <= same_solution);
    CHECK(with.totals.balance[0] <= oracle.totals.balance[0] + balance_slack);
    // What it is for: fewer links split and asked piece by piece.
    CHECK(with.stats.visibility.queries < oracle.stats.visibility.queries);
}
