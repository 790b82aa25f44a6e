// The shaft's culling tests (visibility/shaft.h) against the slow obvious
// versions they replaced, kept here as oracles:
//   - Shaft::overlaps may say "overlaps" for a box that does not (it is a
//     filter: a node visited for nothing), never "disjoint" for one that
//     does; and it must still cull what is clearly outside.
//   - add_blocker's plain-arithmetic shortcuts for "clearly off a patch's
//     line" and "wholly and clearly inside the shaft" must give the same
//     pieces as the exact tests alone, also for pieces placed at the
//     tolerance's edge, a hair inside or outside an edge, and at extreme
//     coordinates.
#include "visibility/shaft.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

using namespace flatrad;
using shaft_detail::Shaft;

namespace {

// "Clearly outside": by more than this share of the scene's coordinates,
// a million times shaft_detail::culling_slack (the margin the culling
// keeps, relative to the same magnitudes up to small factors).
constexpr double clearly_out_by = 1e-7;

// The separating-axis test as it was: every corner tested with the FMA
// orientation (engine/geometry.h).
bool overlaps_oracle(const Shaft& s, const Box& b) {
    if (b.hi.x < s.box.lo.x || b.lo.x > s.box.hi.x || b.hi.y < s.box.lo.y || b.lo.y > s.box.hi.y) return false;
    const std::array<Vec2, 4> corner{b.lo, Vec2{b.hi.x, b.lo.y}, b.hi, Vec2{b.lo.x, b.hi.y}};
    for (size_t e = 0; e < 4; ++e) {
        if (!s.edge_ok[e]) continue;
        const Vec2 p = s.v[e], q = s.v[(e + 1) % 4];
        bool all_out = true;
        for (const Vec2& c : corner)
            if (orient(p, q, c) >= 0) {
                all_out = false;
                break;
            }
        if (all_out) return false;
    }
    return true;
}

// The least distance from the box to the shaft's region, roughly: how far
// outside the nearest edge's line its nearest corner is, over the edge's
// length (0 when the oracle says it overlaps).
double outside_by(const Shaft& s, const Box& b) {
    const std::array<Vec2, 4> corner{b.lo, Vec2{b.hi.x, b.lo.y}, b.hi, Vec2{b.lo.x, b.hi.y}};
    double worst = 0;
    for (size_t e = 0; e < 4; ++e) {
        if (!s.edge_ok[e]) continue;
        const Vec2 p = s.v[e], q = s.v[(e + 1) % 4];
        double best = -std::numeric_limits<double>::infinity();
        for (const Vec2& c : corner) best = std::max(best, orient(p, q, c) / distance(p, q));
        worst = std::max(worst, -best);
    }
    return worst;
}

// add_blocker as it was: the exact on-line test alone.
bool add_blocker_oracle(const Shaft& shaft, const Segment& s, std::vector<Segment>& blockers) {
    Segment piece;
    int enter = -1, leave = -1;
    if (!shaft.clip(s, piece, enter, leave)) return false;
    const auto magnitude = [](Vec2 v) { return std::max(std::abs(v.x), std::abs(v.y)); };
    const auto on_line = [&](Vec2 p, Vec2 q, Vec2 x) {
        const bool from_p = distance(x, p) <= distance(x, q);
        const Vec2 near = from_p ? p : q;
        const double o = from_p ? orient(p, q, x) : -orient(q, p, x);
        const double local = std::max(magnitude(x), magnitude(near)) + distance(x, near);
        return o <= shaft_detail::on_edge_tolerance * local * distance(p, q);
    };
    bool end_on_patch_line = false;
    for (size_t e : {size_t{0}, size_t{2}}) {
        const Vec2 p = shaft.v[e], q = shaft.v[e + 1];
        const bool a_on = on_line(p, q, piece.a), b_on = on_line(p, q, piece.b);
        if (a_on && b_on) return false;
        end_on_patch_line = end_on_patch_line || a_on || b_on;
    }
    if (!end_on_patch_line && ((enter == 1 && leave == 3) || (enter == 3 && leave == 1))) return true;
    blockers.push_back(piece);
    return false;
}

// add_blocker against its oracle on one segment: the same verdict and the
// same piece, bit for bit. Returns the oracle's pieces (none or one) and
// whether it closes the shaft.
std::pair<std::vector<Segment>, bool> check_against_oracle(const Shaft& s, const Segment& b) {
    std::vector<Segment> fast, oracle;
    const bool fast_closes = shaft_detail::add_blocker(s, b, 0, fast);
    const bool oracle_closes = add_blocker_oracle(s, b, oracle);
    CHECK(fast_closes == oracle_closes);
    REQUIRE(fast.size() == oracle.size());
    if (!fast.empty()) {
        CHECK(fast[0].a == oracle[0].a);
        CHECK(fast[0].b == oracle[0].b);
    }
    return {oracle, oracle_closes};
}

// A facing pair lit on the left: i along y = 0 (lit upward), j above it
// (lit downward), both tilted a little, moved by `offset`, scaled by `scale`.
struct Pair {
    Segment i, j;
};
Pair random_pair(std::mt19937_64& rng, double scale, Vec2 offset) {
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec2 a{-1 + 0.3 * u(rng), 0.2 * u(rng)}, b{1 + 0.3 * u(rng), 0.2 * u(rng)};
    const Vec2 c{1 + 0.5 * u(rng), 2 + 0.5 * u(rng)}, d{-1 + 0.5 * u(rng), 2 + 0.5 * u(rng)};
    auto place = [&](Vec2 p) { return offset + scale * p; };
    return {{place(a), place(b)}, {place(c), place(d)}};
}

// A box of size up to `size` (times scale) centred within `spread` of the
// pair's middle (0, 1), a little lopsided.
Box random_box(std::mt19937_64& rng, double scale, Vec2 offset, double spread, double size) {
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec2 c = offset + scale * Vec2{spread * u(rng), 1 + spread * u(rng)};
    const double r = scale * size * std::abs(u(rng));
    Box b;
    b.add(c - Vec2{r, 0.7 * r});
    b.add(c + Vec2{0.4 * r, r});
    return b;
}

}  // namespace

