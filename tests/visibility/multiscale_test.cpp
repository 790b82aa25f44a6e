// Multi-scale visibility (visibility/multiscale.h, cluster_tables.h):
// tables against direct computation, eps = 0 is exact, and the reported
// error bound holds.
#include "visibility/multiscale.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>

#include "engine/formfactor.h"
#include "support/cloud_visibility.h"

using namespace flatrad;

namespace {
// Same code path as the exact method when nothing is approximated: the
// issue's bar is 1e-12 relative.
constexpr double exact_tol = 1e-12;
// The claimed bound is checked with a rounding floor: both values are
// integrals over hundreds of arcs, each term exact to ~1e-15 of the
// unoccluded value.
constexpr double rounding_floor = 1e-12;

// The shaft between c.i and c.j (D apart), closed, with at least
// min_layers layers of shadow between them by the scene's density: shown
// closed exactly, from the slabs alone, asked from i and from j, exact
// (eps 0) or not.
void check_closed_by_slabs(const test::Cloud& c, double D, double min_layers) {
    test::CloudVisibility vis(c);
    vis.multiscale.set_min_pieces_to_bound(32);
    vis.multiscale.set_min_pieces_to_prove_closed(16);
    const double layers = vis.multiscale.layers_per_depth() * D;
    CAPTURE(layers);
    REQUIRE(layers >= min_layers);
    ExactWorkspace ws;
    VisibilityStats st, ex_st;
    const double unocc = form_factor_unoccluded(c.i, c.j);
    REQUIRE(vis.exact.form_factor(c.i, c.j, 0, 1, ws, ex_st) <= rounding_floor * unocc);  // closed
    for (const double eps : {0.0, 1e-3 * unocc}) {
        CAPTURE(eps);
        const long slabs_before = st.slabs;
        const MultiscaleResult r = vis.multiscale.form_factor(c.i, c.j, 0, 1, eps, GammaRule::Bound, ws, st);
        CHECK(r.F == 0);
        CHECK(r.error_bound == 0);
        CHECK(st.slabs == slabs_before + 1);  // settled by the slabs alone
        const long slabs_reversed = st.slabs;
        const MultiscaleResult back = vis.multiscale.form_factor(c.j, c.i, 1, 0, eps, GammaRule::Bound, ws, st);
        CHECK(back.F == 0);
        CHECK(back.error_bound == 0);
        CHECK(st.slabs == slabs_reversed + 1);
    }
}
}  // namespace

TEST_CASE("cluster tables: tau_bar at the sampled directions equals the direct union") {
    std::mt19937_64 rng(3);
    const test::Cloud c = test::make_cloud(rng);
    const Hierarchy h(c.segments);
    const ClusterTables tables(h);
    CHECK(tables.built() == 0);  // lazy: nothing until asked
    const double pi = std::acos(-1.0);
    for (int node : {0, 1, 2, 5}) {
        if (node >= static_cast<int>(h.nodes().size())) continue;
        const ClusterNode& n = h.node(node);
        std::vector<Segment> segs;
        for (int k = n.first; k < n.first + n.count; ++k) segs.push_back(c.segments[static_cast<size_t>(h.order()[static_cast<size_t>(k)])]);
        for (int k = 0; k < ClusterTables::directions; k += 17) {
            const double theta = (k + 0.5) * pi / ClusterTables::directions;
            const ClusterTables::Sample s = tables.at(node, theta);
            CHECK(s.tau_bar == doctest::Approx(exact_tau_bar(segs, n.box, theta)).epsilon(1e-12));
            CHECK(s.tau_bar >= 0);
            CHECK(s.tau_bar <= 1);
            // L1 and L2 of a 0/1 function with mean tau_bar over delta_p.
            CHECK(s.L1 == doctest::Approx(2 * s.delta_p * s.tau_bar * (1 - s.tau_bar)));
            CHECK(s.R2f <= s.R2 + 1e-12);  // filtering only removes detail
        }
    }
    CHECK(tables.built() >= 1);
    // Period pi: theta and theta + pi are the same lines.
    CHECK(tables.at(0, 0.3).tau_bar == doctest::Approx(tables.at(0, 0.3 + pi).tau_bar).epsilon(1e-12));
}

