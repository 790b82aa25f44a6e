// Tests apps/cli/reference_solution.h: the exact reference, K doubled and
// then the mesh graded until its own error estimate is a tenth of the
// error it judges.
#include "cli/reference_solution.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "support/cli_run.h"

using flatrad::test::TempDir;

namespace {

// A closed unit box lit by its floor, a pillar casting shadows (8 patches):
// real discretisation error (shadow edges, corners) that halves about every
// doubling of K, so each stopping rule is reached within a few solves.
const char* const pillar_box = R"({"flatrad": 1, "name": "box with a pillar",
 "materials": {"white": {"reflectance": 0.6}, "lamp": {"reflectance": 0.0, "emission": 1.0}},
 "surfaces": [
  {"name": "floor", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
  {"name": "walls", "material": "white", "points": [[1,0],[1,1],[0,1],[0,0]], "side": "left"},
  {"name": "pillar", "material": "white", "points": [[0.4,0.3],[0.6,0.3],[0.6,0.5],[0.4,0.5]],
   "closed": true, "side": "out"}]})";

flatrad::ReferenceOptions small(int K, long max_elements) {
    flatrad::ReferenceOptions o;
    o.subdivide = K;
    o.max_elements = max_elements;
    return o;
}

}  // namespace

TEST_CASE("solve_reference: doubles K until its estimate is a tenth of the judged error") {
    TempDir tmp;
    const flatrad::Scene scene = flatrad::load_scene(tmp.file("box.json", pillar_box));
    // A judged error of 1e-3: the K = 4 / K = 8 estimate is above 1e-4 on
    // this scene, so at least two pairs are solved before it is reached.
    constexpr double judged = 1e-3;
    std::vector<long> solved;
    flatrad::ReferenceOptions o = small(4, 8 * 256);
    o.on_solve = [&](long K, long elements) {
        CHECK(elements == 8 * K);
        solved.push_back(K);
    };
    const flatrad::Reference r = flatrad::solve_reference(scene, o, [](const flatrad::Solution&) { return judged; });
    CHECK(r.reached);
    CHECK(r.stopped.empty());
    CHECK(r.error_estimate <= judged / flatrad::reference_margin);
    REQUIRE(r.steps.size() >= 2);
    CHECK(solved == r.ladder_subdivide);
    REQUIRE(r.ladder.size() == r.steps.size() + 1);
    for (size_t k = 0; k < r.ladder.size(); ++k) CHECK(r.ladder_subdivide[k] == 4L << k);  // 4, 8, 16, ...
    CHECK(r.subdivide() == 2 * r.estimate_from_subdivide);  // the finer solve of the last pair
    CHECK(r.steps.back().error_estimate == r.error_estimate);
    // Every step but the last was not good enough.
    for (size_t k = 0; k + 1 < r.steps.size(); ++k) CHECK(r.steps[k].error_estimate > judged / flatrad::reference_margin);
    double total = 0;
    for (const flatrad::Solution& s : r.ladder) total += s.stats.time_s;
    CHECK(r.time_total_s == doctest::Approx(total));
}

