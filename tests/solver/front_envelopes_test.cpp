// Occlusion inside every cluster by merged front envelopes
// (solver/front_envelopes.h): against visible_fraction's exact path on small
// sets, an exact interval oracle on larger ones (with segments that cannot
// block), a closed form for crossing segments, and extreme coordinates.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "engine/hierarchy.h"
#include "solver/front_envelopes.h"
#include "solver/self_occlusion.h"
#include "support/seen_oracle.h"

using namespace flatrad;

namespace {

constexpr int K = directional_bins;

// Shares and mean depths are sums of up to a few hundred widths, in
// another order than the oracle's: they agree to rounding, far inside this.
constexpr double rounding_tolerance = 1e-9;

using test::meet;

// n random sticks in the unit square, none meeting another.
std::vector<Segment> sticks(size_t n, double length, std::mt19937& rng) {
    std::uniform_real_distribution<double> pos(0.0, 1.0), ang(0.0, 6.283185307179586);
    std::vector<Segment> out;
    while (out.size() < n) {
        const Vec2 c{pos(rng), pos(rng)};
        const double a = ang(rng);
        const Vec2 d{0.5 * length * std::cos(a), 0.5 * length * std::sin(a)};
        const Segment s{c - d, c + d};
        if (std::none_of(out.begin(), out.end(), [&](const Segment& t) { return meet(s, t); })) out.push_back(s);
    }
    return out;
}

// Every internal node of a hierarchy over `segs`, its two children the groups.
struct Setup {
    Hierarchy h;
    EnvelopeClusters clusters;
    std::vector<uint8_t> sides_at;
};

Setup every_cluster(const std::vector<Segment>& segs, const std::vector<uint8_t>& sides, int leaf_size) {
    Setup s{Hierarchy(segs, leaf_size), {}, {}};
    for (size_t q = 0; q < s.h.order().size(); ++q) s.sides_at.push_back(sides[static_cast<size_t>(s.h.order()[q])]);
    s.clusters.group_begin.push_back(0);
    for (size_t k = 0; k < s.h.nodes().size(); ++k) {
        const ClusterNode& n = s.h.node(static_cast<int>(k));
        if (n.leaf()) continue;
        s.clusters.node.push_back(static_cast<int32_t>(k));
        // Children in the other order than the places': groups need not be sorted.
        s.clusters.group_node.push_back(n.child[1]);
        s.clusters.group_node.push_back(n.child[0]);
        s.clusters.group_begin.push_back(static_cast<int32_t>(s.clusters.group_node.size()));
    }
    return s;
}

// The members of hierarchy node k (as segment numbers).
std::vector<int32_t> members(const Hierarchy& h, int k) {
    const ClusterNode& n = h.node(k);
    return {h.order().begin() + n.first, h.order().begin() + n.first + n.count};
}

// Checks every cluster's shares and front against the oracle.
void check_against_oracle(const std::vector<Segment>& segs, const std::vector<uint8_t>& sides, const Setup& s,
                          const EnvelopeShares& got) {
    const auto& dirs = bin_directions();
    for (size_t c = 0; c < s.clusters.node.size(); ++c) {
        const std::vector<int32_t> mine = members(s.h, s.clusters.node[c]);
        std::vector<Segment> set;
        std::vector<uint8_t> set_sides;
        for (int32_t m : mine) {
            set.push_back(segs[static_cast<size_t>(m)]);
            set_sides.push_back(sides[static_cast<size_t>(m)]);
        }
        for (int k = 0; k < K; ++k) {
            const std::vector<test::SeenSegment> o = test::seen_segments(set, set_sides, dirs[static_cast<size_t>(k)]);
            double seen = 0, all = 0, depth = 0;
            for (const test::SeenSegment& x : o) {
                seen += x.seen;
                all += x.facing_width;
                depth += x.depth_integral;
            }
            CAPTURE(c);
            CAPTURE(k);
            const double whole = got.whole(c, k);
            CHECK(whole == doctest::Approx(all > 0 ? seen / all : 1.0).epsilon(rounding_tolerance));
            if (seen > 0)
                CHECK(got.front(c, k) == doctest::Approx(depth / seen).epsilon(rounding_tolerance));
            else
                CHECK(std::isnan(got.front(c, k)));
            // Each group: its members' seen widths over their facing widths.
            for (int32_t g = s.clusters.group_begin[c]; g < s.clusters.group_begin[c + 1]; ++g) {
                const ClusterNode& gn = s.h.node(s.clusters.group_node[static_cast<size_t>(g)]);
                const ClusterNode& cn = s.h.node(s.clusters.node[c]);
                double gs = 0, ga = 0;
                for (int32_t q = gn.first; q < gn.first + gn.count; ++q) {
                    gs += o[static_cast<size_t>(q - cn.first)].seen;
                    ga += o[static_cast<size_t>(q - cn.first)].facing_width;
                }
                CHECK(got.group(static_cast<size_t>(g), k) ==
                      doctest::Approx(ga > 0 ? gs / ga : 1.0).epsilon(rounding_tolerance));
            }
        }
    }
}

}  // namespace

