// Normal cones (engine/normal_cone.h) against brute force: the smallest arc
// holding a set of directions, and the facing tests between two convex
// regions checked on dense samples of the regions and the arc.
#include "engine/normal_cone.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

using namespace flatrad;

namespace {

// 2 pi minus the largest gap between consecutive sorted angles.
double smallest_arc(std::vector<double> a) {
    std::sort(a.begin(), a.end());
    double gap = a.front() + 2 * std::numbers::pi - a.back();
    for (size_t k = 1; k < a.size(); ++k) gap = std::max(gap, a[k] - a[k - 1]);
    return 2 * std::numbers::pi - gap;
}

Vec2 dir(double a) { return {std::cos(a), std::sin(a)}; }

}  // namespace

TEST_CASE("normal cone: merging holds every member, in the smallest arc when that is under pi") {
    // atan2 and fmod round to a few ulps of 2 pi.
    constexpr double angle_tol = 1e-12;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(0, 1);
    for (int trial = 0; trial < 500; ++trial) {
        // Members clustered around a random middle, spreads up to the whole circle.
        const double mid = 2 * std::numbers::pi * U(rng), spread = 7.0 * U(rng) * U(rng);
        const int n = 1 + static_cast<int>(U(rng) * 12);
        std::vector<double> angles;
        NormalCone c;
        CHECK(c.empty());
        for (int k = 0; k < n; ++k) {
            const double a = mid + spread * (U(rng) - 0.5);
            angles.push_back(NormalCone::angle_of(dir(a)));
            // Merge in a random tree shape: sometimes a pair first.
            c = NormalCone::merge(c, NormalCone::of(dir(a)));
        }
        CAPTURE(trial);
        // Members within a half circle have one angular hull, and merging
        // hulls gives the hull: the smallest arc. Wider spreads may get a
        // larger arc from merging one at a time (still holding every
        // member, checked below); the solver only uses arcs under pi.
        const double best = smallest_arc(angles);
        if (best < std::numbers::pi - angle_tol)
            CHECK(c.width == doctest::Approx(best).epsilon(0).scale(1).epsilon(angle_tol));
        else
            CHECK(c.width >= best - angle_tol);
        for (double a : angles) {
            double off = std::fmod(a - c.lo + 4 * std::numbers::pi, 2 * std::numbers::pi);
            if (off > 2 * std::numbers::pi - angle_tol) off = 0;  // the arc's start itself
            CHECK(off <= c.width + angle_tol);
        }
    }
    // Merging is symmetric in its result's width.
    const NormalCone a{6.2, 0.1}, b{0.05, 0.02};
    CHECK(NormalCone::merge(a, b).width == doctest::Approx(NormalCone::merge(b, a).width));
    CHECK(NormalCone::merge(a, b).width == doctest::Approx(0.05 + 0.02 + 2 * std::numbers::pi - 6.2));
}

TEST_CASE("normal cone: faces_all and faces_none agree with dense sampling") {
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> U(0, 1);
    int all_seen = 0, none_seen = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const double mid = 2 * std::numbers::pi * U(rng), width = 2.0 * U(rng) * U(rng);
        const NormalCone c = NormalCone::merge(NormalCone::of(dir(mid)), NormalCone::of(dir(mid + width)));
        auto quad = [&](Vec2 at, double size) {
            std::array<Vec2, 4> q{};
            const double t = 2 * std::numbers::pi * U(rng);
            const Vec2 a = dir(t) * size, b = rot90(dir(t)) * (size * U(rng));
            q = {at - a - b, at + a - b, at + a + b, at - a + b};
            return q;
        };
        const auto from = quad({0, 0}, 0.3 * U(rng));
        const double d = 0.5 + 2 * U(rng), where = 2 * std::numbers::pi * U(rng);
        const auto to = quad(dir(where) * d, 0.3 * U(rng));
        // Samples: 9 normals across the arc, 25 points in each region.
        bool every = true, no = true;
        for (int i = 0; i <= 8; ++i) {
            const Vec2 n = dir(c.lo + c.width * i / 8.0);
            for (int p = 0; p < 25; ++p)
                for (int q = 0; q < 25; ++q) {
                    auto at = [](const std::array<Vec2, 4>& r, int k) {
                        const double s = (k % 5) / 4.0, t = (k / 5) / 4.0;
                        return lerp(lerp(r[0], r[1], s), lerp(r[3], r[2], s), t);
                    };
                    const double o = dot(n, at(to, q) - at(from, p));
                    every = every && o >= 0;
                    no = no && o <= 0;
                }
        }
        CAPTURE(trial);
        // The tests are exact (corners and arc ends suffice), so they match
        // the samples whenever they say yes, and a sampled "yes" is a yes
        // unless a sample missed the one failing corner (never: corners are
        // sampled).
        CHECK(c.faces_all(from, to) == every);
        CHECK(c.faces_none(from, to) == no);
        // The combined query gives the same three answers.
        const Vec2 u = dir(where);
        const double spread = U(rng);
        const NormalCone::Facing f = c.facing(from, to, u, spread);
        CHECK(f.all == every);
        CHECK(f.none == no);
        CHECK(f.departure == c.linear_departure(u, spread));
        all_seen += every ? 1 : 0;
        none_seen += no ? 1 : 0;
    }
    // Both answers occur, so neither check is vacuous.
    CHECK(all_seen > 20);
    CHECK(none_seen > 20);
    // An empty cone faces nothing; a cone wider than pi is never "all".
    const std::array<Vec2, 4> p{Vec2{0, 0}, Vec2{0, 0}, Vec2{0, 0}, Vec2{0, 0}}, q{Vec2{1, 0}, Vec2{1, 0}, Vec2{1, 0}, Vec2{1, 0}};
    CHECK(NormalCone{}.faces_none(p, q));
    CHECK_FALSE(NormalCone{}.faces_all(p, q));
    CHECK_FALSE((NormalCone{0.0, 3.5}.faces_all(p, q)));
}
