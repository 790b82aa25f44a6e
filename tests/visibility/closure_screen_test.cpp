// Closure screens (visibility/closure_screen.h, MultiscaleVisibility::
// shown_closed): the screen's geometry, the covering test against brute
// force over sampled lines, and proofs of closure against exact visibility
// in random forests, with the targets a screen covers then closed too.
#include "visibility/closure_screen.h"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "engine/formfactor.h"
#include "engine/hierarchy.h"
#include "visibility/cluster_tables.h"
#include "visibility/exact_visibility.h"
#include "visibility/multiscale.h"

using namespace flatrad;

namespace {

// Exact occluded form factors are sums over hundreds of arcs, each exact to
// ~1e-15 of the unoccluded value: "closed" means below this share of it.
constexpr double rounding_floor = 1e-12;

Box box_of(Vec2 lo, Vec2 hi) {
    Box b;
    b.add(lo);
    b.add(hi);
    return b;
}

// Where the line from p to q crosses the screen's line, as a parameter
// along the screen (0 at its a, 1 at its b), and whether p and q lie on
// opposite sides of that line with p on the side the screen faces.
struct Crossing {
    bool across = false;
    double lambda = 0;
};
Crossing crossing(const Segment& t, Vec2 p, Vec2 q) {
    const Vec2 d = t.direction();
    const double sp = cross(d, p - t.a), sq = cross(d, q - t.a);  // > 0: the side t's left normal points to
    Crossing c;
    c.across = sp > 0 && sq < 0;
    if (!c.across) return c;
    const Vec2 x = p + (q - p) * (sp / (sp - sq));
    c.lambda = dot(x - t.a, d) / norm_squared(d);
    return c;
}

// A's leaf in a hierarchy with one segment per leaf.
int leaf_of(const Hierarchy& h, int segment) {
    for (size_t k = 0; k < h.nodes().size(); ++k) {
        const ClusterNode& n = h.node(static_cast<int>(k));
        if (n.leaf() && n.count == 1 && h.order()[static_cast<size_t>(n.first)] == segment) return static_cast<int>(k);
    }
    return -1;
}

}  // namespace

TEST_CASE("closure screen: faces the segment at the asked depth and width, none where it would not lie in front") {
    const Segment a{{0, 0}, {1, 0}};  // lit upwards
    const auto t = closure_screen(a, {0.5, 10}, 5, 1);
    REQUIRE(t.has_value());
    CHECK(t->midpoint().x == doctest::Approx(0.5));
    CHECK(t->midpoint().y == doctest::Approx(5));
    CHECK(t->length() == doctest::Approx(2));
    CHECK(dot(t->left_normal(), Vec2{0, -1}) == doctest::Approx(1));  // its lit side faces a
    // Tilted: perpendicular to the line from a's midpoint toward the point.
    const auto tilted = closure_screen(a, {3.5, 4}, 2.5, 0.5);
    REQUIRE(tilted.has_value());
    CHECK(dot(tilted->direction(), Vec2{3, 4}) == doctest::Approx(0).epsilon(1e-12));
    CHECK(distance(tilted->midpoint(), Vec2{2, 2}) == doctest::Approx(0).epsilon(1e-12));
    CHECK_FALSE(closure_screen(a, {0.5, -10}, 5, 1).has_value());   // behind a
    CHECK_FALSE(closure_screen(a, {100, 0.1}, 5, 5).has_value());   // along a: half of it behind a's line
    // Shallow and wider than a, straight ahead: a lies wholly in front of
    // it and it wholly on a's lit side, so it stands.
    CHECK(closure_screen(a, {0.5, 10}, 0.2, 1).has_value());
    // Tilted toward (10, 1) at depth 0.2: the screen (ends near (0.698,
    // 0.031) and (0.700, 0.011)) is on a's lit side, but a's end (1, 0) is
    // beyond its line (a reaches past it).
    CHECK_FALSE(closure_screen(a, {10, 1}, 0.2, 0.01).has_value());
    CHECK_FALSE(closure_screen(a, {0.5, 0}, 5, 1).has_value());     // toward a's own midpoint
    CHECK_FALSE(closure_screen(a, {0.5, 10}, 0, 1).has_value());
    CHECK_FALSE(closure_screen(a, {0.5, 10}, 5, 0).has_value());
    CHECK_FALSE(closure_screen(a, {0.5, 10}, std::numeric_limits<double>::infinity(), 1).has_value());
}