TEST_CASE("multiscale: eps = 0 approximates nothing and is exact, on 200 random clouds") {
    std::mt19937_64 rng(17);
    int nonzero = 0;
    for (int t = 0; t < 200; ++t) {
        const test::Cloud c = test::make_cloud(rng);
        const test::CloudVisibility vis(c);
        const MultiscaleVisibility& ms = vis.multiscale;
        const ExactVisibility& ex = vis.exact;
        ExactWorkspace ws;
        VisibilityStats st;
        const double exact = ex.form_factor(c.i, c.j, 0, 1, ws, st);
        const MultiscaleResult r = ms.form_factor(c.i, c.j, 0, 1, 0.0, GammaRule::Bound, ws, st);
        CAPTURE(t);
        CHECK(r.clusters_approximated == 0);
        CHECK(r.error_bound == 0);
        CHECK(std::abs(r.F - exact) <= exact_tol * std::max(exact, 1e-300));
        if (exact > 0) ++nonzero;
    }
    CHECK(nonzero > 150);
}

TEST_CASE("multiscale: the reported error bound holds (rule: bound), and F -> exact as eps -> 0") {
    // Three times: as the module comes (cluster approximation), with
    // direction bounds in shafts of 32 pieces or more, and with bands of
    // pieces tried before them there too (as the hierarchical solver has it).
    for (const int mode : {0, 1, 2}) {
        const bool with_bounds = mode > 0, with_bands = mode == 2;
        CAPTURE(mode);
        std::mt19937_64 rng(23);
        int checked = 0, approximated = 0, bounded = 0, banded = 0, failures = 0;
        const double eps_list[] = {0.1, 0.03, 0.01, 3e-3, 1e-3, 1e-4};
        double sum_err[6] = {};
        for (int t = 0; t < 120; ++t) {
            const test::Cloud c = test::make_cloud(rng);
            test::CloudVisibility vis(c);
            if (with_bounds) vis.multiscale.set_min_pieces_to_bound(32);
            if (with_bands) vis.multiscale.set_min_pieces_to_prove_closed(32);
            const MultiscaleVisibility& ms = vis.multiscale;
            const ExactVisibility& ex = vis.exact;
            ExactWorkspace ws;
            VisibilityStats st;
            const double exact = ex.form_factor(c.i, c.j, 0, 1, ws, st);
            // Floor relative to the unoccluded F: a fully blocked pair has F = 0
            // but its integral still sums terms of the unoccluded size.
            const double unocc = form_factor_unoccluded(c.i, c.j);
            size_t e_index = 0;
            for (double eps : eps_list) {
                const long bounded_before = st.bounded, banded_before = st.banded + st.opaque;
                const MultiscaleResult r = ms.form_factor(c.i, c.j, 0, 1, eps, GammaRule::Bound, ws, st);
                ++checked;
                if (st.bounded > bounded_before) ++bounded;
                if (st.banded + st.opaque > banded_before) ++banded;
                if (r.clusters_approximated > 0) ++approximated;
                const double err = std::abs(r.F - exact);
                sum_err[e_index++] += err;
                if (err > r.error_bound + rounding_floor * unocc) {
                    ++failures;
                    MESSAGE("bound fails: t=" << t << " eps=" << eps << " err=" << err << " bound=" << r.error_bound);
                }
                CHECK(r.F >= 0);
            }
        }
        MESSAGE("mode " << mode << ": " << checked << " (configuration, eps) pairs, " << approximated
                        << " with approximations, " << bounded << " answered by direction bounds, " << banded
                        << " by bands, " << failures << " bound failures");
        CHECK(failures == 0);
        if (with_bounds) {
            CHECK(bounded + banded > checked / 10);  // the bounds are exercised
        } else {
            CHECK(bounded == 0);  // off unless asked for
            CHECK(approximated > checked / 4);  // the test exercises approximation
        }
        // F -> exact as eps -> 0: the summed error falls from the loosest to the
        // tightest eps, by more than 10x.
        MESSAGE("summed |F - exact| per eps: " << sum_err[0] << " " << sum_err[2] << " " << sum_err[4] << " "
                                              << sum_err[5]);
        CHECK(sum_err[5] * 10 < sum_err[0]);
    }
}