TEST_CASE("shaft: culling never drops a box the corner test keeps, and still culls what is clearly out") {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    // Scenes of unit size near the origin, and the same far from it; at the
    // fuzzer's 1e14 offsets (coordinates rounded by ulps of 1e14, the margin
    // of the size of the scene) only "never drops" is asked.
    struct Case {
        double scale;
        Vec2 offset;
        bool culls;
    };
    for (const auto& [scale, offset, culls] : {Case{1.0, {0, 0}, true}, Case{1e-3, {3, -2}, true},
                                               Case{1e6, {0, 0}, true}, Case{1.0, {1e6, -3e5}, true},
                                               Case{1.0, {1e14, -3e13}, false}}) {
        long kept = 0, culled = 0, clearly_out = 0;
        for (int t = 0; t < 400; ++t) {
            const Pair pr = random_pair(rng, scale, offset);
            const Shaft s(pr.i, pr.j);
            for (int k = 0; k < 50; ++k) {
                const Box b = random_box(rng, scale, offset, 2.5, 0.3);
                const bool oracle = overlaps_oracle(s, b), fast = s.overlaps(b);
                if (oracle) {
                    CHECK(fast);  // never drops an overlapping box
                    ++kept;
                } else if (culls && outside_by(s, b) > clearly_out_by * (scale + std::abs(offset.x) + std::abs(offset.y))) {
                    // Clearly outside (by far more than the culling margin):
                    // culled as before.
                    CHECK_FALSE(fast);
                    ++clearly_out;
                }
                culled += fast ? 0 : 1;
            }
        }
        // Both verdicts occur (the draw is not degenerate).
        CHECK(kept > 1000);
        if (culls) {
            CHECK(clearly_out > 1000);
            CHECK(culled >= clearly_out);
        }
    }
}