TEST_CASE("closure screen: covers a region only if every sampled line from the segment to it crosses the screen") {
    // Random segments, screens and regions; where screen_covers says yes,
    // 400 lines from random points of a (its ends among them) to random
    // points of the region (its corners among them) must all cross the
    // screen's line inside the screen, from a's side to the far side. The
    // draws also give many regions it refuses where some line misses.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(0, 1);
    int yes = 0, refused_with_a_miss = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const double angle = 2 * std::numbers::pi * U(rng), len = 0.05 + 2 * U(rng);
        const Vec2 da{std::cos(angle), std::sin(angle)};
        const Vec2 ma{10 * (U(rng) - 0.5), 10 * (U(rng) - 0.5)};
        const Segment a{ma - da * (0.5 * len), ma + da * (0.5 * len)};
        const double turn = (U(rng) - 0.5) * 2.6;  // toward, within +-75 degrees of a's normal
        const Vec2 n = a.left_normal();
        const Vec2 u = n * std::cos(turn) + rot90(n) * std::sin(turn);
        const double depth = 1 + 10 * U(rng);
        const auto t = closure_screen(a, ma + u, depth, depth * (0.02 + 0.5 * U(rng)));
        if (!t) continue;
        // The region: around a point at 0.5 to 3 times the depth, within
        // +-40 degrees of the screen's direction, up to a fifth of the
        // depth wide.
        const double beyond = depth * (0.5 + 2.5 * U(rng)), off = (U(rng) - 0.5) * 1.4;
        const Vec2 dir = u * std::cos(off) + rot90(u) * std::sin(off);
        const Vec2 c = ma + dir * beyond;
        const Vec2 half{0.2 * depth * U(rng), 0.2 * depth * U(rng)};
        const Box region = box_of(c - half, c + half);
        const bool covers = screen_covers(*t, a, region);
        const Vec2 corners[4] = {region.lo, {region.hi.x, region.lo.y}, region.hi, {region.lo.x, region.hi.y}};
        bool missed = false;
        for (int s = 0; s < 400; ++s) {
            const Vec2 p = s < 8 ? (s % 2 ? a.b : a.a) : lerp(a.a, a.b, U(rng));
            const Vec2 q = s < 8 ? corners[s / 2] : Vec2{lerp(region.lo, region.hi, U(rng)).x, lerp(region.lo, region.hi, U(rng)).y};
            const Crossing x = crossing(*t, p, q);
            const bool through = x.across && x.lambda >= 0 && x.lambda <= 1;
            missed = missed || !through;
            if (covers && !through) {
                CAPTURE(trial);
                CAPTURE(s);
                FAIL_CHECK("a line from a to the region misses a screen said to cover it");
                break;
            }
        }
        yes += covers;
        refused_with_a_miss += !covers && missed;
    }
    MESSAGE(yes << " regions covered, " << refused_with_a_miss << " refused with a line that misses");
    CHECK(yes >= 200);
    CHECK(refused_with_a_miss >= 200);
}

TEST_CASE("closure screen: a region on the screen's line, or a segment reaching it, is never covered, scale-free") {
    const Segment a{{0, 0}, {1, 0}};
    const auto t = closure_screen(a, {0.5, 10}, 5, 1);  // y = 5, x in [-0.5, 1.5]
    REQUIRE(t.has_value());
    CHECK(screen_covers(*t, a, box_of({0.4, 6}, {0.6, 6.2})));
    CHECK_FALSE(screen_covers(*t, a, box_of({0.4, 5}, {0.6, 6.2})));      // touches the line
    CHECK_FALSE(screen_covers(*t, a, box_of({0.4, 4.9}, {0.6, 6.2})));    // straddles it
    CHECK_FALSE(screen_covers(*t, a, box_of({0.4, 3}, {0.6, 3.2})));      // in front of it
    CHECK_FALSE(screen_covers(*t, a, box_of({3.0, 10}, {3.2, 10.2})));    // lines pass beside it
    CHECK_FALSE(screen_covers(*t, a, Box{}));
    const Segment far_a{{0, 0}, {1, 0}};
    CHECK_FALSE(screen_covers(*t, Segment{{0, 5}, {1, 5}}, box_of({0.4, 6}, {0.6, 6.2})));  // a on the line
    CHECK(screen_covers(*t, far_a, box_of({0.4, 6}, {0.6, 6.2})));
    // Far from a's end of the screen, lines from a to a wide region spread
    // past the screen's ends: the region [x0, x1] at y = 10 is crossed at
    // y = 5 between x0 / 2 and (x1 + 1) / 2.
    CHECK(screen_covers(*t, a, box_of({-0.9, 10}, {1.9, 10.1})));
    CHECK_FALSE(screen_covers(*t, a, box_of({-1.1, 10}, {1.9, 10.1})));
    // The same answers at every scale.
    for (const double s : {1e-6, 1e6}) {
        CAPTURE(s);
        const Segment as{a.a * s, a.b * s};
        const auto ts = closure_screen(as, Vec2{0.5, 10} * s, 5 * s, 1 * s);
        REQUIRE(ts.has_value());
        CHECK(screen_covers(*ts, as, box_of(Vec2{0.4, 6} * s, Vec2{0.6, 6.2} * s)));
        CHECK(screen_covers(*ts, as, box_of(Vec2{-0.9, 10} * s, Vec2{1.9, 10.1} * s)));
        CHECK_FALSE(screen_covers(*ts, as, box_of(Vec2{-1.1, 10} * s, Vec2{1.9, 10.1} * s)));
        CHECK_FALSE(screen_covers(*ts, as, box_of(Vec2{0.4, 5} * s, Vec2{0.6, 6.2} * s)));
    }
}