TEST_CASE("solve_reference: the element cap stops the doubling, and says so") {
    TempDir tmp;
    const flatrad::Scene scene = flatrad::load_scene(tmp.file("box.json", pillar_box));
    // No error is good enough for a judged error of 0: only the cap stops it.
    const flatrad::Reference r =
        flatrad::solve_reference(scene, small(4, 8 * 16), [](const flatrad::Solution&) { return 0.0; });
    CHECK_FALSE(r.reached);
    CHECK(r.stopped.find("--max-elements") != std::string::npos);
    // K = 4 against 8 (32 and 64 elements); 8 against 16 would pass half
    // the cap (128 > 64), so graded meshes follow, each within 64 and its
    // halves within 128.
    REQUIRE(r.ladder.size() >= 4);
    CHECK(r.ladder_subdivide[0] == 4);
    CHECK(r.ladder_subdivide[1] == 8);
    for (size_t k = 2; k < r.ladder.size(); ++k) {
        CHECK(r.ladder_subdivide[k] == 0);
        CHECK(r.ladder[k].stats.elements <= (k % 2 ? 128 : 64));
    }
    CHECK(r.subdivide() == 0);
    CHECK(r.estimate_from_subdivide == 0);  // a graded pair
    CHECK(std::isfinite(r.error_estimate));

    // No pair at K = 16 within half the cap (256 elements > 64): K is
    // halved until one fits, so that the reference comes with an estimate
    // and room is left to grade.
    const flatrad::Reference halved =
        flatrad::solve_reference(scene, small(16, 8 * 16), [](const flatrad::Solution&) { return 1.0; });
    REQUIRE(halved.ladder.size() >= 2);
    CHECK(halved.ladder_subdivide[0] == 4);
    CHECK(halved.ladder_subdivide[1] == 8);
    CHECK(halved.estimate_from_subdivide == 4);
    CHECK(std::isfinite(halved.error_estimate));

    // No pair at all (K = 1 is 8 elements, its pair 16): K alone, its error unknown.
    const flatrad::Reference alone =
        flatrad::solve_reference(scene, small(1, 8), [](const flatrad::Solution&) { return 1.0; });
    CHECK_FALSE(alone.reached);
    CHECK(alone.ladder.size() == 1);
    CHECK(alone.estimate_from_subdivide == 0);
    CHECK(alone.estimate_from.empty());
    CHECK(std::isinf(alone.error_estimate));
    CHECK(std::isnan(alone.estimate_max_relative));

    // A first K that does not fit is halved like any other (K = 32 under a
    // cap of 128: 16 would fit alone, but the first pair must fit in 64,
    // so K = 4 against 8); only a cap below one element per patch, which
    // no halving helps, is refused, and K < 1.
    CHECK_FALSE(flatrad::reference_fits(scene, 32, 8 * 16));
    const flatrad::Reference from_32 =
        flatrad::solve_reference(scene, small(32, 8 * 16), [](const flatrad::Solution&) { return 1.0; });
    REQUIRE(from_32.ladder_subdivide.size() >= 2);
    CHECK(from_32.ladder_subdivide[0] == 4);
    CHECK_THROWS_AS(flatrad::solve_reference(scene, small(1, 7), [](const flatrad::Solution&) { return 1.0; }),
                    std::invalid_argument);
    CHECK_THROWS_AS(flatrad::solve_reference(scene, small(0, 8 * 16), [](const flatrad::Solution&) { return 1.0; }),
                    std::invalid_argument);
}

TEST_CASE("solve_reference: a mesh-independent scene stops at rounding, not at the cap") {
    // A closed square, every wall emitting and reflecting alike: B = E / (1 -
    // rho) everywhere whatever the mesh, so K and 2K agree to rounding and no
    // finer mesh can help. Judged against an error of 0, only the rounding
    // floor can stop the doubling before the (huge) cap -- unless the two
    // solves agree to the last bit, which counts as reached (0 <= 0 / 10).
    const flatrad::Scene scene = flatrad::load_scene(std::string(FLATRAD_DATA_DIR) + "/uniform_box.json");
    const flatrad::Reference r =
        flatrad::solve_reference(scene, small(1, 1 << 20), [](const flatrad::Solution&) { return 0.0; });
    CHECK(r.ladder.size() == 2);
    CHECK(r.error_estimate <= flatrad::reference_rounding_floor);
    if (r.error_estimate > 0) {
        CHECK_FALSE(r.reached);
        CHECK(r.stopped.find("rounding") != std::string::npos);
    } else {
        CHECK(r.reached);
    }
}

namespace {

// A table in a lit box: its top and legs (two-sided) close a cavity over
// the floor, open only by 1 cm slits under and over each leg. The light
// under the table comes through the slits, and the floor's radiosity
// jumps at the legs: a mesh must be fine there, and need not be anywhere
// else.
const char* const table_box = R"({"flatrad": 1, "name": "table in a box",
 "materials": {"white": {"reflectance": 0.7}, "lamp": {"reflectance": 0.0, "emission": 1.0}},
 "surfaces": [
  {"name": "floor", "material": "white", "points": [[0,0],[1,0]], "side": "left"},
  {"name": "walls", "material": "white", "points": [[1,0],[1,1]], "side": "left"},
  {"name": "ceiling", "material": "lamp", "points": [[1,1],[0,1]], "side": "left"},
  {"name": "wall", "material": "white", "points": [[0,1],[0,0]], "side": "left"},
  {"name": "top", "material": "white", "points": [[0.3,0.3],[0.7,0.3]], "side": "both"},
  {"name": "leg 1", "material": "white", "points": [[0.32,0.01],[0.32,0.29]], "side": "both"},
  {"name": "leg 2", "material": "white", "points": [[0.68,0.01],[0.68,0.29]], "side": "both"}]})";

