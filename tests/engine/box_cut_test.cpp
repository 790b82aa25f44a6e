// engine/box_cut.h: whether a segment cuts a box in two, against an oracle
// on random segments (a segment whose ends both lie outside the box's
// interior and that meets the box runs through it, for ends in general
// position), by hand where ends touch edges and corners, and over a
// hierarchy with skipped places and segments that cannot block.
#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "engine/box_cut.h"
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

}  // namespace

TEST_CASE("segment_cuts_box: agrees with the oracle on random segments") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(-2, 2);
    const Box b = box({-0.5, -0.25}, {0.75, 0.5});
    int cuts = 0, not_cuts = 0;
    for (int n = 0; n < 20000; ++n) {
        const Segment s{{U(rng), U(rng)}, {U(rng), U(rng)}};
        const bool oracle = !strictly_inside(s.a, b) && !strictly_inside(s.b, b) && segment_meets_box(s.a, s.b, b);
        CAPTURE(s.a.x); CAPTURE(s.a.y); CAPTURE(s.b.x); CAPTURE(s.b.y);
        REQUIRE(segment_cuts_box(s, b) == oracle);
        (oracle ? cuts : not_cuts)++;
    }
    // Both answers are exercised (about a tenth of the segments cut).
    CHECK(cuts > 500);
    CHECK(not_cuts > 500);
}

TEST_CASE("segment_cuts_box: ends on edges and corners, along edges, and boxes of no area") {
    const Box b = box({0, 0}, {2, 1});
    // Across, from edge to edge: cuts; reversed too.
    CHECK(segment_cuts_box({{-1, 0.5}, {3, 0.5}}, b));
    CHECK(segment_cuts_box({{3, 0.5}, {-1, 0.5}}, b));
    // Starting exactly on an edge, or at a corner, and leaving through the
    // other side (a shelf's top from the corner of its end face).
    CHECK(segment_cuts_box({{0, 0.5}, {3, 0.5}}, b));
    CHECK(segment_cuts_box({{0, 0}, {3, 1.5}}, b));
    CHECK(segment_cuts_box({{0, 0.999}, {2, 0.999}}, b));
    // Ending inside: does not cut; nor does a segment wholly inside.
    CHECK_FALSE(segment_cuts_box({{-1, 0.5}, {1, 0.5}}, b));
    CHECK_FALSE(segment_cuts_box({{0.5, 0.5}, {1.5, 0.5}}, b));
    // Along an edge, or along a part of it; touching a corner; outside.
    CHECK_FALSE(segment_cuts_box({{-1, 1}, {3, 1}}, b));
    CHECK_FALSE(segment_cuts_box({{0.5, 0}, {1.5, 0}}, b));
    CHECK_FALSE(segment_cuts_box({{-1, 1}, {0, 2}}, b));
    CHECK_FALSE(segment_cuts_box({{-1, 1}, {1, 3}}, b));
    CHECK_FALSE(segment_cuts_box({{-1, 2}, {3, 2}}, b));
    // A segment that is a point.
    CHECK_FALSE(segment_cuts_box({{1, 0.5}, {1, 0.5}}, b));
    // A box of no area (collinear members): nothing cuts it.
    const Box flat = box({0, 0}, {2, 0});
    CHECK_FALSE(segment_cuts_box({{1, -1}, {1, 1}}, flat));
    CHECK_FALSE(segment_cuts_box({{-1, 0}, {3, 0}}, flat));
    // An empty box.
    CHECK_FALSE(segment_cuts_box({{-1, 0.5}, {3, 0.5}}, Box{}));
    // Far from the origin, the same answers (the tolerance follows the
    // coordinates' magnitude): across, and along an edge.
    const Box far = box({1e6, 1e6}, {1e6 + 2, 1e6 + 1});
    CHECK(segment_cuts_box({{1e6 - 1, 1e6 + 0.5}, {1e6 + 3, 1e6 + 0.5}}, far));
    CHECK_FALSE(segment_cuts_box({{1e6 - 1, 1e6 + 1}, {1e6 + 3, 1e6 + 1}}, far));
}

TEST_CASE("box_cut_by_blocker: finds a cutting blocker, leaving out the skipped places and non-blockers") {
    // Three short sticks (the box's own) and a long bar across their box,
    // plus sticks elsewhere so that the hierarchy has levels to walk.
    std::vector<Segment> segs = {
        {{0, 0}, {0, 1}}, {{1, 0}, {1, 1}}, {{0.5, 0.2}, {0.5, 0.8}},  // the members
        {{-1, 0.5}, {2, 0.5}},                                          // the bar: cuts their box
        {{5, 5}, {6, 6}}, {{7, 5}, {7, 6}}, {{5, 8}, {6, 8}}, {{8, 8}, {9, 9}},
    };
    const Hierarchy h(segs, 1);
    Box members;
    for (int k = 0; k < 3; ++k) members.add(segs[static_cast<size_t>(k)]);
    std::vector<int32_t> stack;
    // Where the bar sits in the hierarchy's order.
    int32_t bar = -1;
    for (size_t q = 0; q < h.order().size(); ++q)
        if (h.order()[q] == 3) bar = static_cast<int32_t>(q);
    REQUIRE(bar >= 0);
    CHECK(box_cut_by_blocker(h, members, 0, 0, stack));
    // Only blockers at least min_length long count: the bar is 3 long.
    CHECK(box_cut_by_blocker(h, members, 0, 0, stack, 3.0));
    CHECK_FALSE(box_cut_by_blocker(h, members, 0, 0, stack, 3.01));
    // The bar's place skipped: nothing else cuts the box (the members lie
    // on its edges or inside it).
    CHECK_FALSE(box_cut_by_blocker(h, members, bar, 1, stack));
    // The bar cannot block (a wall on the scene's hull): not a cut.
    Hierarchy open = h;
    std::vector<char> can_block(segs.size(), 1);
    can_block[3] = 0;
    open.set_blockers(can_block);
    CHECK_FALSE(box_cut_by_blocker(open, members, 0, 0, stack));
    // Away from the bar: a box that a stick runs along one edge of is not
    // cut; one that a stick crosses corner to edge is.
    CHECK_FALSE(box_cut_by_blocker(h, box({7, 5}, {8, 6}), 0, 0, stack));
    CHECK(box_cut_by_blocker(h, box({5, 5}, {7, 6}), 0, 0, stack));
}