TEST_CASE("multiscale: through crowded forests, band answers are within their bound of exact") {
    // The clouds above rarely hold the 8 layers of shadow a band needs; these
    // do: patches 2 to 6 apart, 300 to 800 sticks of 0.05 to 0.15 between
    // them (10 to 60 layers), every other forest with a clear lane 0.3 wide
    // so that it stays open. Settings as the hierarchical solver has them.
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> U(0, 1);
    int checked = 0, banded = 0, opaque = 0, failures = 0;
    for (int t = 0; t < 24; ++t) {
        test::Cloud c;
        const double D = 2 + 4 * U(rng), wi = 1 + U(rng), wj = 1 + U(rng);
        c.i = {{-wi / 2, 0}, {wi / 2, 0}};
        c.j = {{wj / 2 + 0.3 * (U(rng) - 0.5), D}, {-wj / 2, D}};
        c.segments = {c.i, c.j};
        const int n = 300 + static_cast<int>(500 * U(rng));
        const double lane = t % 2 ? (U(rng) - 0.5) * 0.6 : 1e9;
        while (static_cast<int>(c.segments.size()) < n + 2) {
            const Vec2 m{(U(rng) - 0.5) * 3, 0.2 + (D - 0.4) * U(rng)};
            if (std::abs(m.x - lane) < 0.15) continue;
            const double a = 2 * M_PI * U(rng), len = 0.05 + 0.1 * U(rng);
            const Vec2 d{std::cos(a) * len / 2, std::sin(a) * len / 2};
            c.segments.push_back({m - d, m + d});
        }
        test::CloudVisibility vis(c);
        vis.multiscale.set_min_pieces_to_bound(32);
        vis.multiscale.set_min_pieces_to_prove_closed(32);
        ExactWorkspace ws;
        VisibilityStats st;
        const double exact = vis.exact.form_factor(c.i, c.j, 0, 1, ws, st);
        const double unocc = form_factor_unoccluded(c.i, c.j);
        for (const double eps : {0.3, 0.1, 0.03, 0.01}) {
            const long before = st.banded, closed_before = st.opaque;
            const MultiscaleResult r = vis.multiscale.form_factor(c.i, c.j, 0, 1, eps, GammaRule::Bound, ws, st);
            ++checked;
            if (st.banded > before) ++banded;
            if (st.opaque > closed_before) {
                ++opaque;
                CHECK(r.F == 0);
            }
            if (std::abs(r.F - exact) > r.error_bound + rounding_floor * unocc) {
                ++failures;
                MESSAGE("bound fails: t=" << t << " eps=" << eps << " F=" << r.F << " exact=" << exact
                                          << " bound=" << r.error_bound);
            }
        }
    }
    MESSAGE(checked << " (forest, eps) pairs: " << banded << " answered by a band's bound, " << opaque
                    << " shown closed, " << failures << " bound failures");
    CHECK(failures == 0);
    CHECK(banded >= 5);
    CHECK(opaque >= 5);
}

