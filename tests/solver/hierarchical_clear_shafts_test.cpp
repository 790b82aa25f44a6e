// Links whose shaft no blocker can reach do not ask the visibility module
// (HierarchicalOptions::clear_shaft_shortcut; the solver's nothing_between):
// the same links and radiosity, bit for bit, as asking every one of them,
// for far fewer queries.
#include <doctest/doctest.h>

#include <fmt/format.h>
#include <string>

#include "engine/scene.h"
#include "solver/hierarchical_solver.h"
#include "support/ring_scene.h"

using namespace flatrad;

namespace {

// Solves with and without the shortcut; checks that the two agree bit for
// bit and returns {queries with, queries without}.
std::pair<long, long> compare(const Scene& scene) {
    HierarchicalOptions on, off;
    off.clear_shaft_shortcut = false;
    const Solution a = solve_hierarchical(scene, on), b = solve_hierarchical(scene, off);
    CHECK(a.stats.links == b.stats.links);
    CHECK(a.stats.elements == b.stats.elements);
    long differing = 0;
    for (size_t p = 0; p < scene.patches.size(); ++p)
        for (int c = 0; c < scene.channels; ++c)
            differing += a.patches[p].radiosity[static_cast<size_t>(c)] != b.patches[p].radiosity[static_cast<size_t>(c)];
    CHECK(differing == 0);
    return {a.stats.visibility.queries, b.stats.visibility.queries};
}

}  // namespace

TEST_CASE("clear shafts: a round room with a lamp inside asks only the lamp's shadows") {
    // Measured at 10^5 walls: 45 765 queries against 427 863, 387 569 of
    // which found their shaft empty. Bar: at most a quarter here.
    const auto [with, without] = compare(flatrad::test::ring_scene(3000, 0.7, 0, true));
    MESSAGE("3000-wall ring with a lamp inside: ", with, " queries with the shortcut, ", without, " without");
    CHECK(with > 0);  // the lamp's shadows are still asked
    CHECK(4 * with <= without);
}

TEST_CASE("clear shafts: the data scenes with few blockers, and a crowded one, are unchanged") {
    // data/default.json and data/stiff_room.json have a few blockers each
    // (the shortcut spares some of their queries); data/tube_bank.json has
    // more than 64 segments that may block: the shortcut is not tried there.
    for (const char* name : {"default", "stiff_room", "tube_bank"}) {
        CAPTURE(name);
        const auto [with, without] = compare(load_scene(fmt::format("{}/{}.json", FLATRAD_DATA_DIR, name)));
        MESSAGE(std::string(name), ": ", with, " queries with the shortcut, ", without, " without");
        CHECK(with <= without);
    }
}
