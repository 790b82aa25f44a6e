// Graded meshes for the exact solver (solver/exact_mesh.h): cutting, and the
// solver on a mesh against its K equal elements and against closed forms.
#include "solver/exact_mesh.h"

#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "solver/exact_solver.h"

using namespace flatrad;

namespace {

// A closed room, one material, an occluding plate: every patch lit both
// ways, shadows, one side right-lit (the plate's "right").
const char* const room = R"({"flatrad": 1, "name": "room",
  "materials": {"m": {"reflectance": 0.6, "emission": 1.0}, "w": {"reflectance": 0.8}},
  "surfaces": [
    {"name": "walls", "material": "w", "closed": true, "side": "in", "points": [[0,0],[2,0],[2,1],[0,1]]},
    {"name": "lamp", "material": "m", "points": [[0.2,0.9],[0.8,0.9]], "side": "right"},
    {"name": "plate", "material": "w", "points": [[0.3,0.4],[0.9,0.7]], "side": "both"}]})";

}  // namespace

TEST_CASE("exact mesh: uniform, halved and marked cuts") {
    const Scene scene = parse_scene(room, "room.json");
    const ExactMesh u = uniform_mesh(scene, 4);
    REQUIRE(u.cuts.size() == scene.patches.size());
    CHECK(u.elements() == 4 * static_cast<long>(scene.patches.size()));
    CHECK(u.cuts[0] == std::vector<double>{0.25, 0.5, 0.75});
    const ExactMesh h = halved(u);
    CHECK(h.elements() == 2 * u.elements());
    CHECK(h.cuts[0] == std::vector<double>{0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875});
    // Marking the first patch's second element and the second patch's last.
    std::vector<int> marked(static_cast<size_t>(u.elements()), 0);
    marked[1] = 1;
    marked[7] = 1;
    const ExactMesh m = split_levels(u, marked);
    CHECK(m.elements() == u.elements() + 2);
    CHECK(m.cuts[0] == std::vector<double>{0.25, 0.375, 0.5, 0.75});
    CHECK(m.cuts[1] == std::vector<double>{0.25, 0.5, 0.75, 0.875});
    CHECK_THROWS_AS(split_levels(u, std::vector<int>(3, 1)), std::invalid_argument);
    // Level 2: the element halved twice over, into quarters.
    std::vector<int> twice(static_cast<size_t>(u.elements()), 0);
    twice[0] = 2;
    CHECK(split_levels(u, twice).cuts[0] == std::vector<double>{0.0625, 0.125, 0.1875, 0.25, 0.5, 0.75});
    CHECK_THROWS_AS(uniform_mesh(scene, 0), std::invalid_argument);
    // An element too short to cut in floating point stays whole.
    ExactMesh tiny;
    tiny.cuts = {{0.5, std::nextafter(0.5, 1.0)}};
    CHECK(halved(tiny).elements() == 5);  // the middle one stays whole
    check_mesh(parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5, "emission": 1}},
        "surfaces": [{"name": "a", "material": "w", "points": [[0,0],[1,0]], "side": "left"}]})", "one.json"),
               halved(tiny));
}

TEST_CASE("exact mesh: check_mesh refuses cuts out of order, outside (0, 1), NaN, or the wrong patch count") {
    const Scene scene = parse_scene(room, "room.json");
    ExactMesh m = uniform_mesh(scene, 2);
    check_mesh(scene, m);
    for (const std::vector<double>& bad : {std::vector<double>{0.0}, std::vector<double>{1.0}, std::vector<double>{0.6, 0.4},
                                           std::vector<double>{0.5, 0.5}, std::vector<double>{std::nan("")},
                                           std::vector<double>{-0.1}}) {
        ExactMesh b = m;
        b.cuts[1] = bad;
        CHECK_THROWS_AS(check_mesh(scene, b), std::invalid_argument);
        CHECK_THROWS_AS(solve_exact(scene, b), std::invalid_argument);
    }
    ExactMesh shorter = m;
    shorter.cuts.pop_back();
    CHECK_THROWS_AS(solve_exact(scene, shorter), std::invalid_argument);
}

