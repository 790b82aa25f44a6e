// A band of blockers shown to close a shaft (visibility/opaque_band.h),
// against the exact line-space integral (ExactVisibility::
// exchange_with_blockers): a claim of "closed" must mean an exact 0; a
// staggered blind is shown closed and the same blind with a gap is not;
// scale does not change the verdicts.
#include "visibility/opaque_band.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <tuple>

#include "engine/formfactor.h"
#include "visibility/exact_visibility.h"
#include "support/facing_pairs.h"
#include "visibility/shaft.h"

using namespace flatrad;

namespace {

// The exact integral is a sum of a few hundred rounded terms of the size
// of the unoccluded exchange; a closed shaft gives 0 up to ~1e-15 of it.
// 1e-12 of it is that with a thousand-fold margin, and far below the
// exchange through the narrowest gap of these scenes (1e-4 of it or more).
constexpr double rounding_tol = 1e-12;
// A bound on a scaled and moved scene: the same arithmetic on coordinates
// of another size, each operation rounded at ~1e-16 of its operands; the
// bound sums a few hundred gaps. 1e-9 relative leaves a thousand-fold margin.
constexpr double scale_tol = 1e-9;

// The exact exchange through the blockers' parts inside the shaft.
double exact_exchange(const Segment& i, const Segment& j, const std::vector<Segment>& blockers) {
    const shaft_detail::Shaft shaft(i, j);
    std::vector<Segment> pieces;
    for (const Segment& b : blockers)
        if (shaft_detail::add_blocker(shaft, b, 0, pieces)) return 0;  // one piece closes it
    ExactWorkspace ws;
    VisibilityStats st;
    return ExactVisibility::exchange_with_blockers(i, j, pieces, ws, st);
}

// Patches 4 apart facing each other, and a blind of three pairs of
// staggered rows between them: in each pair, row A (sticks 0.3 long, gaps
// of 0.1) and 0.4 above it row B (sticks 0.4 long, each centred on a gap of
// A). A line from i to j turns at most 1/4 across: through a gap of A it
// reaches row B within 0.1 of the gap, inside the stick there with 0.05 to
// spare. (Three pairs: band_closes_shaft does not try shafts with fewer
// than opaque_band_min_layers layers of shadow; these have 10.5.)
struct Blind {
    Segment i{{0, 0}, {1, 0}}, j{{1, 4}, {0, 4}};
    std::vector<Segment> sticks;
    Blind() {
        for (const double c : {0.8, 2.0, 3.2}) {
            for (double x = -0.5; x < 1.5; x += 0.4) sticks.push_back({{x, c - 0.2}, {x + 0.3, c - 0.2}});
            for (double x = -0.35; x < 1.6; x += 0.4) sticks.push_back({{x, c + 0.2}, {x + 0.4, c + 0.2}});
        }
    }
    // Without row B's sticks that start near x0 (in every pair): the gap of
    // A under them is open through the whole blind.
    Blind without_b(double x0) const {
        Blind out = *this;
        std::erase_if(out.sticks, [&](const Segment& s) {
            const bool row_b = s.b.x - s.a.x > 0.35;
            return row_b && std::abs(s.a.x - x0) < 0.01;
        });
        return out;
    }
};

Blind scaled(const Blind& b, double s, Vec2 shift) {
    Blind out;
    auto f = [&](Segment g) { return Segment{g.a * s + shift, g.b * s + shift}; };
    out.i = f(b.i);
    out.j = f(b.j);
    out.sticks.clear();
    for (const Segment& g : b.sticks) out.sticks.push_back(f(g));
    return out;
}

// Facing pairs of random shape 0.3 to 3.3 apart; n sticks of 0.03 to 0.15
// at random angles around them (those crossing the shaft from side to side
// dropped: they close it alone). With `lane`, no stick's middle is within
// 0.15 of a random vertical line x = c, c in [0.5, 1]: a lane at least
// 0.15 wide is clear from i (y = 0, x in [0.5, 1] at least) up through the
// blockers, so a crowded shaft can still be open.
struct RandomShaft {
    Segment ci, cj;
    std::vector<Segment> sticks;
};
RandomShaft random_shaft(int n, std::mt19937_64& rng, bool lane = false) {
    std::uniform_real_distribution<double> u(0, 1);
    RandomShaft out;
    std::tie(out.ci, out.cj) = test::random_facing_pair(rng);
    const shaft_detail::Shaft shaft(out.ci, out.cj);
    const Box& box = shaft.box;
    const double lane_x = lane ? 0.5 + 0.5 * u(rng) : 0;
    int tries = 0;
    while (static_cast<int>(out.sticks.size()) < n && ++tries < 100 * n) {
        const Vec2 a{box.lo.x - 0.2 + (box.hi.x - box.lo.x + 0.4) * u(rng), box.lo.y + (box.hi.y - box.lo.y) * u(rng)};
        const double t = 2 * M_PI * u(rng), len = 0.03 + 0.12 * u(rng);
        const Segment s{a, a + Vec2{std::cos(t), std::sin(t)} * len};
        if (lane && std::abs(s.midpoint().x - lane_x) < 0.15) continue;
        std::vector<Segment> pieces;
        if (shaft_detail::add_blocker(shaft, s, 0, pieces)) continue;
        if (!pieces.empty()) out.sticks.push_back(s);
    }
    return out;
}

// band_bound with a tolerance, as the multi-scale module asks for it, and
// no limit.
BandOptions bounding() {
    BandOptions o;
    o.limit = std::numeric_limits<double>::infinity();
    o.drift = band_bound_drift;
    o.max_checks = band_bound_max_checks;
    return o;
}

}  // namespace

