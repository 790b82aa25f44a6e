// The cluster hierarchy (engine/hierarchy.h): structure and queries against
// a linear scan.
#include "engine/hierarchy.h"

#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

using namespace flatrad;

namespace {
std::vector<Segment> random_segments(std::mt19937_64& rng, int n) {
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Segment> s;
    for (int k = 0; k < n; ++k) {
        const Vec2 c{U(rng), U(rng)};
        const Vec2 d{0.02 * (U(rng) - 0.5), 0.02 * (U(rng) - 0.5)};
        s.push_back({c - d, c + d});
    }
    return s;
}
bool overlap(const Box& a, const Box& b) {
    return !(a.hi.x < b.lo.x || a.lo.x > b.hi.x || a.hi.y < b.lo.y || a.lo.y > b.hi.y);
}
Box random_box(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> U(0, 1);
    Box b;
    b.add(Vec2{U(rng), U(rng)});
    b.add(Vec2{U(rng), U(rng)});
    return b;
}
bool box_meets(const Segment& g, const Box& query) {
    Box gb;
    gb.add(g);
    return overlap(gb, query);
}
// The segments whose boxes meet `query` (only those with keep[s], if given).
std::set<int> linear_scan(const std::vector<Segment>& segs, const Box& query, const std::vector<char>* keep = nullptr) {
    std::set<int> out;
    for (size_t s = 0; s < segs.size(); ++s)
        if ((!keep || (*keep)[s]) && box_meets(segs[s], query)) out.insert(static_cast<int>(s));
    return out;
}
}  // namespace

TEST_CASE("hierarchy: every segment in one leaf, boxes nest, depth is logarithmic") {
    std::mt19937_64 rng(5);
    for (int n : {1, 2, 3, 17, 1000, 4096}) {
        const auto segs = random_segments(rng, n);
        for (int leaf : {1, 2, 4}) {
            const Hierarchy h(segs, leaf);
            std::vector<int> seen(static_cast<size_t>(n), 0);
            for (const ClusterNode& nd : h.nodes()) {
                if (nd.leaf()) {
                    CHECK(nd.count <= std::max(leaf, 1));
                    for (int k = nd.first; k < nd.first + nd.count; ++k) {
                        const int s = h.order()[static_cast<size_t>(k)];
                        ++seen[static_cast<size_t>(s)];
                        const Segment& g = segs[static_cast<size_t>(s)];
                        CHECK(nd.box.lo.x <= std::min(g.a.x, g.b.x));
                        CHECK(nd.box.hi.y >= std::max(g.a.y, g.b.y));
                    }
                } else {
                    for (int c : nd.child) {
                        const Box& cb = h.node(c).box;
                        CHECK(nd.box.lo.x <= cb.lo.x);
                        CHECK(nd.box.lo.y <= cb.lo.y);
                        CHECK(nd.box.hi.x >= cb.hi.x);
                        CHECK(nd.box.hi.y >= cb.hi.y);
                        CHECK(h.node(c).parent >= 0);
                    }
                }
            }
            for (int c : seen) CHECK(c == 1);
            // Heuristic splits down to 2 ceil(log2(n + 1)) + 4, median splits
            // below: depth <= that + ceil(log2(n / leaf)) + 1 levels.
            const int bound = 2 * static_cast<int>(std::ceil(std::log2(double(n) + 1))) + 4 +
                              static_cast<int>(std::ceil(std::log2(std::max(1.0, double(n) / leaf)))) + 1;
            CAPTURE(n);
            CAPTURE(leaf);
            CHECK(h.depth() <= bound);
        }
    }
}

TEST_CASE("hierarchy: box queries find exactly what a linear scan finds") {
    std::mt19937_64 rng(6);
    const auto segs = random_segments(rng, 3000);
    const Hierarchy h(segs, 2);
    std::vector<int32_t> stack;
    for (int q = 0; q < 50; ++q) {
        const Box query = random_box(rng);
        std::set<int> found;
        const long visited = h.query([&](const Box& b) { return overlap(b, query); },
                                     [&](int s, const Segment& g) {
                                         if (box_meets(g, query)) found.insert(s);
                                     },
                                     stack);
        CHECK(found == linear_scan(segs, query));
        CHECK(visited >= 1);
    }
}

