// The hierarchical solver with clustering (solver/hierarchical_solver.h):
// white furnace, convergence to the exact solver as eps shrinks, energy
// balance, refusal of a closed reflectance-1 room.
#include "solver/hierarchical_solver.h"
#include "support/relative_l2.h"
#include "support/ring_scene.h"

#include <doctest/doctest.h>

#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <string>

#include "engine/error.h"
#include "solver/exact_solver.h"

using namespace flatrad;
using flatrad::test::relative_l2;

namespace {

// A closed room with an occluding two-sided plate and an "out" pillar, one
// material everywhere (the exact solver's furnace).
std::string furnace_scene(double rho, double emission) {
    return fmt::format(R"({{"flatrad": 1, "name": "furnace",
      "materials": {{"m": {{"reflectance": {}, "emission": {}}}}},
      "surfaces": [
        {{"name": "room", "material": "m", "closed": true, "side": "in",
          "points": [[0,0],[2,0],[2,1],[1.4,1.3],[0,1]]}},
        {{"name": "plate", "material": "m", "points": [[0.3,0.4],[0.9,0.7]], "side": "both"}},
        {{"name": "pillar", "material": "m", "circle": {{"center": [1.5, 0.5], "radius": 0.2, "segments": 16}}, "side": "out"}}
      ]}})",
                       rho, emission);
}

// Open: a lamp over a floor with a one-sided blocker between (its unlit side a sink).
const char* open_plates = R"({"flatrad": 1, "name": "open plates",
  "materials": {"lamp": {"reflectance": 0.2, "emission": 5}, "grey": {"reflectance": 0.6}},
  "surfaces": [
    {"name": "floor", "material": "grey", "points": [[0,0],[3,0]]},
    {"name": "lamp", "material": "lamp", "points": [[2,2],[0.5,2.2]]},
    {"name": "blocker", "material": "grey", "points": [[1.2,1],[1.8,1.1]], "side": "right"}
  ]})";

// Closed box lit by a small lamp, a two-sided shelf casting shadows.
const char* shadow_box = R"({"flatrad": 1, "name": "shadow box",
  "materials": {"white": {"reflectance": 0.7}, "lamp": {"emission": 10},
                "dark": {"reflectance": [0.3]}},
  "surfaces": [
    {"name": "room", "material": "white", "closed": true, "side": "in",
     "points": [[0,0],[3,0],[3,2],[0,2]]},
    {"name": "lamp", "material": "lamp", "points": [[1.2,1.95],[1.8,1.95]], "side": "right"},
    {"name": "shelf", "material": "dark", "points": [[0.8,1.0],[2.0,1.2]], "side": "both"}
  ]})";


}  // namespace

TEST_CASE("hierarchical solver: white furnace at reflectance 0.999 gives E / (1 - rho)") {
    // A leaf's row sum off by d moves B by about d / (1 - rho) = 1000 d
    // here: this holds only because closed patches' leaves get their row
    // deficit (the header's "Row sums"), with approximated visibility too.
    constexpr double furnace_tol = 1e-6;  // the issue's bar
    const Scene scene = parse_scene(furnace_scene(0.999, 1.0), "furnace.json");
    for (double vis_eps : {-1.0, 0.0, 1e-3, 1e-5}) {  // -1: the default, eps / 10
        CAPTURE(vis_eps);
        HierarchicalOptions o;
        o.eps = 1e-2;
        o.vis_eps = vis_eps;
        const Solution sol = solve_hierarchical(scene, o);
        double worst = 0;
        for (const PatchResult& p : sol.patches) {
            worst = std::max(worst, std::abs(p.radiosity[0] - 1000.0) / 1000.0);
            for (const ElementValue& e : p.elements) worst = std::max(worst, std::abs(e.B[0] - 1000.0) / 1000.0);
        }
        MESSAGE(fmt::format("furnace vis_eps {:g}: worst {:.3g}, iterations {}, elements {}, links {}, "
                            "approximated {}", sol.vis_eps, worst, sol.stats.iterations, sol.stats.elements,
                            sol.stats.links, sol.stats.visibility.approximated));
        CHECK(sol.method == "hierarchical");
        CHECK(worst <= furnace_tol);
        CHECK(sol.stats.iterations <= 100);
        CHECK(sol.stats.visibility.queries > 0);  // the plate and pillar really occlude
        CHECK(sol.totals.balance[0] <= 1e-9);
    }
}