// Every corner of the box inside the closed shaft (the FMA orientation).
bool inside_oracle(const Shaft& s, const Box& b) {
    const std::array<Vec2, 4> corner{b.lo, Vec2{b.hi.x, b.lo.y}, b.hi, Vec2{b.lo.x, b.hi.y}};
    for (size_t e = 0; e < 4; ++e) {
        if (!s.edge_ok[e]) continue;
        for (const Vec2& c : corner)
            if (orient(s.v[e], s.v[(e + 1) % 4], c) < 0) return false;
    }
    return true;
}

TEST_CASE("shaft: a box said to be inside is inside, and boxes clearly inside are said so") {
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(-1, 1);
    for (const auto& [scale, offset] : {std::pair{1.0, Vec2{0, 0}}, std::pair{1e-3, Vec2{3, -2}},
                                        std::pair{1.0, Vec2{1e6, -3e5}}, std::pair{1.0, Vec2{1e14, -3e13}}}) {
        long inside = 0, across = 0;
        for (int t = 0; t < 400; ++t) {
            const Pair pr = random_pair(rng, scale, offset);
            const Shaft s(pr.i, pr.j);
            for (int k = 0; k < 50; ++k) {
                const Box b = random_box(rng, scale, offset, 0.8, 0.2);
                const Shaft::Where w = s.where(b);
                CHECK((w == Shaft::Where::outside) == !s.overlaps(b));
                if (w == Shaft::Where::inside) {
                    CHECK(inside_oracle(s, b));  // surely inside
                    ++inside;
                } else if (w == Shaft::Where::across) {
                    ++across;
                }
            }
        }
        // Near the origin most of these boxes lie well inside the shaft;
        // at 1e14 the margin is of the scene's size and nothing need be.
        if (std::abs(offset.x) < 1e10) CHECK(inside > 2000);
        CHECK(inside + across > 2000);
    }
}

TEST_CASE("shaft: a box touching an edge, or sharing a corner with the shaft, overlaps") {
    const Segment i{{0, 0}, {2, 0}}, j{{2, 3}, {0, 3}};  // a 2 x 3 rectangle shaft
    const Shaft s(i, j);
    for (const double offset : {0.0, 1e14}) {
        const Shaft far(Segment{i.a + Vec2{offset, 0}, i.b + Vec2{offset, 0}},
                        Segment{j.a + Vec2{offset, 0}, j.b + Vec2{offset, 0}});
        const Shaft& sh = offset == 0 ? s : far;
        auto box = [&](double x0, double y0, double x1, double y1) {
            Box b;
            b.add(Vec2{x0 + offset, y0});
            b.add(Vec2{x1 + offset, y1});
            return b;
        };
        CHECK(sh.overlaps(box(2, 1, 3, 2)));    // touches the right side
        CHECK(sh.overlaps(box(-1, 3, 0, 4)));   // shares the corner (0, 3)
        CHECK(sh.overlaps(box(0.5, 0.5, 1, 1)));  // inside
        CHECK_FALSE(sh.overlaps(box(2.5, 1, 3, 2)));  // half a unit right of it
    }
    // A slanted shaft: a box whose corner lies on the slanted side.
    const Shaft slant(Segment{{0, 0}, {1, 0}}, Segment{{3, 2}, {2, 2}});  // sides (1,0)-(3,2) and (2,2)-(0,0)
    Box on_side;
    on_side.add(Vec2{2, 1});  // on the line y = x - 1
    on_side.add(Vec2{3, 1.5});
    CHECK(overlaps_oracle(slant, on_side));
    CHECK(slant.overlaps(on_side));
}

