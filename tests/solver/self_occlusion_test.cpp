// Occlusion inside a cluster (solver/self_occlusion.h): closed forms on
// small sets, an exact interval oracle on random sticks, and what it does
// to the hierarchical solver's energy balance on a forest.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/hierarchical_solver.h"
#include "solver/self_occlusion.h"
#include "support/seen_oracle.h"

using namespace flatrad;

namespace {

constexpr uint8_t two_sided = left_side | right_side | blocks;

// The bin whose direction is u (u one of the sample directions).
int bin_at(double angle) {
    return static_cast<int>(std::lround(angle / (2 * std::numbers::pi / directional_bins))) % directional_bins;
}

using test::meet;

}  // namespace

TEST_CASE("visible fraction: closed forms on two segments") {
    double f[directional_bins];
    const int up = bin_at(std::numbers::pi / 2), right = bin_at(0);
    // Lines counted per unit width: each end of a run is off by at most one
    // line, and each of these sets has at most 4 run ends in all.
    constexpr int lines = 1000;
    const double line_tol = 4.0 * 1.5 / lines;  // 4 ends, extent at most 1.5, over a facing width >= 1

    SUBCASE("two stacked two-sided sticks: the lower one is hidden seen from above") {
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}};
        const std::vector<uint8_t> sides{two_sided, two_sided};
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        CHECK(f[up] == 0.5);  // the same lines meet both
        CHECK(f[right] == 1.0);                                   // along the sticks: nothing faces
        // At 45 degrees the shadows only touch at one end: nothing hidden.
        CHECK(f[bin_at(std::numbers::pi / 4)] == 1.0);
    }
    SUBCASE("shifted by half: a quarter of the facing width is hidden") {
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0.5, 1}, {1.5, 1}}};
        const std::vector<uint8_t> sides{two_sided, two_sided};
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        CHECK(std::abs(f[up] - 0.75) <= line_tol);
        CHECK(std::abs(f[bin_at(3 * std::numbers::pi / 2)] - 0.75) <= line_tol);  // from below, the upper one hidden
    }
    SUBCASE("a blocker without a side facing up hides, and is not counted") {
        // The upper stick is lit downwards only (its upper side does not exist).
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0.5, 1}, {1.5, 1}}};
        const uint8_t down_only = segs[1].left_normal().y < 0 ? (left_side | blocks) : (right_side | blocks);
        const std::vector<uint8_t> sides{two_sided, down_only};
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        CHECK(std::abs(f[up] - 0.5) <= line_tol);  // half of the lower stick, and nothing else, faces up
    }
    SUBCASE("a segment that cannot block hides nothing") {
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}};
        const std::vector<uint8_t> sides{two_sided, left_side | right_side};
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        CHECK(f[up] == 1.0);
        // But it is hidden behind a blocker in front of it (seen from below).
        CHECK(f[bin_at(3 * std::numbers::pi / 2)] == 0.5);
    }
    SUBCASE("a convex closed object, lit outside, hides none of its own lit sides") {
        // A square lit outside (counter-clockwise: the left side is inside,
        // which does not exist).
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{1, 0}, {1, 1}}, {{1, 1}, {0, 1}}, {{0, 1}, {0, 0}}};
        const std::vector<uint8_t> sides(4, right_side | blocks);
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        for (int k = 0; k < directional_bins; ++k) CHECK(f[k] == 1.0);
    }
}

TEST_CASE("visible fraction: extreme coordinates and degenerate segments give shares in [0, 1]") {
    // Stacked sticks scaled to 1e308 (their lengths and extents overflow to
    // infinity, their normals to NaN), to 1e-300 (underflow), and a
    // zero-length segment: every share finite and within [0, 1], by both
    // paths (what cannot be measured is left at 1).
    for (double scale : {1e308, 1e-300, 1.0}) {
        CAPTURE(scale);
        std::vector<Segment> segs{{{-scale, 0}, {scale, 0}}, {{-scale, 0.01 * scale}, {scale, 0.01 * scale}},
                                  {{0, 0.005 * scale}, {0, 0.005 * scale}}};
        for (int k = 0; k < 30; ++k)
            segs.push_back({{-scale, (2 + k) * scale * 0.01}, {scale * 0.9, (2 + k) * scale * 0.01}});
        const std::vector<uint8_t> sides(segs.size(), two_sided);
        for (size_t n : {size_t{3}, segs.size()}) {  // the exact path, the lines
            double f[directional_bins];
            visible_fraction(segs.data(), sides.data(), n, f);
            for (int k = 0; k < directional_bins; ++k) {
                CHECK(std::isfinite(f[k]));
                CHECK(f[k] >= 0.0);
                CHECK(f[k] <= 1.0);
            }
        }
    }
}