TEST_CASE("opaque band: a staggered blind is shown closed, and it is") {
    const Blind b;
    OpaqueBandScratch scratch;
    CHECK(exact_exchange(b.i, b.j, b.sticks) <= rounding_tol * exchange_crossed_strings(b.i, b.j));
    CHECK(band_closes_shaft(b.i, b.j, b.sticks.data(), b.sticks.size(), scratch));
}

TEST_CASE("opaque band: the blind with a gap through it is open, and not shown closed") {
    const Blind full;
    const Blind b = full.without_b(0.45);  // over A's gaps at [0.6, 0.7]
    REQUIRE(b.sticks.size() == full.sticks.size() - 3);
    OpaqueBandScratch scratch;
    CHECK(exact_exchange(b.i, b.j, b.sticks) > 1e-4 * exchange_crossed_strings(b.i, b.j));
    CHECK_FALSE(band_closes_shaft(b.i, b.j, b.sticks.data(), b.sticks.size(), scratch));
}

TEST_CASE("opaque band: a slit open only near one direction, between the bins' centres, is not shown closed") {
    // Three rows of wall-to-wall sticks (3 layers each), 0.5 apart, each
    // with a slit 0.004 wide at x = 0.5: only lines within ~0.004 rad of the
    // vertical pass all three (0.008 for the two rows a band takes). The
    // vertical is the middle of the range (the pair is symmetric), a bin
    // edge, 0.015 rad from the nearest bins' centres: a test at the bins'
    // centres alone calls it closed (checked by hand, with the drift set to
    // 0); the drift bound sees the slit.
    const Segment i{{0, 0}, {1, 0}}, j{{1, 4}, {0, 4}};
    constexpr double slit = 0.004;
    std::vector<Segment> sticks;
    for (const double y : {1.5, 2.0, 2.5}) {
        sticks.push_back({{-1, y}, {0.5 - slit / 2, y}});
        sticks.push_back({{0.5 + slit / 2, y}, {2, y}});
    }
    OpaqueBandScratch scratch;
    CHECK(exact_exchange(i, j, sticks) > 1e-9 * exchange_crossed_strings(i, j));
    CHECK_FALSE(band_closes_shaft(i, j, sticks.data(), sticks.size(), scratch));
    // Closed (no slit in the middle row), it is shown closed.
    sticks[2] = {{-1, 2.0}, {2, 2.0}};
    sticks.erase(sticks.begin() + 3);
    CHECK(exact_exchange(i, j, sticks) == 0);
    CHECK(band_closes_shaft(i, j, sticks.data(), sticks.size(), scratch));
}

