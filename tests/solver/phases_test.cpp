// stats.phases (solver/solution.h): the run's stages in order, each with
// its wall time. The names follow the run's shape: for the hierarchical
// solver set-up, tree, self occlusion, then refine / solve rounds (one
// refine per pass, plus the round that found nothing to change, which
// ends the loop before a solve), a separate final solve when the last one
// stopped at the intermediate tolerance, and the result. The times are
// read from one monotonic clock, stage after stage, so none is negative
// and together they cannot exceed time_s, which is read last.
#include <doctest/doctest.h>

#include <fmt/format.h>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "support/forest_scene.h"

using namespace flatrad;
using flatrad::test::forest900;

namespace {

std::vector<std::string> names_of(const SolveStats& st) {
    std::vector<std::string> names;
    for (const Phase& ph : st.phases) names.push_back(ph.name);
    return names;
}

void check_times(const SolveStats& st) {
    double sum = 0;
    for (const Phase& ph : st.phases) {
        CAPTURE(ph.name);
        CHECK(ph.time_s >= 0);
        sum += ph.time_s;
    }
    CHECK(sum <= st.time_s);
}

// The names a hierarchical run with these passes must give: refine k and
// solve k for each pass, then either one more refine (the round that
// changed nothing, when the loop ended early) or none (max_passes reached),
// and "solve final" when the last pass's solve was a loose one.
std::vector<std::string> expected_hierarchical(long passes, bool extra_refine, bool final_solve) {
    std::vector<std::string> names = {"set-up", "tree", "self occlusion"};
    for (long k = 1; k <= passes; ++k) {
        names.push_back(fmt::format("refine {}", k));
        names.push_back(fmt::format("solve {}", k));
    }
    if (extra_refine) names.push_back(fmt::format("refine {}", passes + 1));
    if (final_solve) names.push_back("solve final");
    names.push_back("result");
    return names;
}

void check_hierarchical(const Scene& scene, const HierarchicalOptions& o) {
    const Solution sol = solve_hierarchical(scene, o);
    const SolveStats& st = sol.stats;
    MESSAGE(fmt::format("{} eps {} max_passes {}: passes {}, phases [{}]", scene.file, o.eps, o.max_passes, st.passes,
                        fmt::join(names_of(st), ", ")));
    REQUIRE(st.passes >= 1);
    // The loop ends early (one refine more than the passes) unless it ran
    // max_passes rounds. Only a loop that ended early left its last solve at
    // the loose tolerance (the last allowed pass solves to the full one), so
    // only then is there a final solve.
    const bool ended_early = st.passes < o.max_passes;
    const bool final_solve = ended_early && o.loose_intermediate_solves;
    CHECK(names_of(st) == expected_hierarchical(st.passes, ended_early, final_solve));
    check_times(st);
}

}  // namespace

TEST_CASE("phases: a hierarchical run names its rounds in order, the times within time_s") {
    for (const double eps : {12.0, 2.0}) {
        HierarchicalOptions o;
        o.eps = eps;
        check_hierarchical(forest900(1), o);
        o.max_passes = 1;
        check_hierarchical(forest900(1), o);
        o.max_passes = 2;
        check_hierarchical(forest900(1), o);
        o.max_passes = 16;
        o.loose_intermediate_solves = false;
        check_hierarchical(forest900(1), o);
    }
    check_hierarchical(load_scene(std::string(FLATRAD_DATA_DIR) + "/furnished_room.json"), HierarchicalOptions{});
}

TEST_CASE("phases: a scene where nothing emits has no rounds") {
    const Scene scene = parse_scene(R"({
      "flatrad": 1,
      "materials": {"white": {"reflectance": 0.5}},
      "surfaces": [{"name": "box", "material": "white", "points": [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], "side": "left"}]
    })",
                                    "dark.json");
    const Solution sol = solve_hierarchical(scene, HierarchicalOptions{});
    CHECK(sol.stats.passes == 0);
    CHECK(names_of(sol.stats) == std::vector<std::string>{"set-up", "tree", "self occlusion", "result"});
    check_times(sol.stats);
}

TEST_CASE("phases: the exact solver's form factors, solve and result") {
    const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/default.json");
    const Solution sol = solve_exact(scene, ExactSolverOptions{});
    CHECK(names_of(sol.stats) == std::vector<std::string>{"form factors", "solve", "result"});
    check_times(sol.stats);
    // The form factors' stage holds the form factors' own time.
    CHECK(sol.stats.phases[0].time_s >= sol.stats.form_factor_time_s);
    CHECK(sol.stats.phases[1].time_s == sol.stats.linear_solve_time_s);
}
