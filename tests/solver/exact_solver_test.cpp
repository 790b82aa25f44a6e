// The exact reference solver (solver/exact_solver.h) and group form factors
// (solver/group_form_factor.h): stiff furnaces, refusals, energy balance,
// subdivision, and the plate-cylinder closed form.
#include "solver/exact_solver.h"

#include <doctest/doctest.h>

#include <cmath>
#include <fmt/format.h>
#include <string>

#include "engine/error.h"
#include "solver/group_form_factor.h"

using namespace flatrad;

namespace {

// A closed room with an occluding two-sided plate and an "out" pillar, one
// material everywhere.
std::string furnace_scene(double rho, double emission, int pillar_segments = 16) {
    return fmt::format(R"({{"flatrad": 1, "name": "furnace",
      "materials": {{"m": {{"reflectance": {}, "emission": {}}}}},
      "surfaces": [
        {{"name": "room", "material": "m", "closed": true, "side": "in",
          "points": [[0,0],[2,0],[2,1],[1.4,1.3],[0,1]]}},
        {{"name": "plate", "material": "m", "points": [[0.3,0.4],[0.9,0.7]], "side": "both"}},
        {{"name": "pillar", "material": "m", "circle": {{"center": [1.5, 0.5], "radius": 0.2, "segments": {}}}, "side": "out"}}
      ]}})",
                       rho, emission, pillar_segments);
}

}  // namespace

TEST_CASE("exact solver: white furnace at reflectance 0.999 gives E / (1 - rho) everywhere") {
    // Closure holds to ~1e-15 per row; the system's condition is about
    // 1 / (1 - rho) = 1e3, so B is right to ~1e-12 relative. The issue asks 1e-9.
    constexpr double furnace_tol = 1e-9;
    const Scene scene = parse_scene(furnace_scene(0.999, 1.0), "furnace.json");
    for (int K : {1, 3}) {
        const Solution sol = solve_exact(scene, {K, 0});
        CAPTURE(K);
        REQUIRE(sol.patches.size() == scene.patches.size());
        double worst = 0;
        for (const PatchResult& p : sol.patches) {
            worst = std::max(worst, std::abs(p.radiosity[0] - 1000.0) / 1000.0);
            for (const ElementValue& e : p.elements) worst = std::max(worst, std::abs(e.B[0] - 1000.0) / 1000.0);
        }
        CHECK(worst <= furnace_tol);
        CHECK(sol.stats.visibility.queries > 0);  // the plate and pillar really occlude
        CHECK(sol.totals.escaped[0] == 0);         // closed: nothing leaves
        CHECK(sol.totals.balance[0] <= 1e-12);
    }
}

TEST_CASE("exact solver: reflectance 1 in a closed room is refused, 0.999999 is solved") {
    const Scene white = parse_scene(furnace_scene(1.0, 1.0), "white.json");
    CHECK_THROWS_AS(solve_exact(white), InputError);
    try {
        solve_exact(white);
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).find("no unique solution") != std::string::npos);
        CHECK(e.file() == "white.json");
    }
    // Just below 1: the system is stiff (condition ~1e6) but regular.
    // B = 1e6 to ~1e6 * 1e-15 * n relative; 1e-6 leaves room.
    const Scene near = parse_scene(furnace_scene(0.999999, 1.0), "near.json");
    const Solution sol = solve_exact(near);
    for (const PatchResult& p : sol.patches) CHECK(std::abs(p.radiosity[0] - 1e6) / 1e6 <= 1e-6);
}

TEST_CASE("exact solver: reflectance 1 with an absorber or an opening is solved") {
    // An open scene (a room with one wall missing) leaks: unique solution.
    const std::string open = R"({"flatrad": 1, "materials": {"w": {"reflectance": 1, "emission": 1}},
      "surfaces": [{"name": "u", "material": "w", "points": [[0,1],[0,0],[1,0],[1,1]], "side": "left"}]})";
    const Solution sol = solve_exact(parse_scene(open, "open.json"));
    CHECK(sol.totals.escaped[0] > 0);
    CHECK(sol.totals.balance[0] <= 1e-12);
    // One-sided plate inside a white room: its black back absorbs.
    const std::string plate = R"({"flatrad": 1, "materials": {"w": {"reflectance": 1, "emission": 1}},
      "surfaces": [{"name": "room", "material": "w", "closed": true, "side": "in", "points": [[0,0],[1,0],[1,1],[0,1]]},
                   {"name": "p", "material": "w", "points": [[0.3,0.5],[0.7,0.5]]}]})";
    const Solution s2 = solve_exact(parse_scene(plate, "plate.json"));
    CHECK(s2.totals.absorbed[0] == doctest::Approx(s2.totals.emitted[0]).epsilon(1e-12));
}