TEST_CASE("opaque band: scaled by 1e-6 .. 1e6 and moved away, the verdicts stay") {
    const Blind closed;
    const Blind open = closed.without_b(0.05);  // over A's gaps at [0.2, 0.3]
    OpaqueBandScratch scratch;
    REQUIRE(exact_exchange(open.i, open.j, open.sticks) > 1e-4 * exchange_crossed_strings(open.i, open.j));
    for (const double s : {1e-6, 1e-3, 1.0, 1e3, 1e6}) {
        for (const Vec2 shift : {Vec2{0, 0}, Vec2{1e3 * s, -7e2 * s}}) {
            const Blind c = scaled(closed, s, shift), o = scaled(open, s, shift);
            CHECK_MESSAGE(band_closes_shaft(c.i, c.j, c.sticks.data(), c.sticks.size(), scratch), "scale ", s);
            CHECK_MESSAGE(!band_closes_shaft(o.i, o.j, o.sticks.data(), o.sticks.size(), scratch), "scale ", s);
        }
    }
}

TEST_CASE("opaque band: on random crowded shafts, every shaft shown closed has an exact exchange of 0") {
    // Dense sets are mostly closed, sparse ones open: both verdicts must
    // occur, and "closed" must be right.
    std::mt19937_64 rng(17);
    OpaqueBandScratch scratch;
    int shown_closed = 0, open_exact = 0, cases = 0;
    for (const int n : {60, 120, 160, 200, 500}) {
        for (int rep = 0; rep < (n == 60 || n == 500 ? 12 : 60); ++rep) {
            const RandomShaft r = random_shaft(n, rng);
            const double unocc = exchange_crossed_strings(r.ci, r.cj);
            const double exact = exact_exchange(r.ci, r.cj, r.sticks);
            const bool closed = band_closes_shaft(r.ci, r.cj, r.sticks.data(), r.sticks.size(), scratch);
            if (closed) {
                ++shown_closed;
                CHECK_MESSAGE(exact <= rounding_tol * unocc, "n ", n, " rep ", rep, ": shown closed, exact ", exact,
                              " of ", unocc);
            } else if (exact > rounding_tol * unocc) {
                ++open_exact;
            }
            ++cases;
        }
    }
    MESSAGE(cases, " shafts: ", shown_closed, " shown closed, ", open_exact, " open");
    CHECK(shown_closed >= 3);
    CHECK(open_exact >= 3);
}

TEST_CASE("opaque band: on random crowded shafts, the bound is never below the exact exchange") {
    // The bound must hold on every shaft it is made for, open or closed, and
    // tell something: on the densest sets without a lane (most of them
    // nearly closed) it is well below the unoccluded exchange.
    std::mt19937_64 rng(29);
    OpaqueBandScratch scratch;
    int made = 0, open_bounded = 0, zero = 0, tight = 0, dense = 0;
    for (const int n : {200, 500, 800}) {
        for (int rep = 0; rep < 40; ++rep) {
            const bool lane = rep % 2 == 1;
            const RandomShaft r = random_shaft(n, rng, lane);
            const double unocc = exchange_crossed_strings(r.ci, r.cj);
            const double exact = exact_exchange(r.ci, r.cj, r.sticks);
            const double upper = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), bounding(), scratch);
            if (!std::isfinite(upper)) continue;
            ++made;
            CHECK_MESSAGE(upper >= exact - rounding_tol * unocc, "n ", n, " rep ", rep, ": bound ", upper,
                          " below exact ", exact, " of ", unocc);
            if (upper == 0) ++zero;
            if (exact > rounding_tol * unocc) ++open_bounded;
            if (n == 500 && !lane) {
                ++dense;
                if (upper <= 0.05 * unocc) ++tight;
            }
        }
    }
    MESSAGE(made, " bounds: ", zero, " of 0, ", open_bounded, " on open shafts; ", tight, " of ", dense,
            " dense ones within 5% of the unoccluded exchange");
    CHECK(made >= 60);
    CHECK(zero >= 3);
    CHECK(open_bounded >= 20);
    CHECK(tight * 2 >= dense);
}

