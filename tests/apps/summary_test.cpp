// apps/cli/summary.h: the summary says when the linear solve stopped short
// of its residual, or the energy balance is off by more than the default
// eps's accuracy, and only then.
#include "cli/summary.h"

#include <doctest/doctest.h>

#include <sstream>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"

using namespace flatrad;

namespace {

// A small room's exact solution in `channels` channels (a few ulps of
// residual, energy conserved), and its summary as the solution stands.
struct Solved {
    Scene scene;
    Solution solution;
    std::string summary() const {
        std::ostringstream os;
        print_summary(os, scene, solution, "");
        return os.str();
    }
};

Solved solved_room(const char* reflectance) {
    Solved r{parse_scene(std::string(R"({"flatrad":1,"materials":{"w":{"reflectance":)") + reflectance +
                             R"(},"l":{"emission":1}},
      "surfaces":[{"name":"room","material":"w","closed":true,"side":"in","points":[[0,0],[2,0],[2,1],[0,1]]},
                  {"name":"lamp","material":"l","side":"both","points":[[0.5,0.5],[1.5,0.6]]}]})",
                         "room.json"),
             {}};
    r.solution = solve_exact(r.scene, {2, 1});
    return r;
}

}  // namespace

TEST_CASE("summary: a residual far above the solvers' targets is warned of, a converged one is not") {
    Solved r = solved_room("0.5");
    REQUIRE(r.solution.stats.residual < 1e-12);  // the LU's own: a few ulps
    CHECK(r.summary().find("warning") == std::string::npos);
    // A GMRES run that stopped short (a stiff scene: the fuzzer's triangle
    // room at reflectance 0.999999 ended at 6.65e-9 after 8242 iterations).
    r.solution.stats.residual = 6.65e-9;
    CHECK(r.summary().find("warning: the linear solve stopped at residual 6.65e-09") != std::string::npos);
}

TEST_CASE("summary: an energy balance past 1e-2 is warned of, a smaller one is not") {
    Solved r = solved_room("[0.5,0.5,0.5]");
    REQUIRE(r.solution.totals.balance.size() == 3);
    for (double b : r.solution.totals.balance) REQUIRE(b < 1e-12);  // the exact solver conserves energy
    CHECK(r.summary().find("warning") == std::string::npos);
    // The data scenes' largest at the default eps (furnished_room), in one
    // channel: no warning.
    r.solution.totals.balance[1] = 4.2e-3;
    CHECK(r.summary().find("warning") == std::string::npos);
    // A room at reflectance 0.94 with a one-sided plate at the default eps,
    // in one channel.
    r.solution.totals.balance[2] = 1.2e-2;
    CHECK(r.summary().find("warning: energy balance 0.012:") != std::string::npos);
}

TEST_CASE("summary: a hierarchical solve whose rounds ran out before the links settled is warned of") {
    Solved r = solved_room("0.5");
    REQUIRE(r.solution.stats.refined_to_eps);  // the exact solver's: always
    CHECK(r.summary().find("warning") == std::string::npos);
    r.solution.stats.refined_to_eps = false;
    r.solution.stats.passes = 16;
    CHECK(r.summary().find("warning: refinement stopped after 16 rounds with links still above the error bar") !=
          std::string::npos);
}