TEST_CASE("hierarchical solver: reflectance 1 in a closed room is refused, 0.999999 is solved") {
    const Scene white = parse_scene(furnace_scene(1.0, 1.0), "white.json");
    CHECK_THROWS_AS(solve_hierarchical(white), InputError);
    const Scene almost = parse_scene(furnace_scene(0.999999, 1.0), "almost.json");
    CHECK_NOTHROW(solve_hierarchical(almost));
}

TEST_CASE("hierarchical solver: converges to the exact solver as eps shrinks") {
    // The issue's bars, at the tightest eps of the sweep (3e-5).
    constexpr double tight_tol = 1e-3;
    constexpr double balance_tol = 1e-4;
    constexpr double tightest = 3e-5;
    constexpr int reference_subdivide = 48;
    struct Case {
        std::string name;
        Scene scene;
    };
    std::vector<Case> cases;
    cases.push_back({"default", load_scene(FLATRAD_DATA_DIR "/default.json")});
    cases.push_back({"open plates", parse_scene(open_plates, "open.json")});
    cases.push_back({"shadow box", parse_scene(shadow_box, "shadow.json")});
    for (const Case& k : cases) {
        CAPTURE(k.name);
        // K = 48, not 16: on data/default.json the K = 16 mesh is itself
        // 1.2e-3 (relative L2) from K = 48, as far off as the bar below.
        const Solution exact = solve_exact(k.scene, {reference_subdivide, 0});
        double prev = 1e300;
        for (double eps : {1e-1, 1e-2, 1e-3, 1e-4, tightest}) {
            HierarchicalOptions o;
            o.eps = eps;
            const Solution h = solve_hierarchical(k.scene, o);
            const double err = relative_l2(k.scene, h, exact);
            double balance = 0, absorbed_err = 0;
            for (double b : h.totals.balance) balance = std::max(balance, b);
            // In the closed scenes balance is the transport's own energy error
            // (escaped is 0 where the geometry proves it); the absorbed power's
            // error against the exact solver's is printed beside it.
            for (int c = 0; c < k.scene.channels; ++c)
                absorbed_err = std::max(absorbed_err, std::abs(h.totals.absorbed[static_cast<size_t>(c)] -
                                                               exact.totals.absorbed[static_cast<size_t>(c)]) /
                                                          exact.totals.emitted[static_cast<size_t>(c)]);
            MESSAGE(fmt::format("{}: eps {:g}: L2 {:.3e}, balance {:.2e}, absorbed err {:.2e}, elements {}, links {}, iterations {}, "
                                "time {:.3f}s (exact K=48: {:.3f}s)",
                                k.name, eps, err, balance, absorbed_err, h.stats.elements, h.stats.links, h.stats.iterations,
                                h.stats.time_s, exact.stats.time_s));
            // Below ~1e-4 the K = 48 reference's own discretisation error
            // (measured by `flatrad compare`: K = 32 is 2e-4 from K = 64 on
            // data/default.json) hides any further fall.
            constexpr double reference_floor = 1e-4;
            if (prev > 10 * reference_floor) CHECK(err < prev);
            prev = err;
            if (eps == tightest) {
                CHECK(err <= tight_tol);
                CHECK(balance <= balance_tol);
            }
        }
    }
}

TEST_CASE("hierarchical solver: the closed data scenes' energy balance is within 1e-4 at eps 1e-5") {
    // The issue's balance bar, on every closed scene of data/ (in a closed
    // room nothing escapes: |emitted - absorbed| / emitted is the transport's
    // own energy error). data/default.json meets it from eps 1e-4 (the test
    // above); closed_box and furnished_room only from 1e-5 (1.9e-4 and
    // 2.6e-4 at 1e-4, 1.2e-4 at 3e-5): an element sender's mean crosses the
    // books' 1 mm gaps over the shelves, and many links each within eps
    // add up on one element.
    constexpr double balance_tol = 1e-4;
    constexpr double eps = 1e-5;
    for (const char* name : {"closed_box", "furnished_room", "stiff_room"}) {
        CAPTURE(name);
        const Scene scene = load_scene(fmt::format("{}/{}.json", FLATRAD_DATA_DIR, name));
        HierarchicalOptions o;
        o.eps = eps;
        const Solution h = solve_hierarchical(scene, o);
        for (int c = 0; c < scene.channels; ++c) {
            CAPTURE(c);
            CHECK(h.totals.escaped[static_cast<size_t>(c)] == 0.0);
            CHECK(h.totals.balance[static_cast<size_t>(c)] <= balance_tol);
        }
    }
}

