// Tests apps/cli/reference_solution.h: the exact reference, K doubled until
// its own error estimate is a tenth of the error it judges.
#include "cli/reference_solution.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "engine/scene.h"
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
    CHECK(r.subdivide() == 16);  // 4, 8, 16; 32 would pass 128 elements
    CHECK(r.estimate_from_subdivide == 8);
    CHECK(std::isfinite(r.error_estimate));

    // No pair at all: the first K alone, its error unknown.
    const flatrad::Reference alone =
        flatrad::solve_reference(scene, small(16, 8 * 16), [](const flatrad::Solution&) { return 1.0; });
    CHECK_FALSE(alone.reached);
    CHECK(alone.ladder.size() == 1);
    CHECK(alone.estimate_from_subdivide == 0);
    CHECK(std::isinf(alone.error_estimate));
    CHECK(std::isnan(alone.estimate_max_relative));

    CHECK_FALSE(flatrad::reference_fits(scene, 32, 8 * 16));
    CHECK_THROWS_AS(flatrad::solve_reference(scene, small(32, 8 * 16), [](const flatrad::Solution&) { return 1.0; }),
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
