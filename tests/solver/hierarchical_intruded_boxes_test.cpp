// A cluster whose box a long blocker not its own runs through
// (engine/box_intrusion.h; solver/hierarchical_solver.cpp,
// intruded_box_share): its links' transmittance to its cross-section says
// nothing of its members. A lit room, a shelf 75 x 3 cm (a closed box) and
// a two-sided 4 cm piece 1 mm over the shelf's top: 5 cm from its left end,
// or straddling that end. The shelf's end face and the piece share a
// cluster whose box the shelf's top runs across (or into, ending at the
// end face's corner), hiding most of the lines to its cross-section from
// the lamp and the left wall, while nothing stands between them and the
// end face or the piece's top.
#include <doctest/doctest.h>

#include <fmt/format.h>
#include <string>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"

using namespace flatrad;

namespace {

// The piece from x0 to x0 + 0.04, 1 mm over the shelf's top.
std::string shelf_and_piece(double x0) {
    return fmt::format(R"({{"flatrad": 1, "name": "a piece over a shelf",
 "materials": {{"wood": {{"reflectance": 0.55}}, "paint": {{"reflectance": 0.8}}, "book": {{"reflectance": 0.7}},
               "lamp": {{"reflectance": 0.0, "emission": 12.0}}}},
 "surfaces": [
  {{"name": "room", "material": "paint", "closed": true, "side": "in", "points": [[0,0],[3,0],[3,3],[0,3]]}},
  {{"name": "lamp", "material": "lamp", "points": [[1.2,2.9],[1.8,2.9]], "side": "right"}},
  {{"name": "shelf", "material": "wood", "closed": true, "side": "out", "points": [[2.2,1.65],[2.95,1.65],[2.95,1.68],[2.2,1.68]]}},
  {{"name": "piece", "material": "book", "points": [[{},1.681],[{},1.681]], "side": "both"}}]}})",
                       x0, x0 + 0.04);
}

}  // namespace

TEST_CASE("hierarchical intruded boxes: the faces of a cluster a shelf's top runs through get their light") {
    // Patches: the room's 4 walls (0-3), the lamp (4), the shelf's bottom,
    // right end, top and left end (5-8), the piece's top and underside
    // (9, 10).
    constexpr size_t end_face = 8, piece_top = 9;
    // Each within 5% of exact at every eps of the sweep. Measured: within
    // 2.4% / 2.1% / 0.7% at eps 1e-2 / 3e-3 / 1e-3 with the piece at 2.25,
    // 3.8% / 2.8% / 0.7% at 2.199. The cross-section's transmittance put
    // them 66% and 81% too dark at 2.25 (eps 1e-2 and 3e-3; 33% and 30% at
    // 1e-3), and counting only blockers that cut the box in two left the
    // piece's top at 2.199 74% too dark. Single patches carry more than
    // the solution's 1% (the furnished room's per-patch median is 1.1% at
    // the default eps): 5% leaves that room and still catches a factor.
    constexpr double patch_tolerance = 0.05;
    // x0 2.25: the shelf's top cuts the cluster's box in two; 2.199: it runs
    // into the box from its right edge and ends at the end face's corner.
    for (double x0 : {2.25, 2.199}) {
        CAPTURE(x0);
        const Scene scene = parse_scene(shelf_and_piece(x0), "shelf_and_piece.json");
        REQUIRE(scene.patches.size() == 11);
        // K = 32: at 2.25 those two patches within 0.1% of K = 128 (1.4102
        // / 1.4114, 2.0768 / 2.0794).
        const Solution exact = solve_exact(scene, {32, 0});
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
}