TEST_CASE("visible fraction: random non-crossing sticks against the exact interval oracle") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0, 1);
    const auto& dirs = bin_directions();
    int compared = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const int n = 2 + static_cast<int>(U(rng) * 30);
        const double len = 0.05 + 0.5 * U(rng);  // sticks in a unit box: from sparse to many layers
        std::vector<Segment> segs;
        std::vector<uint8_t> sides;
        while (static_cast<int>(segs.size()) < n) {
            const Vec2 c{U(rng), U(rng)};
            const double a = 2 * std::numbers::pi * U(rng);
            const Vec2 d{std::cos(a) * len / 2, std::sin(a) * len / 2};
            const Segment s{c - d, c + d};
            if (std::any_of(segs.begin(), segs.end(), [&](const Segment& q) { return meet(s, q); })) continue;
            segs.push_back(s);
            // Mostly two-sided blockers; some one-sided, some that cannot block.
            const double r = U(rng);
            sides.push_back(r < 0.6 ? two_sided : r < 0.8 ? (left_side | blocks) : r < 0.9 ? right_side : two_sided);
        }
        double f[directional_bins], auto_f[directional_bins];
        const int lines = 4096;
        visible_fraction(segs.data(), sides.data(), segs.size(), f, lines);
        visible_fraction(segs.data(), sides.data(), segs.size(), auto_f);  // exact up to exact_up_to segments
        for (int k = 0; k < directional_bins; ++k) {
            const Vec2 u = dirs[static_cast<size_t>(k)];
            const test::SeenShare e = test::seen_share(segs, sides, u);
            if (e.facing_width <= 0) continue;
            // The lines' spacing over the set's extent across u.
            const Vec2 v{-u.y, u.x};
            double lo = 1e300, hi = -1e300;
            for (const Segment& s : segs) {
                lo = std::min({lo, dot(s.a, v), dot(s.b, v)});
                hi = std::max({hi, dot(s.a, v), dot(s.b, v)});
            }
            const double w = (hi - lo) / lines;
            // Counting lines misplaces each end of a visible run, and each
            // end of a facing side's interval, by at most one line.
            const double all_lines = e.facing_width / w;
            const double tol = (e.runs + static_cast<double>(n)) / std::max(1.0, all_lines - n);
            CAPTURE(trial);
            CAPTURE(k);
            CHECK(std::abs(f[k] - e.fraction) <= tol);
            CHECK(f[k] <= 1.0);
            // The exact path: the same intervals, summed in another order
            // (rounding of a few hundred lengths of order 1).
            constexpr double exact_tol = 1e-12;
            if (segs.size() <= exact_up_to) CHECK(std::abs(auto_f[k] - e.fraction) <= exact_tol);
            ++compared;
        }
    }
    CHECK(compared > 1000);
}

TEST_CASE("hierarchical solver: a forest's hidden members are not lit, its closed links are shown closed") {
    // data/forest.json (3005 segments, 3000 two-sided sticks) at eps 2.
    // With tables that counted every member facing a direction, cluster
    // links lit hidden sticks as if exposed and the solution absorbed 14%
    // more than was emitted (balance 0.144 at eps 2); with the visible
    // fractions, 5.1% (ninth session). What remained was mostly the
    // direction bounds' midpoint on links through many layers of sticks:
    // up to the visibility tolerance above a truth near 0, on dozens of
    // links per sender. Bands of sticks shown to close those shafts
    // (visibility/opaque_band.h) answer 0: 0.14% (tenth session). Since
    // the bands also bound open shafts (eleventh session) the balance is
    // -0.70%: less of the bounds' upward bias is left to offset the
    // cluster model's own error, which is negative (-1.5% with exact
    // visibility). The bound, 1%, is 5x below the value without the
    // proofs.
    constexpr double balance_bound = 0.01;
    const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/forest.json");
    HierarchicalOptions o;
    o.eps = 2;
    const Solution s = solve_hierarchical(scene, o);
    REQUIRE(s.totals.balance.size() == 1);
    CHECK(s.stats.visibility.opaque > 0);
    CHECK(s.totals.balance[0] <= balance_bound);
    CHECK(s.totals.absorbed[0] > 0);
}