TEST_CASE("front envelopes: every cluster of random sticks as visible_fraction's exact path gives") {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 6; ++trial) {
        const std::vector<Segment> segs = sticks(20, 0.15, rng);
        std::vector<uint8_t> sides;
        std::uniform_int_distribution<int> pick(1, 3);
        for (size_t i = 0; i < segs.size(); ++i) sides.push_back(static_cast<uint8_t>(pick(rng)) | blocks);
        const Setup s = every_cluster(segs, sides, 2);
        const EnvelopeShares got = cluster_visible_fractions(s.h, s.sides_at, s.clusters, 2);
        for (size_t c = 0; c < s.clusters.node.size(); ++c) {
            const ClusterNode& n = s.h.node(s.clusters.node[c]);
            std::vector<Segment> set;
            std::vector<uint8_t> set_sides;
            std::vector<int32_t> group;
            for (int32_t q = n.first; q < n.first + n.count; ++q) {
                set.push_back(segs[static_cast<size_t>(s.h.order()[static_cast<size_t>(q)])]);
                set_sides.push_back(s.sides_at[static_cast<size_t>(q)]);
                // group 0 is child[1] (every_cluster's order), 1 is child[0]
                group.push_back(q < s.h.node(n.child[0]).first + s.h.node(n.child[0]).count ? 1 : 0);
            }
            REQUIRE(set.size() <= exact_up_to);
            double out[K], group_out[2 * K];
            visible_fraction(set.data(), set_sides.data(), set.size(), out, group.data(), 2, group_out);
            const size_t g0 = static_cast<size_t>(s.clusters.group_begin[c]);
            for (int k = 0; k < K; ++k) {
                CAPTURE(k);
                CHECK(got.whole(c, k) == doctest::Approx(out[k]).epsilon(rounding_tolerance));
                for (size_t g = 0; g < 2; ++g)
                    CHECK(got.group(g0 + g, k) ==
                          doctest::Approx(group_out[g * K + static_cast<size_t>(k)]).epsilon(rounding_tolerance));
            }
        }
    }
}

TEST_CASE("front envelopes: hundreds of sticks, some that cannot block, against the exact oracle") {
    std::mt19937 rng(11);
    const std::vector<Segment> segs = sticks(300, 0.06, rng);
    std::vector<uint8_t> sides;
    std::uniform_int_distribution<int> pick(0, 9);
    for (size_t i = 0; i < segs.size(); ++i) {
        const int r = pick(rng);
        // One in ten cannot block; sides: both, left only, right only.
        sides.push_back(static_cast<uint8_t>((r % 3 == 0 ? left_side | right_side : r % 3 == 1 ? left_side : right_side) |
                                             (r == 9 ? 0 : blocks)));
    }
    const Setup s = every_cluster(segs, sides, 3);
    const EnvelopeShares got = cluster_visible_fractions(s.h, s.sides_at, s.clusters, 2);
    // The root holds all 300, in layers: some members are hidden.
    double least = 1;
    for (int k = 0; k < K; ++k) least = std::min(least, got.whole(0, k));
    CHECK(least < 0.9);
    check_against_oracle(segs, sides, s, got);
}

TEST_CASE("front envelopes: crossing segments split where they cross (closed form)") {
    // An X: the diagonals of the square [-1, 1]^2, both two-sided blockers.
    // Seen from far along +y, the one rising to the left is in front for x
    // < 0 and the other for x > 0: half of each, at mean depth (y) 1/2.
    const std::vector<Segment> segs{{{-1, -1}, {1, 1}}, {{-1, 1}, {1, -1}}};
    const std::vector<uint8_t> sides{left_side | right_side | blocks, left_side | right_side | blocks};
    Setup s{Hierarchy(segs, 1), {}, {}};
    for (int32_t q : s.h.order()) s.sides_at.push_back(sides[static_cast<size_t>(q)]);
    // (Their middles coincide: the hierarchy keeps them in one leaf, the
    // cluster's one group.)
    s.clusters = {{s.h.root()}, {0, 1}, {s.h.root()}};
    const EnvelopeShares got = cluster_visible_fractions(s.h, s.sides_at, s.clusters);
    const auto& dirs = bin_directions();
    int up = 0;
    for (int k = 0; k < K; ++k)
        if (dot(dirs[static_cast<size_t>(k)], Vec2{0, 1}) > dot(dirs[static_cast<size_t>(up)], Vec2{0, 1})) up = k;
    REQUIRE(dirs[static_cast<size_t>(up)].y == doctest::Approx(1.0));
    CHECK(got.whole(0, up) == doctest::Approx(0.5));
    CHECK(got.group(0, up) == doctest::Approx(0.5));
    CHECK(got.front(0, up) == doctest::Approx(0.5));
    // Every bin: the diagonals' widths across u are proportional to |u.x -
    // u.y| and |u.x + u.y|; they cross at both middles, so the narrower
    // one is in front over half of its width and the wider one is seen
    // everywhere else: the share is the wider width over the sum.
    for (int k = 0; k < K; ++k) {
        const Vec2 u = dirs[static_cast<size_t>(k)];
        const double w1 = std::abs(u.x - u.y), w2 = std::abs(u.x + u.y);
        CAPTURE(k);
        CHECK(got.whole(0, k) == doctest::Approx(std::max(w1, w2) / (w1 + w2)));
    }
}

TEST_CASE("front envelopes: coordinates near the largest double leave bins unmeasured, never NaN shares") {
    const double big = 1e308;
    const std::vector<Segment> segs{{{-big, 0}, {big, 0}}, {{-big, 1}, {big, 1}}, {{0, 2}, {1, 2}}};
    const std::vector<uint8_t> sides(3, left_side | right_side | blocks);
    const Setup s = every_cluster(segs, sides, 1);
    const EnvelopeShares got = cluster_visible_fractions(s.h, s.sides_at, s.clusters);
    for (double v : got.whole_by_bin) {
        CHECK(v >= 0.0);
        CHECK(v <= 1.0);
    }
    for (double v : got.group_by_bin) {
        CHECK(v >= 0.0);
        CHECK(v <= 1.0);
    }
}