TEST_CASE("hierarchical solver: pays for what the scene uses (DESIGN.md §4)") {
    // A closed convex room: nothing can block, so no visibility query at all.
    const Scene convex = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.6},
        "lamp": {"emission": 1}}, "surfaces": [
        {"name": "lamp", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
        {"name": "walls", "material": "w", "points": [[1,0],[2,0.5],[2,2],[0.5,2.5],[-0.5,1],[0,0]], "side": "left"}]})",
                                     "convex.json");
    const Solution a = solve_hierarchical(convex);
    CHECK(a.stats.visibility.queries == 0);
    CHECK(a.stats.visibility.unoccluded > 0);
    CHECK(a.stats.links > 0);
    // The same room with a plate inside asks for visibility.
    const Scene blocked = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.6},
        "lamp": {"emission": 1}}, "surfaces": [
        {"name": "lamp", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
        {"name": "walls", "material": "w", "points": [[1,0],[2,0.5],[2,2],[0.5,2.5],[-0.5,1],[0,0]], "side": "left"},
        {"name": "plate", "material": "w", "points": [[0.4,1],[1.2,1.1]], "side": "both"}]})",
                                      "blocked.json");
    CHECK(solve_hierarchical(blocked).stats.visibility.queries > 0);

    // A round room of 400 walls with one lamp inside: only the lamp can
    // block, so each query meets at most that one blocker (the walls on the
    // hull are never walked: engine/convex_scene.h, Hierarchy::set_blockers).
    const Scene round = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5},
        "l": {"reflectance": 0.5, "emission": 1}}, "surfaces": [
        {"name": "wall", "material": "w", "side": "in", "circle": {"center": [0, 0], "radius": 1, "segments": 399}},
        {"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]}]})",
                                    "round.json");
    const Solution r = solve_hierarchical(round);
    CHECK(r.stats.visibility.queries > 0);
    CHECK(r.stats.visibility.blockers <= r.stats.visibility.queries);

    // A round room of 400 walls whose lamp is one of them: every cluster
    // link reads and writes tables where all their members face (the
    // linear part, exact there), so no table keeps its samples
    // (solver/table_array.h). Certifying the facing over the link's whole
    // spread only, 94% of them did in such a room of 10^5 walls. The tube
    // bank needs some: its clusters hold tubes facing every way.
    auto point = [](int k) {
        const double t = 2 * std::numbers::pi * (k % 400) / 400;  // the last point is the first
        return fmt::format("[{:.17g},{:.17g}]", std::cos(t), std::sin(t));
    };
    std::string wall = point(1);
    for (int k = 2; k <= 400; ++k) wall += "," + point(k);
    const Scene ring_room = parse_scene(
        R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}, "l": {"reflectance": 0.5, "emission": 1}},
            "surfaces": [{"name": "lamp", "material": "l", "side": "left", "points": [)" +
            point(0) + "," + point(1) + R"(]}, {"name": "wall", "material": "w", "side": "left", "points": [)" + wall +
            "]}]}",
        "ring.json");
    REQUIRE(ring_room.segments.size() == 400);
    const Solution g = solve_hierarchical(ring_room);
    CHECK(g.stats.cluster_links > 0);
    CHECK(g.stats.cluster_tables > 0);
    CHECK(g.stats.sampled_tables == 0);
    const Solution b = solve_hierarchical(load_scene(FLATRAD_DATA_DIR "/tube_bank.json"));
    CHECK(b.stats.sampled_tables > 0);
    CHECK(b.stats.sampled_tables <= b.stats.cluster_tables);
}