TEST_CASE("opaque band: bins checked again in halves close shafts one width leaves open, and only closed ones") {
    // A bin's check narrows each shadow by how far its piece drifts within
    // the bin; halves drift half as far. Halving may only add proofs (a
    // shaft closed at one width is closed with halvings: the first pass is
    // the same), every proof must be right, and on crowded random shafts
    // some must be added, or the halving does nothing. As bounds (with a
    // limit, the multi-scale module's use), halving may only lower them,
    // never below the exact exchange.
    std::mt19937_64 rng(41);
    OpaqueBandScratch scratch;
    BandOptions one_width;
    one_width.halvings = 0;
    const BandOptions halved;  // opaque_band_halvings
    REQUIRE(halved.halvings > 0);
    int closed_once = 0, added = 0, bounds = 0, lowered = 0;
    for (const int n : {200, 300, 500}) {
        for (int rep = 0; rep < 40; ++rep) {
            const RandomShaft r = random_shaft(n, rng);
            const double unocc = exchange_crossed_strings(r.ci, r.cj);
            const double exact = exact_exchange(r.ci, r.cj, r.sticks);
            const bool closed_one = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), one_width, scratch) == 0;
            const bool closed_halved = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), halved, scratch) == 0;
            if (closed_one) {
                ++closed_once;
                CHECK_MESSAGE(closed_halved, "n ", n, " rep ", rep, ": closed at one width, not with halvings");
            } else if (closed_halved) {
                ++added;
            }
            if (closed_halved)
                CHECK_MESSAGE(exact <= rounding_tol * unocc, "n ", n, " rep ", rep, ": shown closed, exact ", exact,
                              " of ", unocc);
            // As a bound: with no limit nothing is halved; with a limit of
            // half that bound the bins at one width take the sum past it
            // (not shown), and halved they may keep within it.
            BandOptions b_one = bounding();
            b_one.halvings = 0;
            const double u_one = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), b_one, scratch);
            if (!(std::isfinite(u_one) && u_one > 0)) continue;
            ++bounds;
            CHECK(band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), bounding(), scratch) == u_one);
            BandOptions b_half = bounding();
            b_half.limit = 0.5 * u_one;
            const double u_halved = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), b_half, scratch);
            b_half.halvings = 0;
            CHECK(std::isinf(band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), b_half, scratch)));
            if (std::isfinite(u_halved)) {
                ++lowered;
                CHECK(u_halved <= b_half.limit);
                CHECK_MESSAGE(u_halved >= exact - rounding_tol * unocc, "n ", n, " rep ", rep, ": bound ", u_halved,
                              " below exact ", exact);
            }
        }
    }
    MESSAGE(closed_once, " shown closed at one width, ", added, " more with halvings; ", bounds, " bounds, ", lowered,
            " of them halved within half their one-width value");
    CHECK(closed_once >= 3);
    CHECK(added >= 1);
    CHECK(lowered >= 1);
}