TEST_CASE("hierarchical solver: two forests solved apart and together, with hidden members, agree") {
    // Two closed rooms of random two-sided sticks (clusters several layers
    // deep), each with a lamp: independent parts. Solving them apart reads
    // and pushes each part's tables from its own top; together, from the
    // root: the visible-share factors must apply the same way in both.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(0, 1);
    std::string surfaces;
    for (int room = 0; room < 2; ++room) {
        const double x0 = 3.0 * room;
        surfaces += R"({"name": "room)" + std::to_string(room) + R"(", "material": "wall", "closed": true, "side": "in", "points": [[)" +
                    std::to_string(x0) + ",0],[" + std::to_string(x0 + 2) + ",0],[" + std::to_string(x0 + 2) + ",2],[" +
                    std::to_string(x0) + R"(,2]]},)";
        surfaces += R"({"name": "lamp)" + std::to_string(room) + R"(", "material": "lamp", "side": "right", "points": [[)" +
                    std::to_string(x0 + 0.8) + ",1.95],[" + std::to_string(x0 + 1.2) + R"(,1.95]]},)";
        std::vector<Segment> sticks;
        while (sticks.size() < 60) {
            const Vec2 c{x0 + 0.2 + 1.6 * U(rng), 0.2 + 1.5 * U(rng)};
            const double a = 2 * std::numbers::pi * U(rng);
            const Vec2 d{0.06 * std::cos(a), 0.06 * std::sin(a)};
            const Segment s{c - d, c + d};
            if (std::any_of(sticks.begin(), sticks.end(), [&](const Segment& q) { return meet(s, q); })) continue;
            sticks.push_back(s);
            surfaces += R"({"name": "s)" + std::to_string(room) + "_" + std::to_string(sticks.size()) +
                        R"(", "material": "tree", "side": "both", "points": [[)" + std::to_string(s.a.x) + "," +
                        std::to_string(s.a.y) + "],[" + std::to_string(s.b.x) + "," + std::to_string(s.b.y) + "]]},";
        }
    }
    surfaces.pop_back();
    const std::string text = R"({"flatrad": 1, "materials": {"wall": {"reflectance": 0.7}, "tree": {"reflectance": 0.5},
        "lamp": {"emission": 10}}, "surfaces": [)" + surfaces + "]}";
    const Scene scene = parse_scene(text, "two_forests.json");
    HierarchicalOptions apart, together;
    apart.eps = together.eps = 0.5;  // loose: cluster links to deep clusters survive
    together.solve_parts_apart = false;
    // The same links in both runs: the loose solves between refinement
    // rounds stop at different points apart and together, and a link near
    // the bar may split in one run only; this test is about the operator.
    apart.loose_intermediate_solves = together.loose_intermediate_solves = false;
    const Solution a = solve_hierarchical(scene, apart);
    const Solution t = solve_hierarchical(scene, together);
    CHECK(a.stats.independent_parts == 2);
    CHECK(t.stats.independent_parts == 1);
    CHECK(a.stats.cluster_links > 0);
    CHECK(a.stats.links == t.stats.links);
    // As in light_parts_test.cpp: GMRES's 1e-12 residual in either run, an
    // inverse of norm ~10 at these reflectances: 1e-9 of the largest.
    constexpr double same_solution_tol = 1e-9;
    double worst = 0, largest = 0;
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        worst = std::max(worst, std::abs(a.patches[p].radiosity[0] - t.patches[p].radiosity[0]));
        largest = std::max(largest, std::abs(t.patches[p].radiosity[0]));
    }
    REQUIRE(largest > 0);
    CHECK(worst <= same_solution_tol * largest);
}

