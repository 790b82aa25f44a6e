// A cluster whose box a blocker not its own cuts in two (engine/box_cut.h;
// solver/hierarchical_solver.cpp, cut_box_share): its links' transmittance
// to its cross-section says nothing of its members. A lit room, a shelf 75
// x 3 cm (a closed box) and a two-sided 4 cm piece 1 mm over the shelf's
// top, 5 cm from its left end: the shelf's end face and the piece share a
// cluster whose box the shelf's top runs across, hiding most of the lines
// to its cross-section from the lamp and the left wall, while nothing
// stands between them and the end face or the piece's top.
#include <doctest/doctest.h>

#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"

using namespace flatrad;

namespace {

const char* shelf_and_piece = R"({"flatrad": 1, "name": "a piece over a shelf",
 "materials": {"wood": {"reflectance": 0.55}, "paint": {"reflectance": 0.8}, "book": {"reflectance": 0.7},
               "lamp": {"reflectance": 0.0, "emission": 12.0}},
 "surfaces": [
  {"name": "room", "material": "paint", "closed": true, "side": "in", "points": [[0,0],[3,0],[3,3],[0,3]]},
  {"name": "lamp", "material": "lamp", "points": [[1.2,2.9],[1.8,2.9]], "side": "right"},
  {"name": "shelf", "material": "wood", "closed": true, "side": "out", "points": [[2.2,1.65],[2.95,1.65],[2.95,1.68],[2.2,1.68]]},
  {"name": "piece", "material": "book", "points": [[2.25,1.681],[2.29,1.681]], "side": "both"}]})";

}  // namespace

TEST_CASE("hierarchical cut boxes: the faces of a cluster cut by a shelf's top get their light") {
    const Scene scene = parse_scene(shelf_and_piece, "shelf_and_piece.json");
    // Patches: the room's 4 walls (0-3), the lamp (4), the shelf's bottom,
    // right end, top and left end (5-8), the piece's top and underside
    // (9, 10).
    REQUIRE(scene.patches.size() == 11);
    constexpr size_t end_face = 8, piece_top = 9;
    // K = 32: those two patches within 0.1% of K = 128 (1.4102 / 1.4114,
    // 2.0768 / 2.0794).
    const Solution exact = solve_exact(scene, {32, 0});
    // Each within 5% at every eps of the sweep. Measured: within 2.4% at
    // 1e-2, 2.1% at 3e-3, 0.7% at 1e-3. The cross-section's transmittance
    // put them 66% and 81% too dark at 1e-2 and 3e-3, 33% and 30% at 1e-3
    // (the error estimate kept each link under the bar, all erring one
    // way). Single patches carry more than the solution's 1% (the furnished
    // room's per-patch median is 1.1% at the default eps): 5% leaves that
    // room and still catches a factor.
    constexpr double patch_tolerance = 0.05;
    for (double eps : {1e-2, 3e-3, 1e-3}) {
        CAPTURE(eps);
        HierarchicalOptions o;
        o.eps = eps;
        const Solution h = solve_hierarchical(scene, o);
        for (size_t p : {end_face, piece_top}) {
            CAPTURE(p);
            const double got = h.patches[p].radiosity[0], want = exact.patches[p].radiosity[0];
            CAPTURE(got);
            CAPTURE(want);
            CHECK(std::abs(got - want) <= patch_tolerance * want);
        }
    }
}