TEST_CASE("hierarchical solver: review regressions (lit sides of a loop seeing its sinks, crossing loops, no links)") {
    // A square loop whose first two walls are lit inside and last two only
    // outside: the inside sinks are seen by the lit walls, so they must stay
    // (they were dropped, and the row sums forced to 1 gave B = 2 for 1.18).
    const Scene mixed = parse_scene(R"({"flatrad":1,"materials":{"lamp":{"reflectance":0.5,"emission":1.0},"w":{"reflectance":0.5}},
      "surfaces":[{"name":"a","material":"lamp","side":"left","points":[[0,0],[1,0],[1,1]]},
                  {"name":"b","material":"w","side":"right","points":[[1,1],[0,1],[0,0]]}]})",
                                    "mixed.json");
    // Crossing closed loops: the lamp in their overlap lights A's right
    // wall inside B (it got no link when each loop was taken as a room).
    const Scene cross = parse_scene(R"({"flatrad":1,"materials":{"lamp":{"reflectance":0.0,"emission":1.0},"w":{"reflectance":0.5}},
      "surfaces":[{"name":"A","material":"w","closed":true,"side":"both","points":[[0,0],[2,0],[2,2],[0,2]]},
                  {"name":"B","material":"w","closed":true,"side":"both","points":[[1,0.5],[4,0.5],[4,1.5],[1,1.5]]},
                  {"name":"x","material":"lamp","side":"both","points":[[1.4,0.9],[1.4,1.1]]}]})",
                                    "cross.json");
    // Both within the default eps's ~1% (README) with a 3x margin.
    constexpr double patch_tol = 3e-2;
    for (const Scene* s : {&mixed, &cross}) {
        CAPTURE(s->file);
        const Solution h = solve_hierarchical(*s);
        const Solution e = solve_exact(*s, {8, 0});
        double scale = 0;
        for (const PatchResult& p : e.patches) scale = std::max(scale, p.radiosity[0]);
        for (size_t p = 0; p < s->patches.size(); ++p)
            CHECK(std::abs(h.patches[p].radiosity[0] - e.patches[p].radiosity[0]) <= patch_tol * scale);
    }
    // A lone lamp: no link at all, so everything it sends escapes.
    const Scene one = parse_scene(R"({"flatrad":1,"materials":{"lamp":{"reflectance":0.0,"emission":1.0}},
      "surfaces":[{"name":"l","material":"lamp","side":"left","points":[[0,0],[1,0]]}]})",
                                  "one.json");
    const Solution h = solve_hierarchical(one);
    CHECK(h.totals.escaped[0] == doctest::Approx(1.0));
    CHECK(h.totals.balance[0] <= 1e-12);
}

namespace {

// A one-channel scene whose lamp has B = 1: the hierarchical solution at
// the default eps within patch_tol of the exact one at K elements per patch
// (absolute, i.e. relative to the lamp), and its balance within the bar.
void check_default_eps_against_exact(const Scene& s, int K, double patch_tol, double balance_bar) {
    const Solution h = solve_hierarchical(s);
    const Solution e = solve_exact(s, {K, 0});
    for (size_t p = 0; p < s.patches.size(); ++p) {
        CAPTURE(p);
        CHECK(std::abs(h.patches[p].radiosity[0] - e.patches[p].radiosity[0]) <= patch_tol);
    }
    CHECK(h.totals.balance[0] <= balance_bar);
}

// A 4 x 3 room of one-sided walls (material "w", reflectance rho) with the
// given surfaces after it, which may use "w", a lamp "l" (emission 1) and a
// black "b".
Scene room_of(double rho, const std::string& surfaces, const char* file) {
    return parse_scene(fmt::format(R"({{"flatrad":1,"materials":{{"w":{{"reflectance":{}}},"l":{{"emission":1}},"b":{{"reflectance":0}}}},
      "surfaces":[{{"name":"room","material":"w","closed":true,"side":"in","points":[[0,0],[4,0],[4,3],[0,3]]}},{}]}})",
                                   rho, surfaces),
                       file);
}

}  // namespace

