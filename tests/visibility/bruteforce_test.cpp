// Exact occluded exchange (visibility/exact_visibility.h) against an
// independent brute-force oracle (tests/support/bruteforce.h): adaptive
// Gauss-Kronrod over x on i of an exact, angular, per-point visibility.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/error.h"
#include "engine/formfactor.h"
#include "engine/geometry.h"
#include "support/bruteforce.h"
#include "visibility/exact_visibility.h"

using namespace flatrad;
using bruteforce::exchange_bruteforce;
using bruteforce::OracleResult;

namespace {

// Rounding floor on top of the oracle's own error bound, relative to the
// unoccluded exchange L_i F_ij (the scale of the answer, which is at most
// it). Both sides sum O(100) terms of that size with ~1e-16 relative
// rounding each: the oracle w-values (sines) over thousands of pieces, the
// line-space method closed-form arcs over O(n^2) critical directions.
// Measured over 30000 random configurations (facing, far apart at distance
// 50, shared corners, crossing lines), the largest |exact - oracle| beyond
// the oracle's bound was 5e-14 of the scale; 1e-12 leaves a 20x margin and
// is still far below any real error (a mishandled event moves the answer by
// the measure of a bundle of lines, 1e-6 and more here).
constexpr double rounding_floor_rel = 1e-12;

// Oracle self-checks against closed forms (crossed strings, hand
// derivations): these are a few sqrt and sums, good to ~10 ulps of the
// scale; the oracle's own bound is added on top.
constexpr double closed_form_tol_rel = 1e-13;

struct Config {
    Segment i, j;
    std::vector<Segment> blockers;
};

std::string describe(const Config& c) {
    std::string s;
    char buf[256];
    auto seg = [&](const char* name, const Segment& g) {
        std::snprintf(buf, sizeof buf, "%s = {{%.17g, %.17g}, {%.17g, %.17g}}\n", name, g.a.x, g.a.y,
                      g.b.x, g.b.y);
        s += buf;
    };
    seg("i", c.i);
    seg("j", c.j);
    for (size_t k = 0; k < c.blockers.size(); ++k) {
        const std::string name = "blocker[" + std::to_string(k) + "]";
        seg(name.c_str(), c.blockers[k]);
    }
    return s;
}

std::string g17(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

double exact_exchange(const Config& c) {
    ExactWorkspace ws;
    VisibilityStats stats;
    return ExactVisibility::exchange_with_blockers(c.i, c.j, c.blockers, ws, stats);
}

double unoccluded_exchange(const Segment& i, const Segment& j) {
    return form_factor_unoccluded(i, j) * i.length();
}

// Allowed |exact - oracle|: the oracle's own error bound plus rounding.
double allowed(const Config& c, const OracleResult& r) {
    return r.error + rounding_floor_rel * unoccluded_exchange(c.i, c.j);
}

bool disagrees(const Config& c) {
    const OracleResult r = exchange_bruteforce(c.i, c.j, c.blockers);
    return !(std::abs(exact_exchange(c) - r.value) <= allowed(c, r));
}

// Greedy reduction of a disagreeing configuration: drop blockers one at a
// time while the disagreement persists, for a small reproducer.
Config minimize(Config c) {
    for (size_t k = 0; k < c.blockers.size();) {
        Config smaller = c;
        smaller.blockers.erase(smaller.blockers.begin() + static_cast<long>(k));
        if (disagrees(smaller))
            c = smaller;
        else
            ++k;
    }
    return c;
}

Vec2 rotate(Vec2 v, double angle) {
    const double cs = std::cos(angle), sn = std::sin(angle);
    return {cs * v.x - sn * v.y, sn * v.x + cs * v.y};
}

// Adds n blockers to c: most centred at random points between the clipped
// patches (inside the shaft, so they occlude), one in five anywhere around
// (crossing the shaft boundary or touching nothing). Lengths shrink as
// n^(-3/4) times the patches' distance D, which keeps the occluded fraction
// spread over about 0.1 to 0.9 for every n (a shaft that is all dark or all
// clear tests little).
void add_random_blockers(Config& c, std::mt19937_64& rng, int n, double D) {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    auto uni = [&](double lo, double hi) { return lo + (hi - lo) * U(rng); };
    const auto clipped = clip_to_lit_halfplanes(c.i, c.j);
    FLATRAD_ASSERT(clipped.has_value(), "configurations are built facing");
    const auto& [ci, cj] = *clipped;
    Box box;
    box.add(c.i);
    box.add(c.j);
    const double len_scale = D / std::pow(static_cast<double>(n), 0.75);
    for (int k = 0; k < n; ++k) {
        Vec2 m;
        if (U(rng) < 0.8)
            m = lerp(lerp(ci.a, ci.b, U(rng)), lerp(cj.a, cj.b, U(rng)), uni(0.1, 0.9));
        else
            m = {uni(box.lo.x - 0.5, box.hi.x + 0.5), uni(box.lo.y - 0.5, box.hi.y + 0.5)};
        const Vec2 h = rotate({1, 0}, uni(0, 2 * std::numbers::pi)) * (0.5 * len_scale * uni(0.1, 0.8));
        c.blockers.push_back({m - h, m + h});
    }
}

// Two patches facing each other (up to +-57 degrees off, so that clipping to
// the lit half-planes happens too), with n random blockers. D_max is the
// largest centre distance (patch lengths are 0.5 to 2).
Config random_config(std::mt19937_64& rng, int n, double D_max = 3.0) {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    auto uni = [&](double lo, double hi) { return lo + (hi - lo) * U(rng); };
    for (;;) {
        Config c;
        const Vec2 ci{uni(-1, 1), uni(-1, 1)};
        const Vec2 ui = rotate({1, 0}, uni(0, 2 * std::numbers::pi));
        const double L_i = uni(0.5, 2.0);
        c.i = {ci - ui * (L_i / 2), ci + ui * (L_i / 2)};
        const double D = uni(0.8, D_max);
        const Vec2 dir = rotate(rot90(ui), uni(-1, 1));
        const Vec2 cj = ci + dir * D;
        const Vec2 nj = rotate(-dir, uni(-1, 1));
        const Vec2 uj{nj.y, -nj.x};  // rot90(uj) == nj: lit side faces i
        const double L_j = uni(0.5, 2.0);
        c.j = {cj - uj * (L_j / 2), cj + uj * (L_j / 2)};
        if (!(unoccluded_exchange(c.i, c.j) > 1e-3)) continue;  // barely facing: a weak test
        add_random_blockers(c, rng, n, D);
        return c;
    }
}

// j's line crosses i (as where walls meet or pass through each other): both
// patches are clipped at the crossing, so the clipped pair shares a corner
// up to rounding, which makes the shaft a triangle with a tiny fourth side.
Config random_crossing_config(std::mt19937_64& rng, int n) {
    std::uniform_real_distribution<double> U(0.0, 1.0);
    auto uni = [&](double lo, double hi) { return lo + (hi - lo) * U(rng); };
    for (;;) {
        Config c;
        const Vec2 ui = rotate({1, 0}, uni(0, 2 * std::numbers::pi));
        c.i = {Vec2{uni(-1, 1), uni(-1, 1)}, Vec2{}};
        c.i.b = c.i.a + ui * uni(0.5, 2.0);
        const Vec2 X = lerp(c.i.a, c.i.b, uni(0.1, 0.9));
        const Vec2 uj = rotate(ui, uni(0.3, std::numbers::pi - 0.3));
        c.j = {X + uj * uni(0.5, 2.0), X - uj * uni(0.05, 1.0)};  // mostly on i's lit side
        if (U(rng) < 0.5) c.j = c.j.reversed();
        if (!(unoccluded_exchange(c.i, c.j) > 1e-3)) continue;
        add_random_blockers(c, rng, n, 1.0);
        return c;
    }
}

// How many minimized reproducers to print per run (each failure prints one).
constexpr int max_printed_reproducers = 5;
int printed_reproducers = 0;

// One order of the pair against the oracle's answer r for it.
void check_order(const Config& c, const OracleResult& r) {
    const double exact = exact_exchange(c);
    const double unoccluded = unoccluded_exchange(c.i, c.j);
    const double tol = allowed(c, r);
    const double floor = rounding_floor_rel * unoccluded;
    INFO(describe(c));
    INFO("exact      = ", g17(exact));
    INFO("oracle     = ", g17(r.value), " +- ", r.error, " (", r.pieces, " pieces)");
    INFO("unoccluded = ", g17(unoccluded));
    CHECK(exact >= -floor);
    CHECK(exact <= unoccluded + floor);
    const bool ok = std::abs(exact - r.value) <= tol;
    CHECK(ok);
    if (!ok && printed_reproducers++ < max_printed_reproducers) {
        const Config m = minimize(c);
        const OracleResult rm = exchange_bruteforce(m.i, m.j, m.blockers);
        std::printf("DISAGREEMENT (minimized):\n%sexact = %.17g\noracle = %.17g +- %.3g\n",
                    describe(m).c_str(), exact_exchange(m), rm.value, rm.error);
    }
}

// exchange_with_blockers(i, j) and (j, i) against the oracle (reciprocity:
// both equal L_i F_ij; they run the method in different frames).
void check_against_oracle(const Config& c) {
    const OracleResult r = exchange_bruteforce(c.i, c.j, c.blockers);
    INFO(describe(c));
    REQUIRE(r.converged);
    check_order(c, r);
    check_order({c.j, c.i, c.blockers}, r);
}

}  // namespace

// ---------------------------------------------------------------------------
// 1. The oracle against closed forms, and against itself.

TEST_CASE("oracle: no blockers matches crossed strings on random facing pairs") {
    std::mt19937_64 rng(0x5eed0001);
    for (int trial = 0; trial < 200; ++trial) {
        const Config c = random_config(rng, 1);
        const OracleResult r = exchange_bruteforce(c.i, c.j, {});
        const double expect = unoccluded_exchange(c.i, c.j);
        INFO(describe(c));
        REQUIRE(r.converged);
        CHECK(std::abs(r.value - expect) <= r.error + closed_form_tol_rel * expect);
    }
}

// Facing unit plates, bottom [0,1] x {0} and top [0,1] x {1}, and a blocker
// [beta, 1 - beta] x {1/2}. Label a line by where it crosses the plates, u at
// y = 0 and v at y = 1; the line measure is dp dtheta = du dv / (1 + (v-u)^2)^(3/2).
// With m = (u + v)/2 (its crossing of the blocker's line), w = v - u
// (Jacobian 1), the free lines pass a gap: |w|/2 <= m <= beta (or the mirror
// image), so
//   L F = 1/2 * 2 * Int_{-2 beta}^{2 beta} (beta - |w|/2) (1 + w^2)^(-3/2) dw
//       = sqrt(1 + 4 beta^2) - 1,
// which gives sqrt(2) - 1 for beta = 1/2 (no blocker) and 0 for beta = 0.
TEST_CASE("oracle: centered blocker between facing unit plates (hand derivation)") {
    const Segment bottom{{0, 0}, {1, 0}}, top{{1, 1}, {0, 1}};
    for (double beta : {0.0, 0.01, 0.1, 0.25, 0.4, 0.49, 0.5}) {
        CAPTURE(beta);
        const std::vector<Segment> blockers = {{{beta, 0.5}, {1 - beta, 0.5}}};
        const double expect = std::sqrt(1 + 4 * beta * beta) - 1;
        const double scale = std::sqrt(2.0) - 1;
        const OracleResult r = exchange_bruteforce(bottom, top, blockers);
        CHECK(std::abs(r.value - expect) <= r.error + closed_form_tol_rel * scale);
        const OracleResult rr = exchange_bruteforce(top, bottom, blockers);
        CHECK(std::abs(rr.value - expect) <= rr.error + closed_form_tol_rel * scale);
    }
}

// Reciprocity L_i F_ij = L_j F_ji: integrating over x on i or over x on j
// share no pieces, critical points or inner geometry, so the two oracle runs
// check each other.
TEST_CASE("oracle: reciprocity with blockers") {
    std::mt19937_64 rng(0x5eed0002);
    for (int n : {1, 3, 10, 30}) {
        for (int trial = 0; trial < 10; ++trial) {
            // Half facing pairs, half with crossing lines (shared corner).
            const Config c = trial % 2 ? random_crossing_config(rng, n) : random_config(rng, n);
            const OracleResult r = exchange_bruteforce(c.i, c.j, c.blockers);
            const OracleResult rr = exchange_bruteforce(c.j, c.i, c.blockers);
            INFO(describe(c));
            REQUIRE(r.converged);
            REQUIRE(rr.converged);
            CHECK(std::abs(r.value - rr.value) <=
                  r.error + rr.error + rounding_floor_rel * unoccluded_exchange(c.i, c.j));
        }
    }
}

// The exact inner integral against plain ray casting from a few points x:
// checks the clipping of blockers to the region between the lines and the
// shadow logic independently of the angular argument.
TEST_CASE("oracle: inner integral matches ray casting") {
    // Midpoint rule with this many samples of j: error about one kernel
    // sample times the step per shadow edge.
    constexpr int samples = 20000;
    std::mt19937_64 rng(0x5eed0003);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int n : {1, 5, 20}) {
        for (int trial = 0; trial < 6; ++trial) {
            const Config c = trial % 2 ? random_crossing_config(rng, n) : random_config(rng, n);
            const bruteforce::Oracle oracle(c.i, c.j, c.blockers);
            for (int k = 0; k < 5; ++k) {
                const Vec2 x = oracle.point(U(rng));
                const double exact = oracle.visible_point_form_factor(x);
                const auto [ray, step_error] =
                    bruteforce::point_form_factor_raycast(x, c.i, c.j, c.blockers, samples);
                // Each blocker has two shadow edges, j two ends; the
                // smooth part's O(h^2) error is far smaller.
                const double tol = (2.0 * n + 2) * step_error + 1e-12;
                INFO(describe(c));
                CHECK(std::abs(exact - ray) <= tol);
            }
        }
    }
}