TEST_CASE("closure screen: shown closed only where exact visibility finds it closed, and what it covers is closed") {
    // Forests of random sticks (0.05 to 0.15 long, random angles, crossing
    // allowed) above a short element a lit upwards, dense enough that a
    // long shaft starts within ~10 of it. Screens in directions from 40 to
    // 140 degrees at 1.05, 0.47 and 0.37 times that depth, as the
    // hierarchical solver makes them (the nearer two shorter than a long
    // shaft: their proofs use thinner slabs), 0.05 of the depth to each
    // side, and 0.2 for wider ones that the proof fails more often. Every screen shown closed must
    // have an exact form factor from a of 0, and so must every stick it
    // covers (that stick not counted as a blocker). A lane cut through the
    // second forests leaves screens open, which must not be shown closed.
    int closed = 0, open = 0, open_exact = 0, targets = 0, closed_near = 0;
    for (const double density : {60.0, 100.0}) {
        for (unsigned seed = 1; seed <= 2; ++seed) {
            CAPTURE(density);
            CAPTURE(seed);
            std::mt19937_64 rng(seed);
            std::uniform_real_distribution<double> U(0, 1);
            const Segment a{{0, 0}, {0.2, 0}};
            std::vector<Segment> segs{a};
            const double x0 = -4, x1 = 4.2, y0 = 0.1, y1 = 14;
            const int sticks = static_cast<int>(density * (x1 - x0) * (y1 - y0));
            for (int k = 0; k < sticks; ++k) {
                const double len = 0.05 + 0.1 * U(rng), ang = std::numbers::pi * U(rng);
                const Vec2 c{x0 + (x1 - x0) * U(rng), y0 + 0.1 + (y1 - y0 - 0.2) * U(rng)};
                const Vec2 d{0.5 * len * std::cos(ang), 0.5 * len * std::sin(ang)};
                // Seed 2: a lane 0.6 wide, clear of sticks, from a's
                // midpoint at 100 degrees: the screens that way are open.
                const Vec2 lane{std::cos(100 * std::numbers::pi / 180), std::sin(100 * std::numbers::pi / 180)};
                if (seed == 2 && std::abs(cross(lane, c - a.midpoint())) < 0.3 + 0.5 * len) continue;
                segs.push_back({c - d, c + d});
            }
            const Hierarchy h(segs, 1);
            const ClusterTables tables(h);
            MultiscaleVisibility ms(h, tables);
            ms.set_min_pieces_to_prove_closed(32);
            const ExactVisibility exact(h);
            REQUIRE(std::isfinite(ms.long_shaft_depth()));
            REQUIRE(1.05 * ms.long_shaft_depth() < 0.8 * (y1 - y0));
            const int skip_a = leaf_of(h, 0);
            REQUIRE(skip_a >= 0);
            ExactWorkspace ws;
            VisibilityStats st;
            for (const double factor : {1.05, 0.47, 0.37}) {
                for (const double spread : {0.05, 0.2}) {
                    CAPTURE(factor);
                    const double depth = factor * ms.long_shaft_depth();
                    for (int deg = 40; deg <= 140; deg += 20) {
                        const double th = deg * std::numbers::pi / 180;
                        const auto t = closure_screen(a, a.midpoint() + Vec2{std::cos(th), std::sin(th)}, depth, spread * depth);
                        REQUIRE(t.has_value());
                        const bool shown = ms.shown_closed(a, skip_a, *t, ws, st);
                        const double F = exact.form_factor(a, *t, 0, -1, ws, st);
                        const double Fu = form_factor_unoccluded(a, *t);
                        CAPTURE(deg);
                        CAPTURE(spread);
                        if (!shown) {
                            ++open;
                            open_exact += F > rounding_floor * Fu;
                            continue;
                        }
                        ++closed;
                        closed_near += factor < 1;
                        CHECK(F <= rounding_floor * Fu);
                        // Up to 3 sticks it covers, each against exact.
                        int checked = 0;
                        for (size_t s = 1; s < segs.size() && checked < 3; ++s) {
                            Box b;
                            b.add(segs[s]);
                            if (!screen_covers(*t, a, b)) continue;
                            Segment target = segs[s];
                            if (orient(target.a, target.b, a.midpoint()) < 0) target = target.reversed();  // facing a
                            const double Ft = exact.form_factor(a, target, 0, static_cast<int>(s), ws, st);
                            CHECK(Ft <= rounding_floor * form_factor_unoccluded(a, target));
                            ++checked;
                        }
                        targets += checked;
                    }
                }
            }
        }
    }
    MESSAGE(closed << " screens shown closed (" << closed_near << " of them nearer than a long shaft; " << targets
                   << " covered sticks checked), " << open << " not shown closed, " << open_exact
                   << " of them open by exact visibility");
    CHECK(closed >= 8);
    CHECK(closed_near >= 8);  // the thinner slabs prove some
    CHECK(targets >= 10);
    CHECK(open_exact >= 2);  // the lanes: open screens, not shown closed
}