TEST_CASE("exact solver on a mesh: K equal elements given as a mesh are the K path's solution") {
    // The same elements (cut points k / K either way; a right-lit patch's
    // oriented cuts 1 - t differ from (K - k) / K by rounding at most), so
    // the same solution to rounding: 1e-12 relative.
    constexpr double same_tol = 1e-12;
    const Scene scene = parse_scene(room, "room.json");
    ExactSolverOptions o;
    o.subdivide = 4;
    const Solution a = solve_exact(scene, o);
    const Solution b = solve_exact(scene, uniform_mesh(scene, 4));
    CHECK(a.subdivide == 4);
    CHECK(b.subdivide == 0);
    CHECK(b.stats.elements == a.stats.elements);
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        REQUIRE(b.patches[p].elements.size() == 4);
        CHECK(b.patches[p].radiosity[0] == doctest::Approx(a.patches[p].radiosity[0]).epsilon(same_tol));
        for (size_t e = 0; e < 4; ++e) {
            CHECK(b.patches[p].elements[e].t0 == doctest::Approx(a.patches[p].elements[e].t0).epsilon(same_tol));
            CHECK(b.patches[p].elements[e].B[0] == doctest::Approx(a.patches[p].elements[e].B[0]).epsilon(same_tol));
        }
    }
}

TEST_CASE("exact solver on a graded mesh: energy balance, white furnace, length-weighted patch means") {
    const Scene scene = parse_scene(room, "room.json");
    // Cut unevenly: patch p's first element cut p + 1 times more.
    ExactMesh m = uniform_mesh(scene, 2);
    for (int r = 0; r < 3; ++r) {
        std::vector<int> marked(static_cast<size_t>(m.elements()), 0);
        size_t first = 0;
        for (size_t p = 0; p < m.cuts.size(); ++p) {
            if (static_cast<int>(p) % 3 >= r) marked[first] = 1;
            first += m.cuts[p].size() + 1;
        }
        m = split_levels(m, marked);
    }
    const Solution s = solve_exact(scene, m);
    // A closed room: emitted = absorbed to rounding (the dense LU's
    // residual, ~1e-15, times the conditioning 1 / (1 - 0.8)).
    constexpr double balance_tol = 1e-12;
    CHECK(s.totals.balance[0] <= balance_tol);
    // Each patch's radiosity is its elements' length-weighted mean.
    for (const PatchResult& pr : s.patches) {
        double sum = 0;
        for (const ElementValue& v : pr.elements) sum += (v.t1 - v.t0) * v.B[0];
        CHECK(pr.radiosity[0] == doctest::Approx(sum).epsilon(1e-15));
    }
    // The elements tile each patch, in order.
    for (const PatchResult& pr : s.patches) {
        CHECK(pr.elements.front().t0 == 0.0);
        CHECK(pr.elements.back().t1 == 1.0);
        for (size_t e = 1; e < pr.elements.size(); ++e) CHECK(pr.elements[e].t0 == pr.elements[e - 1].t1);
    }
    // White furnace on the same mesh: every element at E / (1 - rho), to
    // the conditioning (1e3) times rounding: 1e-9 as the K path's test.
    constexpr double furnace_tol = 1e-9;
    const Scene furnace = parse_scene(R"({"flatrad": 1, "name": "furnace",
      "materials": {"m": {"reflectance": 0.999, "emission": 1.0}},
      "surfaces": [{"name": "walls", "material": "m", "closed": true, "side": "in", "points": [[0,0],[2,0],[2,1],[0,1]]},
                   {"name": "plate", "material": "m", "points": [[0.3,0.4],[0.9,0.7]], "side": "both"}]})",
                                      "furnace.json");
    ExactMesh fm = uniform_mesh(furnace, 3);
    std::vector<int> marked(static_cast<size_t>(fm.elements()), 0);
    for (size_t e = 0; e < marked.size(); e += 2) marked[e] = 1;
    const Solution f = solve_exact(furnace, split_levels(fm, marked));
    for (const PatchResult& pr : f.patches)
        for (const ElementValue& v : pr.elements) CHECK(v.B[0] == doctest::Approx(1000.0).epsilon(furnace_tol));
}