TEST_CASE("hierarchical solver: a black or one-sided plate in a closed room absorbs what reaches it") {
    // A black plate (reflectance 0, no emission, both sides) was no link's
    // sender, so the walls' rows over their links missed what it absorbs.
    // Those rows were closed to 1 as if nothing were seen but walls and the
    // lamp, which gave the absorbed light back: the walls came out at 0.54
    // for 0.32, with a balance of 0.57. Then the rows were left open, and a
    // stiff room's refinement error came back 1 / (1 - rho) times: at 0.99,
    // 1.0e-2 of the lamp's B off, balance 1.2e-2; a one-sided plate (its
    // back a sink) 1.8e-2 and 1.7e-2. In a stiff room such sides are now
    // senders that carry 0, and the rows close (solver/closed_rows.h).
    struct Case {
        double rho;
        const char* plate;
    };
    for (const Case c : {Case{0.9, R"("material":"b","side":"both")"}, Case{0.99, R"("material":"b","side":"both")"},
                         Case{0.99, R"("material":"w","side":"left")"}}) {
        CAPTURE(c.rho);
        CAPTURE(c.plate);
        const Scene s = room_of(c.rho,
                                fmt::format(R"({{"name":"lamp","material":"l","side":"both","points":[[1.5,2],[2.5,2]]}},
                  {{"name":"plate",{},"points":[[0.5,0.5],[1.5,0.5]]}})",
                                            c.plate),
                                "plate.json");
        // As the lamp against the wall below: about the default eps's
        // accuracy on the data scenes, with margin, against the lamp's B of
        // 1; measured at most 4.2e-3 (0.9, below the stiffness bar: rows
        // open), 1.7e-3 and 1.7e-3 off, balance 7e-3, 3.1e-4 and 9.8e-4.
        constexpr double patch_tol = 1e-2, balance_bar = 1e-2;
        check_default_eps_against_exact(s, 8, patch_tol, balance_bar);
    }
}

TEST_CASE("hierarchical solver: a lamp against the wall of a stiff room keeps the rows closed") {
    // The lamp touches the right wall from inside. The walls' outer sides
    // (sinks) were kept as seen because something touched the loop, so no
    // row was closed to 1 and the refinement's error came back 1 / (1 -
    // rho) = 100 times: walls 0.912 for 0.863, balance 5.4e-2. With them
    // proven unseen (solver/sink_visibility.h): 0.8633, balance 8e-5.
    const Scene s = room_of(0.99, R"({"name":"lamp","material":"l","side":"both","points":[[3.5,1],[4,1]]})",
                            "lamp_on_wall.json");
    // About the default eps's accuracy on the data scenes (README: 0.06-0.2%
    // relative L2) with margin, against the lamp's B of 1; measured 4e-4
    // and 8e-5 (the old code: 5.7e-2 and 5.4e-2).
    constexpr double patch_tol = 1e-2, balance_bar = 1e-2;
    check_default_eps_against_exact(s, 16, patch_tol, balance_bar);
}

TEST_CASE("hierarchical solver: sinks seen only from outside a stiff room leave the rows inside closed") {
    // A lamp through the right wall: its outer part sees the walls' outer
    // sides (sinks). And two rooms in a row: each room's outer sides are
    // kept as sinks, the other room lying outside it. Either way no row
    // was closed to 1 and the refinement's error came back 1 / (1 - rho) =
    // 100 times: 5.6e-2 and 3.5e-2 of the lamp's B off, balance 2.8e-2 and
    // 2.6e-2. A closed loop between the rows and the sinks now leaves the
    // rows inside closed (solver/closed_rows.h).
    const Scene through = room_of(0.99, R"({"name":"lamp","material":"l","side":"both","points":[[3.5,1],[4.5,1]]})",
                                  "lamp_through_wall.json");
    const Scene two = room_of(0.99, R"({"name":"room2","material":"w","closed":true,"side":"in","points":[[5,0],[8,0],[8,3],[5,3]]},
                  {"name":"lamp","material":"l","side":"both","points":[[1,1],[2,1]]},
                  {"name":"lamp2","material":"l","side":"both","points":[[6,2],[7,2.5]]})",
                              "two_rooms.json");
    // As the lamp against the wall above; measured 2.6e-4 and 2.4e-4 of the
    // lamp's B, balance 5.5e-5 and 2.5e-4.
    constexpr double patch_tol = 1e-2, balance_bar = 1e-2;
    for (const Scene* s : {&through, &two}) {
        CAPTURE(s->file);
        check_default_eps_against_exact(*s, 16, patch_tol, balance_bar);
    }
}