TEST_CASE("opaque band: the blind with a gap is bounded above its exchange, and the limit is kept") {
    const Blind b = Blind{}.without_b(0.45);
    OpaqueBandScratch scratch;
    const double exact = exact_exchange(b.i, b.j, b.sticks);
    const double unocc = exchange_crossed_strings(b.i, b.j);
    REQUIRE(exact > 1e-4 * unocc);
    const double upper = band_bound(b.i, b.j, b.sticks.data(), b.sticks.size(), bounding(), scratch);
    MESSAGE("exact ", exact, ", bound ", upper, ", unoccluded ", unocc);
    CHECK(upper >= exact);
    CHECK(upper < unocc);
    // A limit below the bound: not shown (+infinity), whatever the bins
    // summed before giving up.
    BandOptions tight = bounding();
    tight.limit = 0.5 * upper;
    CHECK(std::isinf(band_bound(b.i, b.j, b.sticks.data(), b.sticks.size(), tight, scratch)));
    tight.limit = upper;
    CHECK(band_bound(b.i, b.j, b.sticks.data(), b.sticks.size(), tight, scratch) == upper);
    // Scaled by s, the bound (a length) scales by s.
    for (const double s : {1e-6, 1e3}) {
        const Blind c = scaled(b, s, Vec2{3e2 * s, 1e2 * s});
        const double scaled_upper = band_bound(c.i, c.j, c.sticks.data(), c.sticks.size(), bounding(), scratch);
        CHECK_MESSAGE(std::abs(scaled_upper / s - upper) <= scale_tol * upper, "scale ", s);
    }
}

TEST_CASE("opaque band: nothing to show, or nothing finite: not closed") {
    const Blind b;
    OpaqueBandScratch scratch;
    CHECK_FALSE(band_closes_shaft(b.i, b.j, nullptr, 0, scratch));
    // Patches sharing an endpoint: no slab of depths between them.
    const Segment i{{0, 0}, {1, 0}}, j{{0, 1}, {0, 0}};
    CHECK_FALSE(band_closes_shaft(i, j, b.sticks.data(), b.sticks.size(), scratch));
    // A blocker with a non-finite end is passed over: the blind's own
    // sticks still close it. A non-finite patch is not tried.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<Segment> with_nan = b.sticks;
    with_nan.insert(with_nan.begin() + 3, Segment{{0.5, 2.0}, {nan, 2.0}});
    CHECK(band_closes_shaft(b.i, b.j, with_nan.data(), with_nan.size(), scratch));
    const Segment bad{{0, 0}, {nan, 0}};
    CHECK_FALSE(band_closes_shaft(bad, b.j, b.sticks.data(), b.sticks.size(), scratch));
    // A patch as long as doubles go, under the small blind: most of its
    // lines to j pass beside the blind (open), and its frame overflows.
    const double huge = std::numeric_limits<double>::max();
    const Segment far{{-huge, 0}, {huge, 0}};
    CHECK_FALSE(band_closes_shaft(far, b.j, b.sticks.data(), b.sticks.size(), scratch));
}

namespace {

// gaps_in_window's oracle: sort by start, sweep once (the section check as
// it was).
double gaps_by_sorting(OffsetInterval window, std::vector<OffsetInterval> shadows, double budget) {
    std::sort(shadows.begin(), shadows.end(), [](const OffsetInterval& x, const OffsetInterval& y) { return x.a < y.a; });
    double reach = window.a, free = 0;
    for (const OffsetInterval& sh : shadows) {
        if (sh.a > reach) {
            free += sh.a - reach;
            if (free > budget) return free;
        }
        reach = std::max(reach, sh.b);
        if (reach >= window.b) return free;
    }
    return free + (window.b - reach);
}

}  // namespace

