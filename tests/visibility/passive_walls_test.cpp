// Walls on the scene's convex hull block nothing (engine/convex_scene.h):
// with them marked passive (Hierarchy::set_blockers) the exact and the
// multi-scale form factors are those of the full hierarchy, for less work.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "engine/convex_scene.h"
#include "engine/formfactor.h"
#include "support/random_rooms.h"
#include "visibility/cluster_tables.h"
#include "visibility/exact_visibility.h"
#include "visibility/multiscale.h"

using namespace flatrad;

namespace {
// Both hierarchies see the same blockers in every shaft, and a hull wall
// can at most touch a shaft's boundary: the two results differ only by the
// rounding of the walks (a few ulps of the unoccluded exchange, ~1e-15);
// allowed 1e-13 of it.
constexpr double same_tol = 1e-13;
// The multi-scale quadrature's F is known to ~1e-16 absolute (a sum of arcs
// of rounded line measures), which its bound does not count at grazing
// pairs where F itself is ~1e-16; ten times that.
constexpr double absolute_floor = 1e-15;
}  // namespace

TEST_CASE("passive walls: same exact and multi-scale F as the full hierarchy, fewer nodes visited") {
    std::mt19937_64 rng(99);
    long pairs = 0, walls_total = 0;
    long visited_full = 0, visited_passive = 0;
    double worst = 0;
    for (int room_no = 0; room_no < 12; ++room_no) {
        const test::RandomRoom room = test::make_random_room(rng, 4 + room_no % 3, 3 + room_no % 5);
        const std::vector<char> on = segments_on_hull(room.segments);
        std::vector<char> can(on.size());
        for (size_t k = 0; k < on.size(); ++k) can[k] = !on[k];
        const long walls = static_cast<long>(std::count(on.begin(), on.end(), 1));
        CHECK(walls == 4 * (4 + room_no % 3));  // every wall piece, no plate
        walls_total += walls;
        const Hierarchy full(room.segments, 1);
        Hierarchy passive(room.segments, 1);
        passive.set_blockers(can);
        const ExactVisibility ef(full), ep(passive);
        const ClusterTables tp(passive);
        const MultiscaleVisibility mp(passive, tp);
        ExactWorkspace ws;
        VisibilityStats sf, sp;
        for (const auto& a : room.patches)
            for (const auto& b : room.patches) {
                if (a.segment == b.segment) continue;
                const double Fu = form_factor_unoccluded(a.seg, b.seg);
                if (!(Fu > 0)) continue;
                ++pairs;
                const double x = ef.form_factor(a.seg, b.seg, a.segment, b.segment, ws, sf);
                const double y = ep.form_factor(a.seg, b.seg, a.segment, b.segment, ws, sp);
                CAPTURE(room_no);
                CHECK(std::abs(x - y) <= same_tol * Fu);
                worst = std::max(worst, std::abs(x - y) / Fu);
                // Multi-scale at a loose tolerance: both within their bounds of exact.
                const MultiscaleResult m = mp.form_factor(a.seg, b.seg, a.segment, b.segment, 1e-3, GammaRule::Bound, ws, sp);
                CHECK(std::abs(m.F - x) <= m.error_bound + same_tol * Fu + absolute_floor);
            }
        visited_full += sf.clusters_visited;
        visited_passive += sp.clusters_visited;
    }
    MESSAGE("pairs ", pairs, ", hull walls ", walls_total, ", worst |dF| / F_u ", worst, ", nodes visited full ",
            visited_full, " passive ", visited_passive);
    CHECK(pairs > 1000);
    CHECK(visited_passive < visited_full);
}
