// apps/cli/summary.h: the summary says when the linear solve stopped short
// of its residual, and only then.
#include "cli/summary.h"

#include <doctest/doctest.h>

#include <sstream>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"

using namespace flatrad;

TEST_CASE("summary: a residual far above the solvers' targets is warned of, a converged one is not") {
    const Scene s = parse_scene(R"({"flatrad":1,"materials":{"w":{"reflectance":0.5},"l":{"emission":1}},
      "surfaces":[{"name":"room","material":"w","closed":true,"side":"in","points":[[0,0],[2,0],[2,1],[0,1]]},
                  {"name":"lamp","material":"l","side":"both","points":[[0.5,0.5],[1.5,0.6]]}]})",
                                "room.json");
    Solution sol = solve_exact(s, {2, 1});
    const auto summary = [&] {
        std::ostringstream os;
        print_summary(os, s, sol, "");
        return os.str();
    };
    REQUIRE(sol.stats.residual < 1e-12);  // the LU's own: a few ulps
    CHECK(summary().find("warning") == std::string::npos);
    // A GMRES run that stopped short (a stiff scene: the fuzzer's triangle
    // room at reflectance 0.999999 ended at 6.65e-9 after 8242 iterations).
    sol.stats.residual = 6.65e-9;
    const std::string text = summary();
    CHECK(text.find("warning: the linear solve stopped at residual 6.65e-09") != std::string::npos);
}
