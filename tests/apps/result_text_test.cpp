// apps/cli/result_json.h: result_text writes the result file straight from
// the solution; it must say what the DOM route, format_result(result_json(
// ...)), says: the same JSON value (every double the same bits: its digits
// are the shortest that read back to it, where nlohmann's grisu2 may print
// a 17th), laid out the same (one patch per line).
#include "cli/result_json.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"

using namespace flatrad;

namespace {

bool same_result(const std::string& text, const std::string& dom_text) {
    const auto lines = [](const std::string& t) { return std::count(t.begin(), t.end(), '\n'); };
    const nlohmann::ordered_json a = nlohmann::ordered_json::parse(text), b = nlohmann::ordered_json::parse(dom_text);
    return a == b && a.dump() == b.dump() && lines(text) == lines(dom_text) && text.size() <= dom_text.size();
}

}  // namespace

TEST_CASE("result_text: the DOM route's text, for solved data scenes") {
    for (const char* file : {"/default.json", "/tube_bank.json", "/closed_box.json", "/furnished_room.json"}) {
        CAPTURE(file);
        const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + file);
        const Solution h = solve_hierarchical(scene);
        CHECK(same_result(result_text(scene, h), format_result(result_json(scene, h))));
        const Solution e = solve_exact(scene, {2, 0});
        CHECK(same_result(result_text(scene, e), format_result(result_json(scene, e))));
    }
}

TEST_CASE("result_text: numbers of every form, names that need escaping, no patches") {
    // Values at the switches between plain and exponent notation (decimal
    // exponents -4 and 15), integral values, extremes, negative zero and
    // values that are not finite (null).
    Scene scene = parse_scene(R"({"flatrad": 1, "name": "q\"uote\\ \u00e9",
        "materials": {"w": {"reflectance": 0.5}, "l": {"emission": 1}}, "surfaces": [
        {"name": "tab\t\"name\"", "material": "l", "points": [[0,0],[1e-300,1.5e15]], "side": "left"},
        {"name": "b", "material": "w", "points": [[123456789012345678,-0.0001],[0.00001,-1e22]], "side": "both"}]})",
                                "numbers.json");
    Solution sol = solve_exact(scene, {1, 0});
    const double values[] = {0.0, -0.0, 1.0, -2.0, 0.1, 1e-4, 9.9999e-5, 1e-5, 1.5e15, 1e16, 9.999999999999998e15,
                             123456789.0, 5e-324, std::numeric_limits<double>::max(), 1.0 / 3,
                             std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()};
    size_t k = 0;
    for (PatchResult& p : sol.patches) {
        for (double& r : p.radiosity) r = values[k++ % std::size(values)];
        for (ElementValue& e : p.elements)
            for (double& b : e.B) b = values[k++ % std::size(values)];
        for (size_t extra = 0; extra < std::size(values); ++extra) {
            ElementValue e;
            e.t0 = values[(k + extra) % std::size(values)];
            e.t1 = -values[(k + 2 * extra) % std::size(values)];
            e.B = {values[extra]};
            p.elements.push_back(e);
        }
    }
    const std::string text = result_text(scene, sol);
    CHECK(same_result(text, format_result(result_json(scene, sol))));
    CHECK(text.find("null") != std::string::npos);
    CHECK(text.find("-0.0") != std::string::npos);

    Scene empty = scene;
    empty.patches.clear();
    Solution none = sol;
    none.patches.clear();
    CHECK(same_result(result_text(empty, none), format_result(result_json(empty, none))));
}

TEST_CASE("result_text: a result large enough to be written in two halves says what the DOM says") {
    // A polyline of parallel_result_patches + 3 walls lit on one side (an
    // odd count of patches: the halves differ by one), with made-up values:
    // no solve is needed to check the writing.
    const size_t walls = parallel_result_patches + 3;
    std::string points;
    for (size_t k = 0; k <= walls; ++k) {
        if (k > 0) points += ',';
        points += '[';
        points += std::to_string(k);
        points += ',';
        points += std::to_string((k * 7919) % 13);
        points += ']';
    }
    const Scene scene = parse_scene(R"({"flatrad": 1, "name": "halves", "materials": {"w": {"reflectance": 0.5}},
        "surfaces": [{"name": "wall", "material": "w", "points": [)" + points + R"(], "side": "left"}]})",
                                    "halves.json");
    REQUIRE(scene.patches.size() >= parallel_result_patches);
    REQUIRE(scene.patches.size() % 2 == 1);
    Solution sol;
    sol.method = "hierarchical";
    sol.channels = 1;
    sol.patches.resize(scene.patches.size());
    for (size_t p = 0; p < sol.patches.size(); ++p) {
        const double b = 1.0 / static_cast<double>(p + 3);
        sol.patches[p].radiosity = {b};
        for (size_t e = 0; e <= p % 3; ++e)
            sol.patches[p].elements.push_back({static_cast<double>(e) / 3, static_cast<double>(e + 1) / 3, {b * (e + 1)}});
    }
    sol.totals.add_channel(1.0, 0.75, 0.25);
    const std::string text = result_text(scene, sol);
    // The same value and the same lines: no patch lost or doubled at the
    // join between the halves, the separators right on both sides of it.
    CHECK(same_result(text, format_result(result_json(scene, sol))));
}