TEST_CASE("visible fraction by groups: each child's own share, and the whole share is theirs summed") {
    const int up = bin_at(std::numbers::pi / 2), down = bin_at(3 * std::numbers::pi / 2), right = bin_at(0);
    double f[directional_bins];
    SUBCASE("two stacked sticks, one per group: the front one seen whole, the one behind not at all") {
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}};
        const std::vector<uint8_t> sides{two_sided, two_sided};
        const std::vector<int32_t> group{0, 1};
        // The exact path subtracts the covered length from the width: a
        // hidden side's share is 0 to the rounding of lengths of order 1.
        constexpr double rounding = 1e-15;
        for (int lines : {0, 1000}) {  // exact, and on lines
            CAPTURE(lines);
            double g[2 * directional_bins];
            visible_fraction(segs.data(), sides.data(), segs.size(), f, group.data(), 2, g, lines);
            CHECK(f[up] == 0.5);
            CHECK(g[0 * directional_bins + up] <= rounding);  // the lower stick, seen from above
            CHECK(g[1 * directional_bins + up] == 1.0);
            CHECK(g[0 * directional_bins + down] == 1.0);  // from below, the other way round
            CHECK(g[1 * directional_bins + down] <= rounding);
            CHECK(g[0 * directional_bins + right] == 1.0);  // along the sticks nothing faces: 1
        }
    }
    SUBCASE("the visible face: the seen lobes' mean depth along each direction") {
        // The upper stick shifted by half: from above, all of it (width 1 at
        // depth 1) and the lower one's free half (width 0.5 at depth 0):
        // 2/3; from below (depth along -y), all of the lower one (at 0) and
        // the upper one's free half (at -1): -1/3.
        const std::vector<Segment> segs{{{0, 0}, {1, 0}}, {{0.5, 1}, {1.5, 1}}};
        const std::vector<uint8_t> sides{two_sided, two_sided};
        const std::vector<int32_t> group{0, 0};
        constexpr int lines = 3000;
        // On lines each of the 4 run ends is off by a line (1.5 / 3000 wide)
        // over a seen width of 1.5, at depths at most 1 apart.
        const double line_tol = 4 * (1.5 / lines) / 1.5;
        for (int l : {0, lines}) {
            CAPTURE(l);
            double g[directional_bins], front[directional_bins];
            visible_fraction(segs.data(), sides.data(), segs.size(), f, group.data(), 1, g, l, front);
            const double tol = l == 0 ? 1e-15 : line_tol;
            CHECK(std::abs(front[up] - 2.0 / 3) <= tol);
            CHECK(std::abs(front[down] + 1.0 / 3) <= tol);
            CHECK(std::isnan(front[right]));  // nothing faces along the sticks
        }
    }
    SUBCASE("random sticks in random groups: the groups' seen lobes add up to the whole's (exact path)") {
        std::mt19937 rng(23);
        std::uniform_real_distribution<double> U(0, 1);
        const auto& dirs = bin_directions();
        for (int trial = 0; trial < 20; ++trial) {
            const int n = 2 + static_cast<int>(U(rng) * (exact_up_to - 2));
            const int groups = 1 + static_cast<int>(U(rng) * 4);
            std::vector<Segment> segs;
            std::vector<uint8_t> sides;
            std::vector<int32_t> group;
            while (static_cast<int>(segs.size()) < n) {
                const Vec2 c{U(rng), U(rng)};
                const double a = 2 * std::numbers::pi * U(rng);
                const Vec2 d{std::cos(a) * 0.15, std::sin(a) * 0.15};
                const Segment s{c - d, c + d};
                if (std::any_of(segs.begin(), segs.end(), [&](const Segment& q) { return meet(s, q); })) continue;
                segs.push_back(s);
                sides.push_back(U(rng) < 0.8 ? two_sided : (left_side | blocks));
                group.push_back(static_cast<int32_t>(U(rng) * groups));
            }
            std::vector<double> g(static_cast<size_t>(groups) * directional_bins);
            visible_fraction(segs.data(), sides.data(), segs.size(), f, group.data(), groups, g.data());
            for (int k = 0; k < directional_bins; ++k) {
                // Per group its facing width across u_k (the exact path's
                // measure): the groups' shares weighted by it give the whole.
                const Vec2 u = dirs[static_cast<size_t>(k)], v{-u.y, u.x};
                std::vector<double> width(static_cast<size_t>(groups), 0.0);
                double all = 0;
                for (size_t i = 0; i < segs.size(); ++i) {
                    const double c = dot(segs[i].left_normal(), u);
                    const uint8_t side = c > 0 ? left_side : c < 0 ? right_side : 0;
                    if (!(sides[i] & side)) continue;
                    const double w = std::abs(dot(segs[i].b - segs[i].a, v));
                    width[static_cast<size_t>(group[i])] += w;
                    all += w;
                }
                if (!(all > 0)) continue;
                double seen = 0;
                for (int q = 0; q < groups; ++q) {
                    const double share = g[static_cast<size_t>(q) * directional_bins + static_cast<size_t>(k)];
                    CHECK(share >= 0.0);
                    CHECK(share <= 1.0);
                    seen += share * width[static_cast<size_t>(q)];
                }
                // Sums of a few dozen lengths of order 1, in another order.
                constexpr double rounding = 1e-12;
                CAPTURE(trial);
                CAPTURE(k);
                CHECK(std::abs(seen / all - f[k]) <= rounding);
            }
        }
    }
}

