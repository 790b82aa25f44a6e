// The hierarchical solver's answer does not depend on its threads: with one
// thread or two, run after run, the same links, the same visibility work
// and the same radiosity, bit for bit (solver/hierarchical_solver.cpp,
// link_transmittance and behind_closure_screen: answers shared between
// threads are asked in one order, shortcuts take only answers of earlier
// refinement waves, and a query two threads made at once is counted once).
// Before that, two threads could store either order's transmittance of a
// cluster pair (the two differ in the last bits) and a refinement decision
// near its bar could then go either way.
#include <doctest/doctest.h>

#include <fmt/format.h>
#include <omp.h>
#include <string>

#include "engine/scene.h"
#include "solver/hierarchical_solver.h"
#include "support/forest_scene.h"
#include "support/ring_scene.h"
#include "support/same_solution.h"

using namespace flatrad;
using flatrad::test::check_same;
using flatrad::test::forest_json;

namespace {

Solution check_thread_independent(const Scene& scene, HierarchicalOptions o, int runs) {
    // Two threads must really run (a thread limit of 1 would make this
    // test compare one thread with itself).
    REQUIRE(omp_get_thread_limit() >= 2);
    o.threads = 1;
    const Solution one = solve_hierarchical(scene, o);
    MESSAGE(fmt::format("eps {}: links {}, queries {}, screens {}", o.eps, one.stats.links,
                        one.stats.visibility.queries, one.stats.visibility.screens));
    o.threads = 2;
    for (int run = 0; run < runs; ++run) {
        CAPTURE(run);
        const Solution two = solve_hierarchical(scene, o);
        REQUIRE(two.stats.threads == 2);
        check_same(one, two);
    }
    return one;
}

}  // namespace

TEST_CASE("hierarchical threads: a forest's solution is the same with one thread or two, bit for bit") {
    // 1000 sticks at data/forest.json's density: cluster links both ways
    // between crowded clusters, deferred links, bands. Five runs with two
    // threads at two eps (the race this guards against changed the
    // radiosity of 1000-segment forests in 5 runs out of 6).
    const Scene scene = parse_scene(forest_json(1000, 5.8, 5.8, 1), "forest1000.json");
    for (double eps : {2.0, 0.3}) {
        CAPTURE(eps);
        HierarchicalOptions o;
        o.eps = eps;
        check_thread_independent(scene, o, 5);
    }
}

TEST_CASE("hierarchical threads: closure screens give the same solution with one thread or two") {
    // hierarchical_screens_test.cpp's dense forest, where screens answer
    // many links: two threads may prove one screen at once.
    const Scene scene = parse_scene(forest_json(6400, 8, 8, 3), "forest6400.json");
    HierarchicalOptions o;
    o.eps = 10;
    const Solution one = check_thread_independent(scene, o, 2);
    CHECK(one.stats.visibility.screens > 0);  // (what this case is for)
    CHECK(one.stats.visibility.screened > 0);
}

TEST_CASE("hierarchical threads: the operator's passes split over subtrees give one thread's sums") {
    // From 8192 nodes on, with two threads, pull_tables and push_down run
    // disjoint subtrees side by side and the nodes above them on one
    // thread (hierarchical_solver.cpp, OpSchedule). Every table must get
    // its children's shares in one thread's order: a share added out of
    // order changes the last bits, and the links and radiosity follow.
    // A round room with a lamp inside, at a tight eps: walls cut into
    // elements several levels deep (subtrees of elements under a leaf),
    // chains, tables both ways.
    const Scene ring = flatrad::test::ring_scene(9000, 0.7, 0.0, true);
    HierarchicalOptions o;
    o.eps = 1e-3;
    const Solution one = check_thread_independent(ring, o, 3);
    // (What this case is for: elements are nodes, so the operator has more
    // than the 8192 nodes from which it is split.)
    CHECK(one.stats.elements > 8192);
}

TEST_CASE("hierarchical threads: the tree's bottom-up passes over levels give one thread's sums") {
    // build_tree and self_occlusion gather each node from its children a
    // level at a time, levels of 8192 nodes or more on every thread
    // (HierarchicalSolver::bottom_up): the cones, sensitivities and hidden
    // flags must not depend on which thread did which node. 24 000 sticks:
    // the levels near the leaves hold more than 8192 nodes each.
    const Scene scene = parse_scene(forest_json(24000, 15.5, 15.5, 4), "forest24000.json");
    HierarchicalOptions o;
    o.eps = 10;
    const Solution one = check_thread_independent(scene, o, 1);
    CHECK(one.stats.elements > 2 * 8192);
}