// ---------------------------------------------------------------------------
// 2. The exact method against the oracle on random configurations.

TEST_CASE("exchange_with_blockers matches the brute-force oracle on random scenes") {
    int configs = 0;
    for (int n : {1, 2, 5, 10, 20, 50}) {
        std::mt19937_64 rng(0xf1a7'0000 + static_cast<unsigned>(n));
        for (int trial = 0; trial < 15; ++trial) {
            CAPTURE(n);
            CAPTURE(trial);
            check_against_oracle(random_config(rng, n));
            ++configs;
        }
    }
    CHECK(configs >= 50);
}

// Far apart (distance up to 30 patch lengths): a narrow range of directions,
// where measuring angles from a fixed axis would lose digits.
TEST_CASE("exchange_with_blockers matches the oracle for far-apart patches") {
    for (int n : {1, 5, 20}) {
        std::mt19937_64 rng(0xfa70'0000 + static_cast<unsigned>(n));
        for (int trial = 0; trial < 5; ++trial) {
            CAPTURE(n);
            CAPTURE(trial);
            check_against_oracle(random_config(rng, n, 30.0));
        }
    }
}

// Patches whose lines cross: the clipped pair meets at a corner computed
// twice, once per clip, so the two copies may differ by an ulp.
TEST_CASE("exchange_with_blockers matches the oracle when a patch's line crosses the other") {
    for (int n : {1, 3, 10}) {
        std::mt19937_64 rng(0xc055'0000 + static_cast<unsigned>(n));
        for (int trial = 0; trial < 10; ++trial) {
            CAPTURE(n);
            CAPTURE(trial);
            check_against_oracle(random_crossing_config(rng, n));
        }
    }
}

// Minimal cases found by the random tests above, kept as regressions.
TEST_CASE("regressions: shafts whose corner comes from clipping") {
    const Segment i{{-1, 0}, {1, 0}};
    SUBCASE("clip corners an ulp apart: the shaft's tiny side points the wrong way") {
        // i clipped at x = 0.049999999999999822, j at 0.049999999999999989:
        // the side from j's end to i's start runs along i, backwards.
        check_against_oracle({i, {{0.2, 1}, {-0.1, -1}}, {{{0.5, 0.2}, {0.6, 0.3}}}});
    }
    SUBCASE("i clipped on j's line: the shaft is a triangle, one side along j") {
        // The blocker enters through j just past j's end and leaves through
        // the side edge from i's end to j's start; it leaves a gap under j's
        // end (oracle 0.0235925...), so it does not separate.
        check_against_oracle({i, {{1.5, 1}, {0.3, 0.2}}, {{{0.1, 0.2}, {1.5, 0.3}}}});
    }
}

TEST_CASE("regressions: a room's corner whose shared end the pair's frame rounds apart") {
    // A ceiling element and a wall element meeting at the corner (3.2, 3.2)
    // of a forest's room (tests/solver/hierarchical_dim_light_test.cpp), a
    // stick between them. In the pair's frame the two copies of the corner
    // came out 2.8e-17 apart, a patch-to-patch direction pointing backwards
    // (FLATRAD_ASSERT in asserts builds); the shared end gives no direction.
    const Segment ceiling{{3.2000000000000002, 3.2000000000000002}, {2.8000000000000003, 3.2000000000000002}};
    const Segment wall{{3.2000000000000002, 2.4000000000000004}, {3.2000000000000002, 3.2000000000000002}};
    check_against_oracle({ceiling, wall, {{{3.05, 3.0}, {3.1, 3.1}}}});  // (both ways)
}

// ---------------------------------------------------------------------------
// 3. Degenerate blockers.

namespace {
const Segment bottom{{0, 0}, {1, 0}};  // lit side up
const Segment top{{1, 1}, {0, 1}};     // lit side down
const double plates = std::sqrt(2.0) - 1;  // unoccluded L F of the two
}  // namespace

TEST_CASE("degenerate: blocker sharing an endpoint with a patch") {
    SUBCASE("from j's endpoint into the shaft") {
        check_against_oracle({bottom, top, {{{1, 1}, {0.5, 0.5}}}});
    }
    SUBCASE("from i's endpoint into the shaft") {
        check_against_oracle({bottom, top, {{{0, 0}, {0.5, 0.5}}}});
    }
    SUBCASE("from i's endpoint out of the shaft: no effect") {
        const Config c{bottom, top, {{{1, 0}, {1.5, 0.5}}}};
        check_against_oracle(c);
        CHECK(exact_exchange(c) == doctest::Approx(plates).epsilon(closed_form_tol_rel).scale(0));
    }
    SUBCASE("along the shaft's side, patch end to patch end: no effect") {
        const Config c{bottom, top, {{{1, 0}, {1, 1}}}};
        check_against_oracle(c);
        CHECK(exact_exchange(c) == doctest::Approx(plates).epsilon(closed_form_tol_rel).scale(0));
    }
    SUBCASE("patches sharing a corner, blocker inside the wedge") {
        const Segment wall{{0, 1}, {0, 0}};  // lit side +x
        check_against_oracle({bottom, wall, {{{0.2, 0.1}, {0.1, 0.3}}}});
    }
    SUBCASE("patches sharing a corner, blocker from the corner") {
        const Segment wall{{0, 1}, {0, 0}};
        check_against_oracle({bottom, wall, {{{0, 0}, {0.3, 0.3}}}});
        check_against_oracle({bottom, wall, {{{0, 0}, {0.5, 0.2}}}});
    }
}

TEST_CASE("degenerate: blockers exactly separating the patches give 0") {
    // The separated answer is 0 up to rounding of the scale.
    const double zero_tol = rounding_floor_rel * plates;
    const std::vector<std::vector<Segment>> cases = {
        {{{-1, 0.5}, {2, 0.5}}},                          // wide
        {{{0, 0.5}, {1, 0.5}}},                           // exactly the shaft's width
        {{{-0.5, 0.2}, {1.5, 0.8}}},                      // tilted
        {{{-1, 0.5}, {0.5, 0.5}}, {{0.5, 0.5}, {2, 0.5}}},  // two, sharing an endpoint
        {{{-1, 0.4}, {0.6, 0.4}}, {{0.4, 0.6}, {2, 0.6}}},  // two, overlapping in shadow
    };
    for (size_t k = 0; k < cases.size(); ++k) {
        CAPTURE(k);
        const Config c{bottom, top, cases[k]};
        const OracleResult r = exchange_bruteforce(c.i, c.j, c.blockers);
        CHECK(std::abs(r.value) <= r.error + zero_tol);
        CHECK(std::abs(exact_exchange(c)) <= zero_tol);
    }
}

// A blocker on a patch's own line touches an open segment xy at x or y at
// most (V uses the open segment, DESIGN.md §1): no effect.
TEST_CASE("degenerate: blocker collinear with a patch does not occlude") {
    const std::vector<Segment> cases = {
        {{0.5, 1}, {-0.5, 1}},  // on j, overlapping it
        {{-0.5, 1}, {0.5, 1}},  // same, other orientation
        {{2, 1}, {-1, 1}},      // on j's line, covering j
        {{2, 1}, {3, 1}},       // on j's line, beside j
        {{0.5, 0}, {1.5, 0}},   // on i, overlapping it
        {{-1, 0}, {2, 0}},      // on i's line, covering i
    };
    for (size_t k = 0; k < cases.size(); ++k) {
        CAPTURE(k);
        const Config c{bottom, top, {cases[k]}};
        check_against_oracle(c);
        CHECK(exact_exchange(c) == doctest::Approx(plates).epsilon(closed_form_tol_rel).scale(0));
    }
}