TEST_CASE("hierarchical solver: a scene whose root cluster is a hierarchy leaf, at any eps") {
    // Two segments: the root cluster is a leaf (its children are sides). A
    // faint cluster's self link may stay unsplit (HierarchicalOptions::
    // faint_overlaps_kept), but a leaf cluster has no table for a link to
    // end at: its self link is always split. At eps 1e6 and above the root's
    // self link once stayed unsplit, and the solve read a table that is not
    // there (a crash).
    const Scene tiny = parse_scene(R"({"flatrad":1,"materials":{"lamp":{"reflectance":0.0,"emission":1.0},"w":{"reflectance":0.5}},
      "surfaces":[{"name":"l","material":"lamp","side":"left","points":[[0,0],[1,0]]},
                  {"name":"w","material":"w","side":"right","points":[[0,1],[1,1]]}]})",
                                   "tiny.json");
    // The linear solve stops at a relative residual of 1e-12; the lamp
    // (reflectance 0) is its emission to that, with a 1000x margin.
    constexpr double solve_tol = 1e-9;
    for (double eps : {1.0, 1e6, 1e300}) {
        CAPTURE(eps);
        HierarchicalOptions o;
        o.eps = eps;
        const Solution h = solve_hierarchical(tiny, o);
        REQUIRE(h.patches.size() == 2);
        CHECK(std::abs(h.patches[0].radiosity[0] - 1.0) <= solve_tol);  // the lamp: its emission, nothing reflected
        CHECK(std::isfinite(h.patches[1].radiosity[0]));
        CHECK(h.patches[1].radiosity[0] >= 0);
        CHECK(h.patches[1].radiosity[0] <= 0.5);  // at most rho times the lamp's, even fully lit
    }
}

TEST_CASE("hierarchical solver: data/default.json and data/tube_bank.json at the default eps, against exact") {
    // The default eps is meant to stay well inside 1% error. On default.json
    // cluster links used to carry 13-23% too little light (the pillar's own
    // segments blocking its arcs' stand-ins, one tau for a whole patch):
    // relative L2 6.4e-3, balance 2.1e-2. On tube_bank.json a box-diagonal
    // stand-in gave tubes' arcs a tau near 0 towards the hot plate: 2.2e-2.
    // Measured after the fixes: 9.7e-4 / balance 1.2e-3 (default, against
    // K = 64) and 6.7e-4 (tube bank, against K = 8). Bars: 3e-3 on L2 and
    // 5e-3 on the closed scene's balance (about 3x the measured, well
    // under the old figures). The references' own errors, as `flatrad
    // compare` estimates them (K against 2K): ~2e-4 at K = 32 for default,
    // 1.4e-3 at K = 8 for the tube bank; both under the bar, so a failure
    // is the hierarchical solver's.
    constexpr double l2_bar = 3e-3;
    constexpr double balance_bar = 5e-3;
    struct Case {
        const char* file;
        int K;
        bool closed;
    };
    for (const Case& c : {Case{"/default.json", 32, true}, Case{"/tube_bank.json", 8, false}}) {
        CAPTURE(c.file);
        const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + c.file);
        const Solution exact = solve_exact(scene, {c.K, 0});
        const Solution h = solve_hierarchical(scene);
        const double err = relative_l2(scene, h, exact);
        double balance = 0;
        for (double b : h.totals.balance) balance = std::max(balance, b);
        MESSAGE(std::string(c.file), " at eps ", HierarchicalOptions{}.eps, ": L2 ", err, ", balance ", balance, ", links ",
                h.stats.links, " (", h.stats.cluster_links, " cluster links)");
        CHECK(h.stats.cluster_links > 0);  // the clusters are exercised
        CHECK(err <= l2_bar);
        if (c.closed) CHECK(balance <= balance_bar);  // open: balance only checks the linear solve
    }
}

