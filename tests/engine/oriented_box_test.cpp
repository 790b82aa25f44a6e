// Oriented boxes per hierarchy node (engine/oriented_box.h): they hold
// their segments, and along a curved wall they are as thin as its sagitta.
#include "engine/oriented_box.h"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

using namespace flatrad;

namespace {

// Is p inside b, up to `tol` outside any side?
bool holds(const OrientedBox& b, Vec2 p, double tol) {
    const double u = dot(p, b.axis), v = dot(p, rot90(b.axis));
    return u >= b.lo_u - tol && u <= b.hi_u + tol && v >= b.lo_v - tol && v <= b.hi_v + tol;
}

std::vector<Segment> round_wall(int n) {
    std::vector<Segment> s;
    for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * k / n, b = 2 * std::numbers::pi * (k + 1) / n;
        s.push_back({{std::cos(a), std::sin(a)}, {std::cos(b), std::sin(b)}});
    }
    return s;
}

}  // namespace

TEST_CASE("oriented boxes hold every segment of their node") {
    // Projections of coordinates ~1 round to ~1e-16; the parent's box is
    // built from its children's corners, so a few roundings stack up.
    constexpr double hold_tol = 1e-12;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Segment> segs = round_wall(300);
    for (int k = 0; k < 300; ++k) {
        const Vec2 c{U(rng) - 0.5, U(rng) - 0.5};
        const Vec2 d{0.05 * (U(rng) - 0.5), 0.05 * (U(rng) - 0.5)};
        segs.push_back({c - d, c + d});
    }
    const Hierarchy h(segs, 1);
    const std::vector<OrientedBox> boxes = oriented_boxes(h);
    REQUIRE(boxes.size() == h.nodes().size());
    long checked = 0;
    for (size_t k = 0; k < boxes.size(); ++k) {
        const ClusterNode& n = h.nodes()[k];
        CHECK(std::abs(norm(boxes[k].axis) - 1) <= 1e-15);
        for (int32_t i = n.first; i < n.first + n.count; ++i) {
            const Segment& s = segs[static_cast<size_t>(h.order()[static_cast<size_t>(i)])];
            CHECK(holds(boxes[k], s.a, hold_tol));
            CHECK(holds(boxes[k], s.b, hold_tol));
            checked += 2;
        }
        // range_along is the corners' range.
        const auto [lo, hi] = boxes[k].range_along({0.1, 0.2}, {0.6, 0.8});
        for (Vec2 c : boxes[k].corners()) {
            CHECK(dot(c - Vec2{0.1, 0.2}, {0.6, 0.8}) >= lo - 1e-15);
            CHECK(dot(c - Vec2{0.1, 0.2}, {0.6, 0.8}) <= hi + 1e-15);
        }
    }
    CHECK(checked > 600 * 2);
}

TEST_CASE("oriented boxes of a round wall's arcs are as thin as their sagitta") {
    // An arc of angle t on the unit circle bows out by 1 - cos(t / 2) from
    // its chord; a box along the chord needs no more. The box of a child
    // pair is built from its children's corners, so it may add their own
    // thickness: a factor 2 covers it. The axis-aligned box of an arc at 45
    // degrees is about half its length thick: the reason for this module.
    const int n = 4096;
    const std::vector<Segment> segs = round_wall(n);
    const Hierarchy h(segs, 1);
    const std::vector<OrientedBox> boxes = oriented_boxes(h);
    int arcs = 0;
    for (size_t k = 0; k < boxes.size(); ++k) {
        const ClusterNode& nd = h.nodes()[k];
        if (nd.count < 8 || nd.count > n / 16) continue;  // arcs well under a quarter circle
        const double t = 2 * std::numbers::pi * nd.count / n;
        const double sagitta = 1 - std::cos(t / 2);
        const double thick = boxes[k].hi_v - boxes[k].lo_v, chord = 2 * std::sin(t / 2);
        CAPTURE(nd.count);
        CHECK(thick <= 2 * sagitta + 1e-12);
        CHECK(boxes[k].hi_u - boxes[k].lo_u <= chord * (1 + 1e-9) + 2 * sagitta);
        ++arcs;
    }
    CHECK(arcs > 100);
}