TEST_CASE("multiscale: a long shaft's bands settle it from their slabs alone, within the bound") {
    // Patches 30 apart and a blind between them: rows 0.4 apart, sticks
    // 0.3 long with gaps of 0.1 and, alternately, 0.4 long centred on those
    // gaps (as in opaque_band_test.cpp). Lines from i to j turn by less
    // than 1/30, so each pair of rows stops them all: closed, exactly. The
    // scene's density puts ~43 layers of shadow between the patches, past
    // the 36 at which only the slabs around the bands' depths are walked
    // first. With a channel cut through every row (the long sticks above
    // one gap removed) the shaft is open; the answer must then be within
    // its bound of exact.
    constexpr double D = 30;
    auto blind = [&](bool channel) {
        test::Cloud c;
        c.i = {{0, 0}, {1, 0}};
        c.j = {{1, D}, {0, D}};
        c.segments = {c.i, c.j};
        int row = 0;
        for (double y = 0.4; y < D - 0.2; y += 0.4, ++row) {
            const bool a = row % 2 == 0;
            for (double x = a ? -0.5 : -0.35; x < 1.6; x += 0.4) {
                if (!a && channel && std::abs(x - 0.45) < 0.01) continue;  // over A's gap [0.6, 0.7]
                c.segments.push_back({{x, y}, {x + (a ? 0.3 : 0.4), y}});
            }
        }
        return c;
    };
    for (const bool channel : {false, true}) {
        CAPTURE(channel);
        const test::Cloud c = blind(channel);
        test::CloudVisibility vis(c);
        vis.multiscale.set_min_pieces_to_bound(32);
        vis.multiscale.set_min_pieces_to_prove_closed(32);
        ExactWorkspace ws;
        VisibilityStats st, ex_st;
        const double exact = vis.exact.form_factor(c.i, c.j, 0, 1, ws, ex_st);
        const double unocc = form_factor_unoccluded(c.i, c.j);
        if (channel)
            REQUIRE(exact > 1e-3 * unocc);
        else
            REQUIRE(exact <= rounding_floor * unocc);
        for (const double eps : {0.0, 1e-3 * unocc, 0.1 * unocc}) {
            CAPTURE(eps);
            const long slabs_before = st.slabs;
            const MultiscaleResult r = vis.multiscale.form_factor(c.i, c.j, 0, 1, eps, GammaRule::Bound, ws, st);
            CHECK(std::abs(r.F - exact) <= r.error_bound + rounding_floor * unocc);
            if (!channel) {
                CHECK(r.F == 0);
                CHECK(st.slabs == slabs_before + 1);  // settled by the slabs alone
            }
        }
    }
}

TEST_CASE("multiscale: a long tapered shaft's slabs lie at its narrow end") {
    // A short patch i (length 1) and a wide j (31) 30 apart: the shaft's
    // section grows from 1 to 31. A blind closes it within 3 of i (pairs of
    // rows 0.05 apart, sticks 0.3 long with gaps of 0.1 and 0.4 long
    // centred on those gaps, from x = -3 to 4: the shaft is at most 2.5
    // wide there and its lines turn by less than 0.5, so each pair stops
    // them all); nothing else is in the shaft. Long rows outside it, on its
    // left, give the scene the density of a long shaft (about 80 layers
    // between the patches by the root box's density, past the 36 of a long
    // shaft), slabs about 3 deep. Slabs evenly spaced along the shaft
    // (around 5, 15 and 25) hold nothing of the blind; slabs from the
    // narrow end (around 1.5, 4.5 and 7.5) hold it: closed, exactly, from
    // the slabs alone, asked from either end.
    constexpr double D = 30;
    test::Cloud c;
    c.i = {{0, 0}, {1, 0}};
    c.j = {{16, D}, {-15, D}};
    c.segments = {c.i, c.j};
    for (double y = 0.4; y < 3; y += 0.4) {
        for (double x = -3; x < 4; x += 0.4) c.segments.push_back({{x, y}, {x + 0.3, y}});
        for (double x = -2.85; x < 4; x += 0.4) c.segments.push_back({{x, y + 0.05}, {x + 0.4, y + 0.05}});
    }
    // The shaft's left side runs from (0, 0) to (-15, 30): x = -y / 2.
    for (double y = 0.2; y < D - 1; y += 0.05) c.segments.push_back({{-15, y}, {-0.5 * y - 1, y}});
    // A long shaft, slabs 8 layers thick: 3.3 deep at most. Asked from
    // j's side too, the narrow end is the far one.
    check_closed_by_slabs(c, D, 72);
}

