// A solve after a refinement that changed no link keeps the last solve's
// set-up (HierarchicalOptions::keep_unchanged_setup): its leaves, links
// sorted by receiver, row sums and parts. The final solve after a round
// that splits nothing is such a solve. Against the oracle that sets up
// every solve anew: the same solution bit for bit (the operator is the
// same, and so is the Krylov run from the same start).
#include <doctest/doctest.h>

#include <fmt/format.h>
#include <string>

#include "engine/scene.h"
#include "solver/hierarchical_solver.h"
#include "support/forest_scene.h"
#include "support/same_solution.h"

using namespace flatrad;
using flatrad::test::check_same;
using flatrad::test::forest900;

namespace {

// Solves with and without the kept set-up; returns how many solves kept it.
long check_kept_setup_same(const Scene& scene, HierarchicalOptions o) {
    o.keep_unchanged_setup = true;
    const Solution kept = solve_hierarchical(scene, o);
    o.keep_unchanged_setup = false;
    const Solution fresh = solve_hierarchical(scene, o);
    MESSAGE(fmt::format("{} at eps {}: passes {}, setups kept {}, applications {}, residual {:.2e}", scene.file, o.eps,
                        kept.stats.passes, kept.stats.setups_kept, kept.stats.iterations, kept.stats.residual));
    CHECK(fresh.stats.setups_kept == 0);
    check_same(kept, fresh);
    CHECK(kept.stats.residual == fresh.stats.residual);
    CHECK(kept.stats.independent_parts == fresh.stats.independent_parts);
    CHECK(kept.stats.patches_left_out == fresh.stats.patches_left_out);
    CHECK(kept.stats.sampled_tables == fresh.stats.sampled_tables);
    return kept.stats.setups_kept;
}

}  // namespace

TEST_CASE("hierarchical kept set-up: forests and data scenes, the same solution bit for bit as set up anew") {
    long kept = 0;
    for (unsigned seed : {1u, 2u}) {
        CAPTURE(seed);
        const Scene scene = forest900(seed);
        for (double eps : {12.0, 2.0}) {
            HierarchicalOptions o;
            o.eps = eps;
            kept += check_kept_setup_same(scene, o);
        }
    }
    for (const char* name : {"default.json", "furnished_room.json", "tube_bank.json", "closed_box.json"}) {
        CAPTURE(name);
        const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/" + name);
        kept += check_kept_setup_same(scene, HierarchicalOptions{});
    }
    // The path is taken at all (a final round that changes nothing is the
    // common case: each of these runs ends with one).
    CHECK(kept >= 1);
}