TEST_CASE("exact solver: energy balance, channels and element layout") {
    const std::string text = R"({"flatrad": 1, "materials": {
        "lamp": {"reflectance": 0, "emission": [3, 2, 1]},
        "red": {"reflectance": [0.8, 0.2, 0.1]},
        "grey": {"reflectance": 0.5}},
      "surfaces": [
        {"name": "room", "material": "grey", "closed": true, "side": "in", "points": [[0,0],[3,0],[3,2],[0,2]]},
        {"name": "lamp", "material": "lamp", "points": [[1,1.9],[2,1.9]], "side": "right"},
        {"name": "box", "material": "red", "closed": true, "side": "out", "points": [[1,0.3],[1.6,0.3],[1.6,0.8],[1,0.8]]},
        {"name": "shelf", "material": "red", "points": [[2,1],[2.8,1.2]], "side": "both"}]})";
    const Scene scene = parse_scene(text, "balance.json");
    const Solution sol = solve_exact(scene, {4, 0});
    REQUIRE(sol.channels == 3);
    for (int c = 0; c < 3; ++c) {
        // Closed scene: emitted = absorbed to rounding; balance uses
        // reciprocity of independently computed pairs (1e-12 each).
        CHECK(sol.totals.balance[static_cast<size_t>(c)] <= 1e-11);
        CHECK(sol.totals.escaped[static_cast<size_t>(c)] == 0);
    }
    CHECK(sol.stats.residual <= 1e-13);
    CHECK(sol.stats.elements == static_cast<long>(scene.patches.size() * 4));
    for (size_t p = 0; p < sol.patches.size(); ++p) {
        const auto& el = sol.patches[p].elements;
        REQUIRE(el.size() == 4);
        double t = 0, mean = 0;
        for (const ElementValue& e : el) {
            CHECK(e.t0 == doctest::Approx(t).epsilon(1e-15));
            t = e.t1;
            mean += e.B[0] / 4;
        }
        CHECK(t == doctest::Approx(1.0));
        CHECK(sol.patches[p].radiosity[0] == doctest::Approx(mean).epsilon(1e-14));
    }
    // The lamp sits near the ceiling and shines down: the floor is brighter
    // than the ceiling in every channel (a sanity check of the lit sides).
    const double floor = sol.patches[0].radiosity[0], ceiling = sol.patches[2].radiosity[0];
    CHECK(floor > ceiling);
}

TEST_CASE("exact solver: emission 0 everywhere gives 0, not NaN") {
    const Scene scene = parse_scene(furnace_scene(0.5, 0.0), "dark.json");
    const Solution sol = solve_exact(scene);
    for (const PatchResult& p : sol.patches) CHECK(p.radiosity[0] == 0);
    CHECK(sol.totals.balance[0] == 0);
}

TEST_CASE("group form factor: plate facing a parallel cylinder converges to the closed form at order 2") {
    // Plate y = 0, x in [b2, b1], lit up; cylinder centre (0, a), radius r.
    // A point at x sees the whole circle with F = a r / (x^2 + a^2), so
    //   F_plate->cyl = r / (b1 - b2) [atan(b1 / a) - atan(b2 / a)].
    // The inscribed n-gon's form factor differs by O(n^-2) (its width
    // seen from the plate shrinks by 1 - cos(pi / n)).
    const double a = 2, r = 0.7, b1 = 1.5, b2 = -0.5;
    const double exact = r / (b1 - b2) * (std::atan(b1 / a) - std::atan(b2 / a));
    std::vector<double> err;
    std::vector<int> ns;
    for (int n = 8; n <= 2048; n *= 2) {
        const std::string text = fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0}}}},
          "surfaces": [{{"name": "plate", "material": "m", "points": [[{}, 0], [{}, 0]]}},
                       {{"name": "cyl", "material": "m", "circle": {{"center": [0, {}], "radius": {}, "segments": {}}}, "side": "out"}}]}})",
                                             b2, b1, a, r, n);
        const Scene scene = parse_scene(text, "cyl.json");
        const GroupFormFactor g = group_form_factor(scene, {0}, {1}, FormFactorMethod::Exact);
        err.push_back(std::abs(g.F - exact));
        ns.push_back(n);
    }
    std::string table;
    for (size_t k = 0; k < err.size(); ++k) {
        const double order = k == 0 ? 0 : std::log2(err[k - 1] / err[k]);
        table += fmt::format("  n = {:5d}  |F_n - F| = {:.3e}  order {:.3f}\n", ns[k], err[k], order);
    }
    MESSAGE("plate -> cylinder convergence:\n" << table);
    // Observed order between successive doublings is 2 up to higher-order
    // terms whose sign depends on where the n-gon's vertices fall relative to
    // the plate (they alternate 2.03, 1.98, 2.04, ... at small n); from
    // n = 256 on they are below 1% of the order.
    for (size_t k = 5; k < err.size(); ++k) CHECK(std::log2(err[k - 1] / err[k]) == doctest::Approx(2.0).epsilon(0.01));
    CHECK(err.back() < 1e-6);
}

TEST_CASE("group form factor: exact equals unoccluded when nothing blocks, and reciprocity of groups") {
    const Scene scene = parse_scene(furnace_scene(0.5, 1.0), "g.json");
    const GroupFormFactor g = group_form_factor(scene, {1}, {2}, FormFactorMethod::Exact);
    const GroupFormFactor u = group_form_factor(scene, {1}, {2}, FormFactorMethod::Unoccluded);
    CHECK(g.F <= u.F + 1e-15);
    // L_A F_AB = L_B F_BA: the plate counts twice (both sides).
    double LA = 0, LB = 0;
    for (const Patch& p : scene.patches) {
        if (p.surface == 1) LA += p.length;
        if (p.surface == 2) LB += p.length;
    }
    CHECK(LA * g.F == doctest::Approx(LB * g.F_reverse).epsilon(1e-14));
    // A room sees all of itself and everything inside: closure of the room row.
    const GroupFormFactor all = group_form_factor(scene, {0}, {0, 1, 2}, FormFactorMethod::Exact);
    CHECK(all.F == doctest::Approx(1.0).epsilon(1e-13));
}