TEST_CASE("opaque band: a section's gaps summed by hops are the sorted sweep's, bit for bit") {
    // Windows covered many times over (a band's usual section: a few hops),
    // sparse ones (many gaps: the sweep takes over past the hop budget),
    // shadows sharing ends, starting before the window or running past it,
    // and budgets that stop the sum part way.
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    long compared = 0, covered = 0, stopped = 0, many_gaps = 0;
    for (int t = 0; t < 20000; ++t) {
        const double scale = std::ldexp(1.0, static_cast<int>(60 * u(rng)) - 30);
        const OffsetInterval window{-scale * u(rng), scale * (1 + u(rng))};
        const double width = window.b - window.a;
        const int m = 1 + static_cast<int>(80 * u(rng));
        const double mean_length = width * (t % 3 == 0 ? 0.02 : t % 3 == 1 ? 0.2 : 0.6) * (0.5 + u(rng));
        std::vector<OffsetInterval> shadows;
        for (int k = 0; k < m; ++k) {
            const double a = window.a - 0.2 * width + 1.4 * width * u(rng);
            OffsetInterval sh{a, a + mean_length * (0.1 + u(rng))};
            if (!shadows.empty() && u(rng) < 0.1) sh.a = shadows.back().b;  // abutting: no gap between them
            if (sh.b > sh.a && sh.b > window.a && sh.a < window.b) shadows.push_back(sh);
        }
        const double budget = t % 4 == 0 ? std::numeric_limits<double>::infinity() : width * 0.3 * u(rng);
        std::vector<OffsetInterval> work = shadows;
        const double by_hops = gaps_in_window(window, work.data(), work.size(), budget);
        const double by_sorting = gaps_by_sorting(window, shadows, budget);
        CHECK(by_hops == by_sorting);
        covered += by_sorting == 0;
        stopped += by_sorting > budget;
        // Gaps in the union over the window, counted by the oracle's order.
        std::sort(shadows.begin(), shadows.end(), [](const OffsetInterval& x, const OffsetInterval& y) { return x.a < y.a; });
        int gaps = 0;
        double reach = window.a;
        for (const OffsetInterval& sh : shadows) {
            gaps += sh.a > reach;
            reach = std::max(reach, sh.b);
        }
        many_gaps += gaps > 12;
        ++compared;
    }
    CHECK(compared == 20000);
    // Each regime was reached: windows wholly covered, sums stopped by the
    // budget, and more gaps than hops (the sweep's part).
    CHECK(covered > 1000);
    CHECK(stopped > 1000);
    CHECK(many_gaps > 1000);
}