TEST_CASE("multiscale: a long shaft's slabs start where its blockers do, past an empty lead") {
    // Patches 1 wide, 30 apart; nothing between them for 10 from i, then a
    // blind 3 deep that closes the shaft (pairs of rows 0.05 apart, sticks
    // 0.3 long with gaps of 0.1 and 0.4 long centred on those gaps, as
    // above), then nothing up to j: a lamp hung above a forest. Long rows
    // far to the left give the scene the density of a long shaft (about 300
    // layers between the patches by the root box's density), slabs under a
    // unit deep: three of them laid from i's end hold nothing, from j's
    // end (17 from the blind) nothing either. Moved to where the blockers
    // start they hold the blind: closed, exactly, from the slabs alone,
    // asked from either end.
    constexpr double D = 30, lead = 10;
    test::Cloud c;
    c.i = {{0, 0}, {1, 0}};
    c.j = {{1, D}, {0, D}};
    c.segments = {c.i, c.j};
    for (double y = lead; y < lead + 3; y += 0.4) {
        for (double x = -1; x < 2; x += 0.4) c.segments.push_back({{x, y}, {x + 0.3, y}});
        for (double x = -0.85; x < 2; x += 0.4) c.segments.push_back({{x, y + 0.05}, {x + 0.4, y + 0.05}});
    }
    for (double y = 0.2; y < D - 0.1; y += 0.05) c.segments.push_back({{-20, y}, {-3, y}});
    check_closed_by_slabs(c, D, 36 * 3);  // a long shaft, slabs 8 layers thick: under a unit deep, three under 3
}

TEST_CASE("multiscale: transmittance between clusters is in [0, 1] and within its bound of eps = 0") {
    std::mt19937_64 rng(5);
    test::Cloud c = test::make_cloud(rng);
    while (c.segments.size() < 100) c = test::make_cloud(rng);  // enough clusters to pair
    const Hierarchy h(c.segments, 2);
    const ClusterTables tables(h);
    const MultiscaleVisibility ms(h, tables);
    ExactWorkspace ws;
    VisibilityStats st;
    auto ancestor = [&](int a, int b) {  // a is an ancestor of b (or equal)
        for (int x = b; x >= 0; x = h.node(x).parent)
            if (x == a) return true;
        return false;
    };
    int pairs = 0, partial = 0;
    const int n = static_cast<int>(h.nodes().size());
    for (int a = 1; a < n && pairs < 300; ++a)
        for (int b = a + 1; b < n && pairs < 300; b += 3) {
            if (ancestor(a, b) || ancestor(b, a)) continue;
            ++pairs;
            const TransmittanceResult t0 = ms.transmittance(a, b, 0.0, GammaRule::Bound, ws, st);
            CHECK(t0.tau >= 0);
            CHECK(t0.tau <= 1);
            CHECK(t0.clusters_approximated == 0);
            if (t0.tau > 0 && t0.tau < 1) ++partial;
            const TransmittanceResult t1 = ms.transmittance(a, b, 0.05, GammaRule::Bound, ws, st);
            CHECK(std::abs(t1.tau - t0.tau) <= t1.error_bound + 1e-12);
        }
    CHECK(pairs > 50);
    CHECK(partial > 5);
    MESSAGE(pairs << " cluster pairs, " << partial << " partly blocked");
    // Two lone segments far from everything: nothing between, tau = 1.
    const Hierarchy lone({Segment{{0, 0}, {0, 1}}, Segment{{5, 0}, {5, 1}}}, 1);
    const ClusterTables lt(lone);
    const MultiscaleVisibility lm(lone, lt);
    CHECK(lm.transmittance(1, 2, 0.0, GammaRule::Bound, ws, st).tau == doctest::Approx(1.0).epsilon(1e-14));
}