TEST_CASE("hierarchical solver: a round room's links per wall do not grow with its wall count") {
    // Exchanges along a curved wall are grazing. The sampled tables err
    // most there (a kink per wall), and an axis-aligned box of an arc
    // reaches past the tangents of walls tens of segments away: both forced
    // splits down to single walls, and links per wall grew with N (78 at
    // 2000 walls, 81 at 8000). Reads through the tables' linear part where
    // every member faces (directional.h, engine/normal_cone.h) and boxes
    // along the wall (engine/oriented_box.h) measured 32 and 22. Bars: no
    // growth from 2000 to 8000, and at most 40 per wall at 8000 (half the
    // old figure).
    auto round = [](int n) {
        return parse_scene(fmt::format(R"({{"flatrad": 1, "materials": {{"w": {{"reflectance": 0.5}},
            "l": {{"reflectance": 0.5, "emission": 1}}}}, "surfaces": [
            {{"name": "wall", "material": "w", "side": "in", "circle": {{"center": [0, 0], "radius": 1, "segments": {}}}}},
            {{"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]}}]}})",
                                       n),
                           fmt::format("round{}.json", n));
    };
    const Solution small = solve_hierarchical(round(2000));
    const Solution large = solve_hierarchical(round(8000));
    const double per_wall_small = static_cast<double>(small.stats.links) / 2000;
    const double per_wall_large = static_cast<double>(large.stats.links) / 8000;
    MESSAGE("links per wall: ", per_wall_small, " at 2000 walls, ", per_wall_large, " at 8000");
    CHECK(per_wall_large <= per_wall_small);
    CHECK(per_wall_large <= 40);

    // And they carry the right light: 1000 walls against exact (K = 2, its
    // own error ~3e-7 by `flatrad compare`), measured L2 1.2e-3; the bar
    // is the default eps's regression bar above.
    constexpr double l2_bar = 3e-3;
    const Scene s = round(1000);
    const double err = relative_l2(s, solve_hierarchical(s), solve_exact(s, {2, 0}));
    MESSAGE("1000 walls: L2 ", err, " against exact");
    CHECK(err <= l2_bar);
}

TEST_CASE("hierarchical solver: chain links along a round room: fewer links, the same error, the furnace holds") {
    // A round room whose walls are one convex loop and whose lamp is one
    // of them: neighbouring arcs exchange their exact etendue as chain
    // links (see the header) instead of being split down to the walls.
    // (tests/support/ring_scene.h: the lamp is one of the walls.)
    // Against exact (K = 1: the walls are the elements, ~1e-8 of mesh
    // error at 2000 walls by `flatrad compare`), with and without chain
    // links. Measured at 2000 walls, eps 3e-3: the errors agree to 3
    // digits. Bars: the error with chains at most 1.25x the one without
    // (each link, chain or not, is kept within the same eps_abs), at most
    // 3e-3 (the default eps's bar), and at least a fifth fewer links.
    constexpr double same_error_ratio = 1.25;
    constexpr double l2_bar = 3e-3;
    const Scene room = test::ring_scene(2000, 0.7, 0);
    HierarchicalOptions with, without;
    without.chain_links = false;
    const Solution c = solve_hierarchical(room, with);
    const Solution p = solve_hierarchical(room, without);
    const Solution e = solve_exact(room, {1, 0});
    const double err_c = relative_l2(room, c, e), err_p = relative_l2(room, p, e);
    MESSAGE("2000-wall ring: L2 ", err_c, " with chain links (", c.stats.links, " links, ", c.stats.chain_links,
            " chain), ", err_p, " without (", p.stats.links, " links); balance ", c.totals.balance[0]);
    CHECK(c.stats.chain_links > 0);
    CHECK(p.stats.chain_links == 0);
    CHECK(c.stats.links <= 0.8 * static_cast<double>(p.stats.links));
    CHECK(err_c <= same_error_ratio * err_p);
    CHECK(err_c <= l2_bar);
    CHECK(c.stats.visibility.queries == 0);
    // A closed room: the balance measures the transport's energy error;
    // measured 1e-5 .. 1e-4 in round rooms at eps 3e-3 (README), bar 1e-3.
    CHECK(c.totals.balance[0] <= 1e-3);

    // White furnace through chain links: every wall emits 1 at reflectance
    // 0.999, so B = 1000 everywhere to the issue's 1e-6.
    constexpr double furnace_tol = 1e-6;
    const Scene furnace = test::ring_scene(3000, 0.999, 1);
    HierarchicalOptions f;
    f.eps = 1e-2;
    const Solution w = solve_hierarchical(furnace, f);
    double worst = 0;
    for (const PatchResult& pr : w.patches) worst = std::max(worst, std::abs(pr.radiosity[0] - 1000.0) / 1000.0);
    MESSAGE("3000-wall white furnace: worst ", worst, ", ", w.stats.chain_links, " chain links of ", w.stats.links);
    CHECK(w.stats.chain_links > 0);
    CHECK(worst <= furnace_tol);
    CHECK(w.stats.iterations <= 100);

    // A few segments inside (a lamp; a plate hugging the wall, 2e-3 from
    // it over ~30 walls): chain links are made only between arcs whose
    // hull none of them meets (chain_clear), and the error against exact
    // is the one without chain links (the ratio bar; measured equal to 3
    // digits). The default eps's bar holds for the lamp alone (1.3e-3);
    // the slit behind the plate has 6.6e-3 with or without chain links
    // (against K = 2, whose own error there is not known), so it is held
    // to the ratio only. More than max_chain_blockers (64) segments that
    // may block (the lamp counts): none at all (a chain link carries its
    // etendue unoccluded).
    for (const char* inside : {R"({"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]})",
                               R"({"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]},
                                  {"name": "plate", "material": "w", "side": "both", "points": [[0.998, -0.05], [0.998, 0.05]]})"}) {
        const Scene s = parse_scene(fmt::format(R"({{"flatrad": 1, "materials": {{"w": {{"reflectance": 0.5}},
            "l": {{"reflectance": 0.5, "emission": 1}}}}, "surfaces": [
            {{"name": "wall", "material": "w", "side": "in", "circle": {{"center": [0, 0], "radius": 1, "segments": 1000}}}},
            {}]}})",
                                                inside),
                                    "inside.json");
        const Solution ci = solve_hierarchical(s, with), pi = solve_hierarchical(s, without);
        const Solution ei = solve_exact(s, {2, 0});
        const double eci = relative_l2(s, ci, ei), epi = relative_l2(s, pi, ei);
        MESSAGE("1000-wall ring with ", s.surfaces.size() - 1, " inside: L2 ", eci, " with chain links (", ci.stats.links,
                " links, ", ci.stats.chain_links, " chain), ", epi, " without (", pi.stats.links, ")");
        CHECK(ci.stats.chain_links > 0);
        CHECK(ci.stats.links < pi.stats.links);
        CHECK(eci <= same_error_ratio * epi);
        if (s.surfaces.size() == 2) CHECK(eci <= l2_bar);
    }
    CHECK(solve_hierarchical(load_scene(FLATRAD_DATA_DIR "/default.json")).stats.chain_links == 0);
    // A round room of 400 walls with its lamp and 64 short plates inside
    // (65 segments that may block: one more than max_chain_blockers), and
    // the same with 63 plates: none, then some.
    for (int plates : {64, 63}) {
        std::string inside;
        for (int k = 0; k < plates; ++k) {
            const double x = -0.6 + 1.2 * (k % 8) / 7, y = -0.6 + 1.2 * (k / 8) / 8;
            inside += fmt::format(R"(, {{"name": "p{}", "material": "w", "side": "both", "points": [[{},{}],[{},{}]]}})", k,
                                  x, y, x + 0.02, y + 0.01);
        }
        const Scene s = parse_scene(fmt::format(R"({{"flatrad": 1, "materials": {{"w": {{"reflectance": 0.5}},
            "l": {{"reflectance": 0.5, "emission": 1}}}}, "surfaces": [
            {{"name": "wall", "material": "w", "side": "in", "circle": {{"center": [0, 0], "radius": 1, "segments": 400}}}},
            {{"name": "lamp", "material": "l", "side": "left", "points": [[0.2, 0.95], [-0.2, 0.95]]}}{}]}})",
                                                inside),
                                    "plates.json");
        CAPTURE(plates);
        if (plates == 64)
            CHECK(solve_hierarchical(s).stats.chain_links == 0);
        else
            CHECK(solve_hierarchical(s).stats.chain_links > 0);
    }
}