// Relative L2 of a against b over patches (cli/solution_error.h).
double distance(const flatrad::Scene& scene, const flatrad::Solution& a, const flatrad::Solution& b) {
    return flatrad::compare_solutions(scene, a, b).relative_l2;
}

}  // namespace

TEST_CASE("solve_reference: a graded mesh puts its elements where a uniform one cannot afford them") {
    TempDir tmp;
    const flatrad::Scene scene = flatrad::load_scene(tmp.file("table.json", table_box));
    const long patches = static_cast<long>(scene.patches.size());  // 10
    // The oracle: 256 equal elements per patch, 20x the cap below.
    flatrad::ExactSolverOptions fine;
    fine.subdivide = 256;
    const flatrad::Solution truth = flatrad::solve_exact(scene, fine);

    // A cap of 128 elements: the first pair must fit in half of it, so K = 4
    // is halved to 2 (20 against 40 elements), then graded pairs of up to 64.
    constexpr long cap = 128;
    const flatrad::Reference r =
        flatrad::solve_reference(scene, small(4, cap), [](const flatrad::Solution&) { return 0.0; });
    REQUIRE(r.ladder.size() >= 4);
    CHECK(r.ladder_subdivide[0] == 2);
    CHECK(r.ladder_subdivide[1] == 4);
    CHECK(r.ladder_subdivide.back() == 0);  // the reference is graded
    CHECK(r.subdivide() == 0);
    CHECK(r.mesh_name().rfind("graded (", 0) == 0);
    CHECK(r.estimate_from.find("graded") != std::string::npos);
    for (size_t k = 2; k < r.ladder.size(); ++k) {
        CHECK(r.ladder_subdivide[k] == 0);
        CHECK(r.ladder[k].stats.elements <= cap);
    }
    // Each graded pair: a mesh and its halves.
    for (size_t k = 2; k + 1 < r.ladder.size(); k += 2)
        CHECK(r.ladder[k + 1].stats.elements == 2 * r.ladder[k].stats.elements);
    CHECK_FALSE(r.reached);  // a judged error of 0 is never reached
    CHECK(r.stopped.find("--max-elements") != std::string::npos);

    // Against the finest uniform mesh within the cap, K = 12 (120 elements).
    flatrad::ExactSolverOptions twelve;
    twelve.subdivide = 12;
    const flatrad::Solution uniform = flatrad::solve_exact(scene, twelve);
    const double uniform_error = distance(scene, uniform, truth), graded_error = distance(scene, r.solution(), truth);
    MESSAGE("uniform K = 12 (", uniform.stats.elements, " elements): ", uniform_error, "; graded (",
            r.solution().stats.elements, "): ", graded_error, ", estimated <= ", r.error_estimate);
    CHECK(r.solution().stats.elements <= cap);
    // Grading must pay, by a digit at least (measured: 2.1e-4 against
    // 6.4e-3, 30x, with 128 elements against 120).
    CHECK(graded_error < 0.1 * uniform_error);
    // And its estimate (of the pair's coarser solve) must hold for the
    // reference itself, the finer one.
    CHECK(graded_error <= r.error_estimate);

    // A judged error the uniform pairs cannot serve but a graded one can
    // (5e-3: a target of 5e-4; K = 2 against 4 estimates 4.9e-2): reached,
    // and nothing is said to have stopped it.
    constexpr double judged = 5e-3;
    const flatrad::Reference g =
        flatrad::solve_reference(scene, small(4, cap), [](const flatrad::Solution&) { return judged; });
    REQUIRE(!g.steps.empty());
    MESSAGE("the uniform pair's estimate: ", g.steps.front().error_estimate);
    CHECK(g.steps.front().error_estimate > judged / flatrad::reference_margin);
    CHECK(g.reached);
    CHECK(g.stopped.empty());
    CHECK(g.subdivide() == 0);
    CHECK(g.error_estimate <= judged / flatrad::reference_margin);
    CHECK(patches == 10);
}