TEST_CASE("multiscale: transmittance from a segment is the exact occluded share of its exchange") {
    // Plate a = [0,0]-[0,1] facing +x; a lone segment b at x = 4 (node 2 of
    // a three-segment hierarchy); a blocker at x = 2 covering y in [0.3, 0.7].
    const Segment a{{0, 1}, {0, 0}};  // lit side (left of a -> b) faces +x
    const Segment b{{4, 0}, {4, 1}};  // lit side faces -x
    const Segment blocker{{2, 0.3}, {2, 0.7}};
    const Hierarchy h({a, b, blocker}, 1);
    const ClusterTables tables(h);
    const MultiscaleVisibility ms(h, tables);
    ExactWorkspace ws;
    VisibilityStats st;
    int leaf_a = -1, leaf_b = -1;
    for (int k = 0; k < static_cast<int>(h.nodes().size()); ++k)
        if (h.node(k).leaf()) {
            const int seg = h.order()[static_cast<size_t>(h.node(k).first)];
            if (seg == 0) leaf_a = k;
            if (seg == 1) leaf_b = k;
        }
    REQUIRE(leaf_a >= 0);
    REQUIRE(leaf_b >= 0);
    const ExactVisibility exact(h);
    const double F = exact.form_factor(a, b, 0, 1, ws, st);
    const double Fu = form_factor_unoccluded(a, b);
    const TransmittanceResult t = ms.transmittance(a, leaf_a, leaf_b, leaf_b, 0.0, GammaRule::Bound, ws, st);
    // Same lines, same blocker: the two ratios agree to rounding (~1e-15).
    CHECK(t.tau == doctest::Approx(F / Fu).epsilon(1e-12));
    CHECK(t.tau > 0.2);
    CHECK(t.tau < 0.9);
    // The node's lone segment is its own stand-in, in either orientation.
    CHECK(ms.transmittance(leaf_a, leaf_b, 0.0, GammaRule::Bound, ws, st).tau == doctest::Approx(F / Fu).epsilon(1e-12));
    // A segment facing away from the node sees no stand-in: unknown.
    const TransmittanceResult away = ms.transmittance(a.reversed(), leaf_a, leaf_b, leaf_b, 0.0, GammaRule::Bound, ws, st);
    CHECK(away.tau == 1);
    CHECK(away.error_bound == 1);
}

TEST_CASE("multiscale: below the piece threshold nothing is approximated and F is exact") {
    // set_min_pieces_to_approximate is a cost choice: a shaft with fewer
    // blocker pieces gets the exact answer (bound 0); at or above it the
    // criterion decides as before. Clouds of a few dozen blockers: a
    // threshold of 10^6 covers every shaft, 0 none.
    std::mt19937_64 rng(29);
    int was_approximated = 0;
    for (int t = 0; t < 60; ++t) {
        const test::Cloud c = test::make_cloud(rng);
        const Hierarchy h(c.segments);
        const ClusterTables tables(h);
        MultiscaleVisibility ms(h, tables);
        const ExactVisibility ex(h);
        ExactWorkspace ws;
        VisibilityStats st;
        const double exact = ex.form_factor(c.i, c.j, 0, 1, ws, st);
        const MultiscaleResult loose = ms.form_factor(c.i, c.j, 0, 1, 0.1, GammaRule::Bound, ws, st);
        if (loose.clusters_approximated > 0) ++was_approximated;
        ms.set_min_pieces_to_approximate(1000000);
        const MultiscaleResult r = ms.form_factor(c.i, c.j, 0, 1, 0.1, GammaRule::Bound, ws, st);
        CAPTURE(t);
        CHECK(r.clusters_approximated == 0);
        CHECK(r.error_bound == 0);
        CHECK(std::abs(r.F - exact) <= exact_tol * std::max(exact, 1e-300));
        // Back to 0: the same approximations as before.
        ms.set_min_pieces_to_approximate(0);
        CHECK(ms.form_factor(c.i, c.j, 0, 1, 0.1, GammaRule::Bound, ws, st).clusters_approximated ==
              loose.clusters_approximated);
    }
    CHECK(was_approximated > 10);  // the threshold had something to turn off
}