TEST_CASE("shaft: add_blocker's shortcut gives the exact test's pieces, at the tolerance's edge too") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    long compared = 0, dropped_on_line = 0;
    for (const auto& [scale, offset] : {std::pair{1.0, Vec2{0, 0}}, std::pair{1.0, Vec2{5e14, 5e14}},
                                        std::pair{1e-4, Vec2{0, 0}}, std::pair{1e8, Vec2{-1e8, 0}}}) {
        for (int t = 0; t < 200; ++t) {
            const Pair pr = random_pair(rng, scale, offset);
            const Shaft s(pr.i, pr.j);
            for (int k = 0; k < 40; ++k) {
                Segment b;
                if (k % 4 == 0) {
                    // Along patch i's line, off it by a few times the
                    // tolerance (relative to the local scale) either way.
                    const Vec2 d = pr.i.b - pr.i.a, n = rot90(d) / norm(d);
                    const double local = scale + std::abs(offset.x) + std::abs(offset.y);
                    const double off = local * shaft_detail::on_edge_tolerance * 8 * u(rng);
                    b = {lerp(pr.i.a, pr.i.b, 0.2 + 0.2 * u(rng)) + off * n, lerp(pr.i.a, pr.i.b, 0.7 + 0.2 * u(rng)) + off * n};
                } else if (k % 4 == 1) {
                    // From patch j's line into the shaft.
                    b = {lerp(pr.j.a, pr.j.b, 0.5 + 0.4 * u(rng)),
                         offset + scale * Vec2{u(rng), 1 + 0.8 * u(rng)}};
                } else {
                    b = {offset + scale * Vec2{1.5 * u(rng), 1 + 1.2 * u(rng)},
                         offset + scale * Vec2{1.5 * u(rng), 1 + 1.2 * u(rng)}};
                }
                const auto [oracle, oracle_closes] = check_against_oracle(s, b);
                if (k % 4 == 0 && oracle.empty() && !oracle_closes) ++dropped_on_line;
                ++compared;
            }
        }
    }
    CHECK(compared == 4 * 200 * 40);
    CHECK(dropped_on_line > 100);  // the edge cases were reached: pieces along the patch dropped
}

TEST_CASE("shaft: add_blocker's inside shortcut gives the exact test's pieces, a hair from every edge") {
    // Segments with one end well inside and the other a few roundings (of
    // the coordinates' magnitude) from one of the four edges' lines, on
    // either side, or on it: where the plain products cannot tell the side,
    // the shortcut must leave the piece to the exact clip.
    std::mt19937_64 rng(13);
    std::uniform_real_distribution<double> u(-1, 1);
    long compared = 0, whole = 0, cut = 0;
    for (const auto& [scale, offset] : {std::pair{1.0, Vec2{0, 0}}, std::pair{1.0, Vec2{5e14, 5e14}},
                                        std::pair{1e-4, Vec2{0, 0}}, std::pair{1e8, Vec2{-1e8, 0}}}) {
        const double local = scale + std::abs(offset.x) + std::abs(offset.y);
        for (int t = 0; t < 200; ++t) {
            const Pair pr = random_pair(rng, scale, offset);
            const Shaft s(pr.i, pr.j);
            const Vec2 centre = 0.25 * (s.v[0] + s.v[1] + s.v[2] + s.v[3]);
            for (size_t e = 0; e < 4; ++e) {
                const Vec2 p = s.v[e], q = s.v[(e + 1) % 4];
                const Vec2 inward = rot90(q - p) / norm(q - p);  // the shaft is counter-clockwise: inside is left
                for (int k = 0; k < 12; ++k) {
                    // A point on the edge's line, moved across it by a few
                    // ulps to a few thousand of the local magnitude.
                    const double ulps = std::ldexp(1.0, static_cast<int>(std::floor(12 * std::abs(u(rng)))));
                    const double off = u(rng) * ulps * std::numeric_limits<double>::epsilon() * local;
                    const Vec2 near = lerp(p, q, 0.5 + 0.45 * u(rng)) + off * inward;
                    const Vec2 far = lerp(centre, near, 0.3 + 0.3 * std::abs(u(rng)));
                    const Segment b = k % 2 ? Segment{near, far} : Segment{far, near};
                    const auto [oracle, oracle_closes] = check_against_oracle(s, b);
                    if (!oracle.empty()) ++(oracle[0].a == b.a && oracle[0].b == b.b ? whole : cut);
                    ++compared;
                }
            }
        }
    }
    CHECK(compared == 4 * 200 * 4 * 12);
    // Both outcomes were reached: pieces kept whole and pieces cut at the edge.
    CHECK(whole > 1000);
    CHECK(cut > 100);
}