TEST_CASE("opaque band: a section's held shadows, four at a time, are the obvious loop's, bit for bit") {
    // The oracle: each item's shadow held over the bin, kept when not empty
    // and meeting the window, in order (band_bound's step as first written).
    auto oracle = [](const std::vector<OpaqueBandScratch::Item>& items, Vec2 n, double h, OffsetInterval window) {
        std::vector<OffsetInterval> kept;
        for (const auto& e : items) {
            const OffsetInterval sh = held(n.x * e.p.x + n.y * e.p.y, e.rp * h, n.x * e.q.x + n.y * e.q.y, e.rq * h);
            if (sh.b > sh.a && sh.b > window.a && sh.a < window.b) kept.push_back(sh);
        }
        return kept;
    };
    auto same_bits = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> u(-1, 1);
    const double specials[] = {0.0, -0.0, std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    long compared = 0, with_specials = 0, kept_some = 0, dropped_some = 0;
    for (int t = 0; t < 5000; ++t) {
        const int count = t % 13;  // 0 .. 12: whole steps of four and every tail
        const double angle = 3.2 * u(rng);
        const Vec2 n{-std::sin(angle), std::cos(angle)};
        const double h = t % 7 == 0 ? 0.0 : 0.05 * std::abs(u(rng));
        OffsetInterval window{-0.5 + 0.3 * u(rng), 0.5 + 0.3 * u(rng)};
        std::vector<OpaqueBandScratch::Item> items;
        bool special = false;
        for (int k = 0; k < count; ++k) {
            OpaqueBandScratch::Item e{{u(rng), u(rng)}, {u(rng), u(rng)}, 0, 0};
            if (t % 5 == 0) e.q = e.p;  // a point: its held shadow is empty
            e.rp = norm(e.p);
            e.rq = norm(e.q);
            if (t % 11 == 0) {  // NaN, infinities and signed zeros in any field
                double* field = &e.p.x + static_cast<int>(6 * (0.5 + 0.5 * u(rng))) % 6;
                *field = specials[static_cast<size_t>(5 * (0.5 + 0.5 * u(rng))) % 5];
                special = true;
            }
            items.push_back(e);
        }
        // Shadows that end exactly where the window starts, or start where
        // it ends: not kept (they meet it in a point).
        if (count > 0 && t % 3 != 0) {
            const auto& e = items[static_cast<size_t>(t) % items.size()];
            const OffsetInterval sh = held(n.x * e.p.x + n.y * e.p.y, e.rp * h, n.x * e.q.x + n.y * e.q.y, e.rq * h);
            if (t % 3 == 1) window.b = sh.a;
            else window.a = sh.b;
        }
        const std::vector<OffsetInterval> want = oracle(items, n, h, window);
        std::vector<OffsetInterval> got(static_cast<size_t>(count) + 1, OffsetInterval{7, 7});
        const size_t m = held_in_window(items.data(), items.size(), n, h, window, got.data());
        REQUIRE(m == want.size());
        for (size_t k = 0; k < m; ++k) {
            CHECK(same_bits(got[k].a, want[k].a));
            CHECK(same_bits(got[k].b, want[k].b));
        }
        ++compared;
        with_specials += special;
        kept_some += m > 0;
        dropped_some += m < items.size();
    }
    CHECK(compared == 5000);
    // Each case was met: specials, shadows kept, shadows dropped.
    CHECK(with_specials > 100);
    CHECK(kept_some > 1000);
    CHECK(dropped_some > 1000);
}

TEST_CASE("opaque band: the runs found bucket by bucket give the whole sort's answers, bit for bit") {
    // band_bound finds each band's run of pieces nearest its depth in
    // buckets of depth sorted on demand; sorting every piece at once
    // (depth_bucket SIZE_MAX) is the oracle. Proofs and bounds, with the
    // bands evenly spaced and at depths the caller chose, with buckets of
    // one piece up to the default.
    std::mt19937_64 rng(31);
    OpaqueBandScratch scratch;
    int compared = 0, finite = 0;
    for (const int n : {120, 500, 800}) {
        for (int rep = 0; rep < 20; ++rep) {
            const RandomShaft r = random_shaft(n, rng, rep % 2 == 1);
            const shaft_detail::PairFrame frame(r.ci, r.cj);
            const double xi = std::max(frame.local(r.ci.a).x, frame.local(r.ci.b).x);
            const double xj = std::min(frame.local(r.cj.a).x, frame.local(r.cj.b).x);
            const double chosen[opaque_band_count] = {xi + 0.1 * (xj - xi), xi + 0.2 * (xj - xi), xi + 0.3 * (xj - xi)};
            for (const bool bound : {false, true})
                for (const bool at_chosen : {false, true}) {
                    BandOptions o = bound ? bounding() : BandOptions{};
                    o.depths = at_chosen ? chosen : nullptr;
                    o.depth_bucket = std::numeric_limits<size_t>::max();
                    const double whole = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), o, scratch);
                    for (const size_t bucket : {size_t{1}, size_t{3}, size_t{16}}) {
                        o.depth_bucket = bucket;
                        const double by_buckets = band_bound(r.ci, r.cj, r.sticks.data(), r.sticks.size(), o, scratch);
                        CHECK(by_buckets == whole);  // (+infinity == +infinity where not shown)
                        ++compared;
                    }
                    finite += std::isfinite(whole);
                }
        }
    }
    CHECK(compared == 3 * 20 * 4 * 3);
    CHECK(finite >= 40);  // proofs and bounds were made, not only refused
}