TEST_CASE("multiscale: a loose query is bounded from fewer pieces, with an estimate within its bound") {
    // Sparse forests (12 to 30 sticks between the patches): below the 32
    // pieces from which any query tries the bounds, but above the 8 from
    // which a loose one does (set_min_pieces_to_bound(32, 8)). A loose
    // query (tolerance the whole unoccluded F) is then answered by bounds,
    // with their midpoint rule as its estimate: within the claimed bound of
    // F, so within twice the bound of the truth (both lie in [F - bound, F +
    // bound]). A tight one (1% of it) gets the exact integral, no estimate.
    std::mt19937_64 rng(43);
    std::uniform_real_distribution<double> U(0, 1);
    int loose_bounded = 0, tight_exact = 0;
    for (int t = 0; t < 40; ++t) {
        test::Cloud c;
        const double D = 1 + 2 * U(rng);
        c.i = {{-0.5, 0}, {0.5, 0}};
        c.j = {{0.5, D}, {-0.5, D}};
        c.segments = {c.i, c.j};
        const int n = 12 + static_cast<int>(18 * U(rng));
        while (static_cast<int>(c.segments.size()) < n + 2) {
            const Vec2 m{(U(rng) - 0.5) * 1.2, 0.1 + (D - 0.2) * U(rng)};
            const double a = 2 * M_PI * U(rng), len = 0.05 + 0.1 * U(rng);
            const Vec2 d{std::cos(a) * len / 2, std::sin(a) * len / 2};
            c.segments.push_back({m - d, m + d});
        }
        test::CloudVisibility vis(c);
        vis.multiscale.set_min_pieces_to_bound(32, 8);
        ExactWorkspace ws;
        VisibilityStats st;
        const double exact = vis.exact.form_factor(c.i, c.j, 0, 1, ws, st);
        const double unocc = form_factor_unoccluded(c.i, c.j);
        CAPTURE(t);
        const long before = st.bounded;
        const MultiscaleResult loose = vis.multiscale.form_factor(c.i, c.j, 0, 1, unocc, GammaRule::Bound, ws, st);
        if (st.bounded > before) {
            ++loose_bounded;
            REQUIRE_FALSE(std::isnan(loose.estimate));
            CHECK(std::abs(loose.estimate - loose.F) <= loose.error_bound * (1 + rounding_floor));
            CHECK(std::abs(loose.estimate - exact) <= 2 * loose.error_bound + rounding_floor * unocc);
        } else {
            CHECK(std::isnan(loose.estimate));
        }
        const long bounded_before = st.bounded;
        const MultiscaleResult tight =
            vis.multiscale.form_factor(c.i, c.j, 0, 1, 0.01 * unocc, GammaRule::Bound, ws, st);
        CHECK(st.bounded == bounded_before);  // fewer than 32 pieces: never bounds
        CHECK(std::isnan(tight.estimate));
        if (tight.error_bound == 0) {
            ++tight_exact;
            CHECK(tight.F == doctest::Approx(exact).epsilon(exact_tol));
        }
    }
    MESSAGE(loose_bounded << " of 40 loose queries bounded, " << tight_exact << " tight ones exact");
    CHECK(loose_bounded >= 20);
    CHECK(tight_exact == 40);
}