TEST_CASE("hierarchy: a compact cloud between two far walls becomes one node") {
    // Two long walls far apart and a dense cloud between them: the heuristic
    // peels the walls off, so some node holds exactly the cloud.
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Segment> segs{{{-5, 0}, {5, 0}}, {{5, 10}, {-5, 10}}};
    for (int k = 0; k < 300; ++k) {
        const Vec2 c{U(rng) - 0.5, 5 + U(rng) - 0.5};
        segs.push_back({c, c + Vec2{0.01, 0.005}});
    }
    const Hierarchy h(segs, 2);
    bool found = false;
    for (const ClusterNode& nd : h.nodes()) {
        if (nd.count != 300) continue;
        bool only_cloud = true;
        for (int k = nd.first; k < nd.first + nd.count; ++k)
            if (h.order()[static_cast<size_t>(k)] < 2) only_cloud = false;
        found = found || only_cloud;
    }
    CHECK(found);
}

TEST_CASE("hierarchy: coincident segments do not split forever") {
    std::vector<Segment> same(100, Segment{{0, 0}, {1, 1}});
    const Hierarchy h(same, 2);
    CHECK(h.nodes().size() == 1);
    CHECK(h.node(0).count == 100);
}

TEST_CASE("hierarchy: set_blockers counts per node (and per place in order), and query_blockers walks only them") {
    std::mt19937_64 rng(8);
    const auto segs = random_segments(rng, 2000);
    Hierarchy h(segs, 1);
    for (const ClusterNode& nd : h.nodes()) CHECK(nd.blockers == nd.count);  // all block by default
    std::vector<char> can(segs.size(), 0);
    std::uniform_real_distribution<double> U(0, 1);
    for (auto& c : can) c = U(rng) < 0.1 ? 1 : 0;
    // By place in order(): every segment blocks until set_blockers says
    // otherwise, and each place holds its segment.
    long mismatched = 0;
    for (size_t q = 0; q < segs.size(); ++q) {
        const Segment& g = segs[static_cast<size_t>(h.order()[q])];
        mismatched += !(h.segment_at(static_cast<int32_t>(q)).a == g.a && h.segment_at(static_cast<int32_t>(q)).b == g.b);
        mismatched += !h.can_block_at(static_cast<int32_t>(q));
    }
    CHECK(mismatched == 0);
    h.set_blockers(can);
    for (size_t q = 0; q < segs.size(); ++q)
        mismatched += h.can_block_at(static_cast<int32_t>(q)) != (can[static_cast<size_t>(h.order()[q])] != 0);
    CHECK(mismatched == 0);
    for (const ClusterNode& nd : h.nodes()) {
        int expected = 0;
        for (int k = nd.first; k < nd.first + nd.count; ++k) expected += can[static_cast<size_t>(h.order()[static_cast<size_t>(k)])];
        CHECK(nd.blockers == expected);
    }
    std::vector<int32_t> stack;
    for (int q = 0; q < 30; ++q) {
        const Box query = random_box(rng);
        std::set<int> found;
        const long visited = h.query_blockers([&](const Box& b) { return overlap(b, query); },
                                              [&](int s, const Segment& g) {
                                                  if (box_meets(g, query)) found.insert(s);
                                              },
                                              stack);
        CHECK(found == linear_scan(segs, query, &can));
        const long all = h.query([&](const Box& b) { return overlap(b, query); }, [](int, const Segment&) {}, stack);
        CHECK(visited <= all);
    }
    CHECK_THROWS(h.set_blockers(std::vector<char>(3, 1)));
}

TEST_CASE("hierarchy: segments flagged alone get leaves of their own, the others share up to the leaf size") {
    std::mt19937_64 rng(11);
    for (int n : {2, 9, 1000}) {
        const auto segs = random_segments(rng, n);
        std::vector<char> alone(static_cast<size_t>(n), 0);
        for (int s = 0; s < n; s += 7) alone[static_cast<size_t>(s)] = 1;  // every seventh
        const Hierarchy h(segs, 8, alone);
        std::vector<int> seen(static_cast<size_t>(n), 0);
        long shared = 0;  // leaves holding more than one segment
        for (const ClusterNode& nd : h.nodes()) {
            if (!nd.leaf()) continue;
            CHECK(nd.count <= 8);
            shared += nd.count > 1;
            for (int k = nd.first; k < nd.first + nd.count; ++k) {
                const int s = h.order()[static_cast<size_t>(k)];
                ++seen[static_cast<size_t>(s)];
                CAPTURE(s);
                if (alone[static_cast<size_t>(s)]) CHECK(nd.count == 1);
            }
        }
        for (int c : seen) CHECK(c == 1);
        CAPTURE(n);
        if (n >= 9) CHECK(shared > 0);  // the flags did not force single leaves everywhere
    }
    CHECK_THROWS_AS(Hierarchy(random_segments(rng, 3), 8, std::vector<char>(2, 0)), std::invalid_argument);
}