TEST_CASE("hierarchical solver: a cluster's arrivals light the members in view, not those behind them") {
    // Six two-sided sticks 0.2 long stacked 0.02 apart, 7.5 below a lamp 2
    // wide, in a black room: only the top stick's upper side sees the
    // lamp (exact at K = 4: 0.0670; the others 2e-4 to 4.5e-4, light
    // grazing in between). At eps 1 the lamp reaches the stack through
    // cluster links. When a cluster's arrivals went to all its members
    // alike (one visible-share factor per cluster), every upper side got
    // a sixth of them and the row-sum correction drove the sticks
    // negative (-0.03 to 0.0017, the top one 0.0017). Now each child takes
    // its own share seen from outside its parent: the top side 0.0649
    // (3.0% low: the cluster link's point approximation of the lamp), the
    // hidden sides 0.
    const Scene scene = parse_scene(R"({"flatrad": 1, "materials": {"black": {"reflectance": 0},
        "lamp": {"emission": 1}, "stick": {"reflectance": 0.5}}, "surfaces": [
        {"name": "room", "material": "black", "points": [[0,0],[10,0],[10,10],[0,10]], "closed": true, "side": "in"},
        {"name": "lamp", "material": "lamp", "points": [[6,9.5],[4,9.5]], "side": "left"},
        {"name": "s0", "material": "stick", "points": [[4.9,2.0],[5.1,2.0]], "side": "both"},
        {"name": "s1", "material": "stick", "points": [[4.9,2.02],[5.1,2.02]], "side": "both"},
        {"name": "s2", "material": "stick", "points": [[4.9,2.04],[5.1,2.04]], "side": "both"},
        {"name": "s3", "material": "stick", "points": [[4.9,2.06],[5.1,2.06]], "side": "both"},
        {"name": "s4", "material": "stick", "points": [[4.9,2.08],[5.1,2.08]], "side": "both"},
        {"name": "s5", "material": "stick", "points": [[4.9,2.1],[5.1,2.1]], "side": "both"}]})",
                                     "stack.json");
    const Solution exact = solve_exact(scene, {4, 0});
    HierarchicalOptions o;
    o.eps = 1;
    const Solution h = solve_hierarchical(scene, o);
    REQUIRE(h.stats.cluster_links > 0);
    // The top stick's upper side: its exact value within the point
    // approximation's error (2 x the lamp's radius over the distance is
    // 0.27 as a bound; 5% leaves room over the measured 3.0%).
    constexpr double top_tolerance = 0.05;
    // The hidden sides: within 1% of the top's exact value of their own
    // (measured 4.5e-4 off, all of it the grazing light they miss).
    constexpr double hidden_tolerance = 0.01;
    // The top side: the brightest patch but the lamp.
    double top_exact = 0;
    for (size_t p = 0; p < exact.patches.size(); ++p)
        if (scene.surfaces[static_cast<size_t>(scene.patches[p].surface)].name != "lamp")
            top_exact = std::max(top_exact, exact.patches[p].radiosity[0]);
    for (size_t p = 0; p < h.patches.size(); ++p) {
        const double b = h.patches[p].radiosity[0], r = exact.patches[p].radiosity[0];
        CAPTURE(p);
        CHECK(b >= 0.0);
        if (r == top_exact)
            CHECK(std::abs(b - r) <= top_tolerance * r);
        else  // the hidden sides (and the lamp, the black room: exact in both)
            CHECK(std::abs(b - r) <= hidden_tolerance * top_exact);
    }
}
