// engine/geometry.h's segment_meets_box against an oracle: the segment
// meets the box when an end lies in it or when it properly crosses one of
// the box's edges (orientation tests); random ends do not touch an edge
// exactly, and the touching cases are checked by hand below.
#include <doctest/doctest.h>

#include <random>

#include "engine/geometry.h"

using namespace flatrad;

namespace {

bool crosses(Vec2 p, Vec2 q, Vec2 a, Vec2 b) {
    const double d1 = orient(p, q, a), d2 = orient(p, q, b), d3 = orient(a, b, p), d4 = orient(a, b, q);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

bool inside(Vec2 p, const Box& b) { return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y; }

bool meets_oracle(Vec2 p, Vec2 q, const Box& b) {
    if (inside(p, b) || inside(q, b)) return true;
    const Vec2 c[4] = {b.lo, {b.hi.x, b.lo.y}, b.hi, {b.lo.x, b.hi.y}};
    for (int k = 0; k < 4; ++k)
        if (crosses(p, q, c[k], c[(k + 1) % 4])) return true;
    return false;
}

}  // namespace

TEST_CASE("segment_meets_box: agrees with crossings of the box's edges on random segments") {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> U(-2, 2);
    Box b;
    b.add(Vec2{-0.5, -0.25});
    b.add(Vec2{0.75, 0.5});
    int met = 0, missed = 0;
    for (int n = 0; n < 20000; ++n) {
        const Vec2 p{U(rng), U(rng)}, q{U(rng), U(rng)};
        const bool expect = meets_oracle(p, q, b);
        CAPTURE(p.x);
        CAPTURE(p.y);
        CAPTURE(q.x);
        CAPTURE(q.y);
        CHECK(segment_meets_box(p, q, b) == expect);
        (expect ? met : missed) += 1;
    }
    // Both answers were exercised.
    CHECK(met > 1000);
    CHECK(missed > 1000);
}

TEST_CASE("segment_meets_box: axis-parallel segments, points, touching and empty boxes") {
    Box b;
    b.add(Vec2{0, 0});
    b.add(Vec2{1, 1});
    CHECK(segment_meets_box({-1, 0.5}, {2, 0.5}, b));     // horizontal, through
    CHECK_FALSE(segment_meets_box({-1, 1.5}, {2, 1.5}, b));  // horizontal, above
    CHECK(segment_meets_box({0.5, -1}, {0.5, 0.2}, b));   // vertical, ending inside
    CHECK_FALSE(segment_meets_box({1.5, -1}, {1.5, 2}, b));
    CHECK(segment_meets_box({0.3, 0.3}, {0.3, 0.3}, b));  // a point inside
    CHECK_FALSE(segment_meets_box({2, 2}, {2, 2}, b));
    CHECK(segment_meets_box({-1, 1}, {2, 1}, b));         // along the top edge: closed box
    CHECK(segment_meets_box({1, 2}, {2, 1}, Box{{0, 0}, {1.5, 1.5}}));  // through a corner region
    CHECK_FALSE(segment_meets_box({1.6, 2}, {2, 1.6}, Box{{0, 0}, {1.5, 1.5}}));  // passes the corner by
    CHECK_FALSE(segment_meets_box({-1, 0.5}, {2, 0.5}, Box{}));  // empty box
}
