// engine/box_intrusion.h: the chord of a segment through a box's interior,
// against an oracle on random segments (the fraction of 20 000 points
// along the segment that lie strictly inside the box, times its length),
// by hand where ends touch edges and corners, and over a hierarchy with
// skipped places, segments that cannot block, and the length and chord
// limits.
#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "engine/box_intrusion.h"
#include "engine/hierarchy.h"

using namespace flatrad;

namespace {

Box box(Vec2 lo, Vec2 hi) {
    Box b;
    b.add(lo);
    b.add(hi);
    return b;
}

bool strictly_inside(Vec2 p, const Box& b) { return p.x > b.lo.x && p.x < b.hi.x && p.y > b.lo.y && p.y < b.hi.y; }

// The length of s inside b's interior by sampling: n points at the middles
// of n equal steps.
double sampled_chord(const Segment& s, const Box& b, int n) {
    int in = 0;
    for (int k = 0; k < n; ++k)
        if (strictly_inside(lerp(s.a, s.b, (k + 0.5) / n), b)) ++in;
    return s.length() * in / n;
}

}  // namespace

TEST_CASE("chord_through_box: agrees with sampling on random segments") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(-2, 2);
    const Box b = box({-0.5, -0.25}, {0.75, 0.5});
    constexpr int samples = 20000;
    int through = 0, missed = 0;
    for (int n = 0; n < 2000; ++n) {
        const Segment s{{U(rng), U(rng)}, {U(rng), U(rng)}};
        const double chord = chord_through_box(s, b), sampled = sampled_chord(s, b, samples);
        CAPTURE(s.a.x); CAPTURE(s.a.y); CAPTURE(s.b.x); CAPTURE(s.b.y);
        // Sampling misses at most a step at each end of the chord.
        REQUIRE(std::abs(chord - sampled) <= 2 * s.length() / samples);
        // A segment in general position crosses the interior wherever it
        // meets the closed box.
        REQUIRE((chord > 0) == segment_meets_box(s.a, s.b, b));
        (chord > 0 ? through : missed)++;
    }
    // Both answers are exercised.
    CHECK(through > 200);
    CHECK(missed > 200);
}

TEST_CASE("chord_through_box: ends on edges and corners, along edges, and boxes of no area") {
    const Box b = box({0, 0}, {2, 1});
    // Across, from edge to edge, either way: the box's width.
    CHECK(chord_through_box({{-1, 0.5}, {3, 0.5}}, b) == doctest::Approx(2));
    CHECK(chord_through_box({{3, 0.5}, {-1, 0.5}}, b) == doctest::Approx(2));
    // Starting exactly on an edge, or at a corner (a shelf's top from the
    // corner of its end face).
    CHECK(chord_through_box({{0, 0.5}, {3, 0.5}}, b) == doctest::Approx(2));
    CHECK(chord_through_box({{0, 0}, {4, 2}}, b) == doctest::Approx(std::sqrt(5.0)));
    CHECK(chord_through_box({{0, 0.999}, {2, 0.999}}, b) == doctest::Approx(2));
    // Ending inside: the part inside; wholly inside: all of it.
    CHECK(chord_through_box({{-1, 0.5}, {1, 0.5}}, b) == doctest::Approx(1));
    CHECK(chord_through_box({{0.5, 0.5}, {1.5, 0.5}}, b) == doctest::Approx(1));
    // Along an edge, or a part of it; touching a corner; outside: 0.
    CHECK(chord_through_box({{-1, 1}, {3, 1}}, b) == 0);
    CHECK(chord_through_box({{0.5, 0}, {1.5, 0}}, b) == 0);
    CHECK(chord_through_box({{-1, 1}, {0, 2}}, b) == 0);
    CHECK(chord_through_box({{-1, 2}, {3, 2}}, b) == 0);
    // A segment that is a point.
    CHECK(chord_through_box({{1, 0.5}, {1, 0.5}}, b) == 0);
    // A box of no area (collinear members): nothing runs through it.
    const Box flat = box({0, 0}, {2, 0});
    CHECK(chord_through_box({{1, -1}, {1, 1}}, flat) == 0);
    CHECK(chord_through_box({{-1, 0}, {3, 0}}, flat) == 0);
    CHECK(chord_through_box({{-1, 0.5}, {3, 0.5}}, Box{}) == 0);
    // Far from the origin, the same answers (the tolerance follows the
    // coordinates' magnitude): across, and along an edge.
    const Box far = box({1e6, 1e6}, {1e6 + 2, 1e6 + 1});
    CHECK(chord_through_box({{1e6 - 1, 1e6 + 0.5}, {1e6 + 3, 1e6 + 0.5}}, far) == doctest::Approx(2));
    CHECK(chord_through_box({{1e6 - 1, 1e6 + 1}, {1e6 + 3, 1e6 + 1}}, far) == 0);
}

TEST_CASE("box_intruded_by_blocker: finds a long blocker through a box, leaving out skipped places and non-blockers") {
    // Three short sticks (the box's own) and a bar 3 long across their box,
    // plus sticks elsewhere so that the hierarchy has levels to walk.
    std::vector<Segment> segs = {
        {{0, 0}, {0, 1}}, {{1, 0}, {1, 1}}, {{0.5, 0.2}, {0.5, 0.8}},  // the members
        {{-1, 0.5}, {2, 0.5}},                                          // the bar: 1 of it inside their box
        {{5, 5}, {6, 6}}, {{7, 5}, {7, 6}}, {{5, 8}, {6, 8}}, {{8, 8}, {9, 9}},
    };
    const Hierarchy h(segs, 1);
    Box members;
    for (int k = 0; k < 3; ++k) members.add(segs[static_cast<size_t>(k)]);
    std::vector<int32_t> stack;
    int32_t bar = -1;
    for (size_t q = 0; q < h.order().size(); ++q)
        if (h.order()[q] == 3) bar = static_cast<int32_t>(q);
    REQUIRE(bar >= 0);
    CHECK(box_intruded_by_blocker(h, members, 0, 0, 0, 0, stack));
    // The limits: the bar is 3 long, and 1 of it runs through the box.
    CHECK(box_intruded_by_blocker(h, members, 0, 0, 3.0, 1.0, stack));
    CHECK_FALSE(box_intruded_by_blocker(h, members, 0, 0, 3.01, 0, stack));
    CHECK_FALSE(box_intruded_by_blocker(h, members, 0, 0, 0, 1.01, stack));
    // The bar's place skipped: nothing else runs through the box (the
    // members lie on its edges, and the middle one is short but inside:
    // its own place is not skipped, so it counts; with a length limit above
    // its 0.6 it does not).
    CHECK(box_intruded_by_blocker(h, members, bar, 1, 0, 0, stack));
    CHECK_FALSE(box_intruded_by_blocker(h, members, bar, 1, 0.7, 0, stack));
    // The bar cannot block (a wall on the scene's hull): not an intruder.
    Hierarchy open = h;
    std::vector<char> can_block(segs.size(), 1);
    can_block[3] = 0;
    open.set_blockers(can_block);
    CHECK_FALSE(box_intruded_by_blocker(open, members, 0, 0, 0.7, 0, stack));
    // Away from the bar: a box that a stick runs along one edge of is not
    // intruded; one that a stick crosses corner to edge is.
    CHECK_FALSE(box_intruded_by_blocker(h, box({7, 5}, {8, 6}), 0, 0, 0, 0, stack));
    CHECK(box_intruded_by_blocker(h, box({5, 5}, {7, 6}), 0, 0, 0, 0, stack));
}