TEST_CASE("hierarchical solver: stats.refined_to_eps says whether the rounds ran out before the links settled") {
    // data/default.json takes three rounds at the default eps, the third
    // splitting nothing. Capped at two, the second round still splits, and
    // the solution says it was not refined to eps; with the cap at one
    // nothing shows that a round would split nothing: not refined either.
    const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/default.json");
    HierarchicalOptions o;
    const Solution full = solve_hierarchical(scene, o);
    REQUIRE(full.stats.passes == 3);
    CHECK(full.stats.refined_to_eps);
    o.max_passes = 2;
    const Solution capped = solve_hierarchical(scene, o);
    CHECK(capped.stats.passes == 2);
    CHECK_FALSE(capped.stats.refined_to_eps);
    CHECK(capped.stats.links < full.stats.links);
    o.max_passes = 1;
    CHECK_FALSE(solve_hierarchical(scene, o).stats.refined_to_eps);
    // A scene that emits nothing needs no link: nothing to refine.
    const Scene dark = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}}, "surfaces": [
        {"name": "room", "material": "w", "closed": true, "side": "in", "points": [[0,0],[1,0],[1,1],[0,1]]}]})",
                                   "dark.json");
    CHECK(solve_hierarchical(dark, HierarchicalOptions{}).stats.refined_to_eps);
}
