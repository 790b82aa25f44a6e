// The pieces of the clustered solver's model: directional tables
// (solver/directional.h), rooms (solver/rooms.h) and sinks no patch can see
// (solver/sink_visibility.h).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/connectivity.h"
#include "engine/normal_cone.h"
#include "engine/scene.h"
#include "solver/directional.h"
#include "solver/rooms.h"
#include "solver/sink_visibility.h"

using namespace flatrad;

namespace {

// A few cosine lobes (weights 0.1 .. 1.1) with normals spread over an arc of
// up to 3 radians around a random direction, added to a table, and the
// normal cone that holds them.
struct RandomLobes {
    double table[directional_table_width] = {};
    std::vector<std::pair<Vec2, double>> lobes;
    NormalCone cone;
};

RandomLobes random_lobes(std::mt19937& rng) {
    std::uniform_real_distribution<double> U(0, 1);
    RandomLobes r;
    const double mid = 2 * std::numbers::pi * U(rng), width = 3.0 * U(rng);
    for (int k = 0; k < 1 + static_cast<int>(U(rng) * 9); ++k) {
        const double a = mid + width * (U(rng) - 0.5);
        r.lobes.push_back({{std::cos(a), std::sin(a)}, 0.1 + U(rng)});
        add_cosine_lobe(r.table, r.lobes.back().first, r.lobes.back().second);
        r.cone = NormalCone::merge(r.cone, NormalCone::of(r.lobes.back().first));
    }
    return r;
}

}  // namespace

TEST_CASE("directional tables: exact at the samples, interpolation error within its estimate") {
    // Rounding in a sum of a few cosines.
    constexpr double sample_tol = 1e-14;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    const auto& dirs = bin_directions();
    int checked = 0, under = 0;
    double worst_ratio = 0;
    for (int trial = 0; trial < 200; ++trial) {
        double table[directional_table_width] = {};
        std::vector<std::pair<Vec2, double>> lobes;
        const int n = 1 + static_cast<int>(u(rng) * 6);
        for (int k = 0; k < n; ++k) {
            const double a = 2 * std::numbers::pi * u(rng);
            lobes.push_back({{std::cos(a), std::sin(a)}, 0.1 + u(rng)});
            add_cosine_lobe(table, lobes.back().first, lobes.back().second);
        }
        auto exact = [&](Vec2 d) {
            double s = 0;
            for (const auto& [nrm, w] : lobes) s += w * std::max(0.0, dot(nrm, d));
            return s;
        };
        for (int k = 0; k < directional_bins; ++k)
            CHECK(std::abs(table[k] - exact(dirs[static_cast<size_t>(k)])) <= sample_tol);
        // Between samples: the estimate (second differences / 4) bounds the
        // error wherever the function is smooth near psi; a kink between two
        // samples shows in their second differences too.
        for (int q = 0; q < 20; ++q) {
            const double a = 2 * std::numbers::pi * u(rng);
            const Vec2 d{std::cos(a), std::sin(a)};
            const BinWeight b = bin_of(d);
            const double err = std::abs(interpolate(table, b) - exact(d));
            if (err > interpolation_error(table, b) + sample_tol) ++under;
            worst_ratio = std::max(worst_ratio, err / (interpolation_error(table, b) + sample_tol));
            ++checked;
        }
    }
    CHECK(checked == 4000);
    MESSAGE("interpolation error above its estimate at " << under << " of " << checked
                                                          << " directions; worst error / estimate " << worst_ratio);
    // An estimate, not a bound (directional.h): the oracle may under-refine
    // where it errs low. Bars: at most 1% of directions, never by more than 2x.
    CHECK(under <= checked / 100);
    CHECK(worst_ratio <= 2.0);
    // bin_of wraps at 2 pi and reads the right pair.
    const BinWeight last = bin_of({std::cos(-1e-9), std::sin(-1e-9)});
    CHECK(last.k == directional_bins - 1);
    CHECK(last.next() == 0);
    CHECK(last.t == doctest::Approx(1.0).epsilon(1e-6));
}

TEST_CASE("directional tables: the lobes without a branch are the branchy sums, bit for bit") {
    // add_cosine_lobe and read_cosine_lobe add w max(c, 0) for every bin,
    // where they once added only where c > 0: w * 0 added to a finite sum
    // leaves it as it was (a -0 may become +0, which compares equal and
    // changes no later sum). The oracle is the branchy loop; weights of
    // both signs (Krylov iterates), normals on and between the bins.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), weight(-2, 2);
    const auto& d = bin_directions();
    for (int trial = 0; trial < 400; ++trial) {
        CAPTURE(trial);
        // Every 4th normal lies on a bin's direction (c = 0 at the bins a
        // quarter turn away, up to rounding).
        const double a = trial % 4 == 0 ? 2 * std::numbers::pi * (trial % directional_bins) / directional_bins : angle(rng);
        const Vec2 n{std::cos(a), std::sin(a)};
        const double w = trial % 10 == 0 ? 0.0 : weight(rng);
        double table[directional_table_width], oracle[directional_table_width];
        for (int k = 0; k < directional_table_width; ++k) table[k] = oracle[k] = trial % 3 == 0 ? 0.0 : weight(rng);
        add_cosine_lobe(table, n, w);
        for (int k = 0; k < directional_bins; ++k) {
            const double c = n.x * d[static_cast<size_t>(k)].x + n.y * d[static_cast<size_t>(k)].y;
            if (c > 0) oracle[k] += w * c;
        }
        oracle[directional_bins] += w * n.x;
        oracle[directional_bins + 1] += w * n.y;
        for (int k = 0; k < directional_table_width; ++k) CHECK(table[k] == oracle[k]);
        double read = 0;
        for (int k = 0; k < directional_bins; ++k) {
            const double c = n.x * d[static_cast<size_t>(k)].x + n.y * d[static_cast<size_t>(k)].y;
            if (c > 0) read += oracle[k] * c;
        }
        read = read + n.x * oracle[directional_bins] + n.y * oracle[directional_bins + 1];
        CHECK(read_cosine_lobe(table, n) == read);
    }
}

TEST_CASE("directional tables: the masked read visits the lobe's bins and gives the full read, bit for bit") {
    // read_cosine_lobe with lobe_bins(n) skips the bins where max(c, 0) is
    // 0: the full read adds zeros there. The oracle is the full read, with
    // and without a per-bin scale (floats, as the solver's gammas); normals
    // on and between the bins (on a bin, the bins a quarter turn away have
    // c = 0 up to rounding, on either side of it).
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), value(-2, 2), share(0, 1);
    const auto& d = bin_directions();
    for (int trial = 0; trial < 400; ++trial) {
        CAPTURE(trial);
        const double a = trial % 4 == 0 ? 2 * std::numbers::pi * (trial % directional_bins) / directional_bins : angle(rng);
        const Vec2 n{std::cos(a), std::sin(a)};
        const uint32_t mask = lobe_bins(n);
        // The mask is where the cosine is positive: about half the bins.
        int bins = 0;
        for (int k = 0; k < directional_bins; ++k) {
            const double c = n.x * d[static_cast<size_t>(k)].x + n.y * d[static_cast<size_t>(k)].y;
            CHECK(((mask >> k) & 1u) == (c > 0 ? 1u : 0u));
            bins += c > 0;
        }
        CHECK(bins >= directional_bins / 2 - 1);
        CHECK(bins <= directional_bins / 2 + 1);
        double table[directional_table_width];
        float scale[directional_bins];
        for (int k = 0; k < directional_table_width; ++k) table[k] = trial % 3 == 0 ? 0.0 : value(rng);
        for (int k = 0; k < directional_bins; ++k) scale[k] = static_cast<float>(share(rng));
        CHECK(read_cosine_lobe(table, table + directional_bins, n, mask) == read_cosine_lobe(table, table + directional_bins, n));
        CHECK(read_cosine_lobe(table, table + directional_bins, n, scale, mask) ==
              read_cosine_lobe(table, table + directional_bins, n, scale));
        // A table kept without samples reads its linear part alone.
        CHECK(read_cosine_lobe(nullptr, table + directional_bins, n, mask) == read_cosine_lobe(nullptr, table + directional_bins, n));
    }
}

TEST_CASE("directional tables: read_cosine_lobe is the adjoint of add_cosine_lobe") {
    // sum_k J_k lobe_n(k) = <J, lobe_n>: adding a lobe of normal m with
    // weight 1 and reading it through normal n is symmetric in n and m.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 2 * std::numbers::pi);
    for (int trial = 0; trial < 50; ++trial) {
        const double a = u(rng), b = u(rng);
        const Vec2 n{std::cos(a), std::sin(a)}, m{std::cos(b), std::sin(b)};
        double tn[directional_table_width] = {}, tm[directional_table_width] = {};
        add_cosine_lobe(tn, n, 1.0);
        add_cosine_lobe(tm, m, 1.0);
        CHECK(read_cosine_lobe(tn, m) == doctest::Approx(read_cosine_lobe(tm, n)).epsilon(1e-12));
    }
}

namespace {

const char* two_boxes = R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}, "l": {"emission": 1}},
  "surfaces": [
    {"name": "left box", "material": "w", "closed": true, "side": "in", "points": [[0,0],[1,0],[1,1],[0,1]]},
    {"name": "right box", "material": "w", "closed": true, "side": "in", "points": [[3,0],[4,0],[4,1],[3,1]]},
    {"name": "lamp", "material": "l", "points": [[0.3,0.9],[0.7,0.9]], "side": "right"},
    {"name": "pillar", "material": "w", "circle": {"center": [3.5, 0.5], "radius": 0.2, "segments": 8}, "side": "out"}
  ]})";

int room_of(const Scene& s, const std::vector<int>& rooms, const std::string& surface, bool left_side) {
    const int k = s.find_surface(surface);
    const int seg = s.surfaces[static_cast<size_t>(k)].first_segment;
    return rooms[2 * static_cast<size_t>(seg) + (left_side ? 0 : 1)];
}

}  // namespace

TEST_CASE("rooms: each box's inside is its own room, the pillar's outside is its box's, outsides are outside") {
    const Scene s = parse_scene(two_boxes, "boxes.json");
    const Connectivity c = scene_connectivity(s);
    const std::vector<int> rooms = side_rooms(s, c);
    // Closed "in" polygons listed counter-clockwise: the inside is the left.
    const int left_in = room_of(s, rooms, "left box", true), right_in = room_of(s, rooms, "right box", true);
    CHECK(left_in >= 0);
    CHECK(right_in >= 0);
    CHECK(left_in != right_in);
    CHECK(room_of(s, rooms, "left box", false) == room_outside);
    CHECK(room_of(s, rooms, "lamp", true) == left_in);
    CHECK(room_of(s, rooms, "lamp", false) == left_in);
    // The pillar's outer side lives in the right box; its inner side in the pillar.
    const int pillar = s.find_surface("pillar");
    const SceneSegment& ps = s.segments[static_cast<size_t>(s.surfaces[static_cast<size_t>(pillar)].first_segment)];
    const int outer = room_of(s, rooms, "pillar", ps.lit_left), inner = room_of(s, rooms, "pillar", !ps.lit_left);
    CHECK(outer == right_in);
    CHECK(inner >= 0);
    CHECK(inner != right_in);
    CHECK((room_mask(left_in) & room_mask(right_in)) == 0);
    CHECK((room_mask(room_unknown) & room_mask(left_in)) != 0);
}

TEST_CASE("sinks: unlit sides no patch can see are found, the others kept") {
    const Scene s = parse_scene(two_boxes, "boxes.json");
    const std::vector<char> v = visible_sinks(s, scene_connectivity(s));
    auto sink_visible = [&](const std::string& surface, bool lit_side) {
        const int k = s.find_surface(surface);
        const SceneSegment& seg = s.segments[static_cast<size_t>(s.surfaces[static_cast<size_t>(k)].first_segment)];
        const bool left = lit_side ? seg.lit_left : !seg.lit_left;
        return v[2 * static_cast<size_t>(s.surfaces[static_cast<size_t>(k)].first_segment) + (left ? 0 : 1)];
    };
    CHECK(sink_visible("pillar", true) == 0);   // lit: not a sink
    CHECK(sink_visible("pillar", false) == 0);  // nothing inside the pillar
    CHECK(sink_visible("lamp", false) == 1);    // the lamp's back faces the room
    // The boxes' outer sides: the other box stands outside each, so they are kept.
    CHECK(sink_visible("left box", false) == 1);
    // One box alone: its outer sides face nothing.
    const Scene one = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}},
      "surfaces": [{"name": "box", "material": "w", "closed": true, "side": "in", "points": [[0,0],[1,0],[1,1],[0,1]]},
                   {"name": "plate", "material": "w", "points": [[0.2,0.5],[0.8,0.5]], "side": "both"}]})",
                                  "one.json");
    const std::vector<char> w = visible_sinks(one, scene_connectivity(one));
    for (char c : w) CHECK(c == 0);
    // A round room of 20000 walls and nothing else: no test to make, so
    // no budget spent (its own walls were counted, 4e8 > 1e8, and every
    // outer side was kept as a sink).
    const Scene round = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5, "emission": 1}},
      "surfaces": [{"name": "wall", "material": "w", "side": "in", "circle": {"center": [0, 0], "radius": 1, "segments": 20000}}]})",
                                    "round.json");
    const std::vector<char> r = visible_sinks(round, scene_connectivity(round));
    long kept = 0;
    for (char c : r) kept += c;
    CHECK(kept == 0);
}

TEST_CASE("sinks: a shelf against the wall inside the room hides the outer sides, one through the wall does not") {
    // The room's outer sides are sinks; a segment that touches the loop with
    // an end and otherwise lies inside it cannot see them (the loop stays
    // closed where it is touched). Before, any contact kept every outer
    // side, so a stiff room with a lamp against its wall got no row closure
    // (13.8% off at eps 1e-2 and reflectance 0.99, where a lamp 1e-3 short
    // of the wall was 0.2% off).
    const auto outer_sinks_kept = [](const std::string& shelf) {
        const Scene s = parse_scene(R"({"flatrad": 1, "materials": {"w": {"reflectance": 0.5}},
          "surfaces": [{"name": "room", "material": "w", "closed": true, "side": "in", "points": [[0,0],[4,0],[4,3],[0,3]]},
                       {"name": "shelf", "material": "w", "side": "both", "points": )" + shelf + "}]}",
                                    "shelf.json");
        const std::vector<char> v = visible_sinks(s, scene_connectivity(s));
        long kept = 0;
        for (size_t k = 0; k < 4; ++k) kept += v[2 * k] + v[2 * k + 1];  // the room's four walls
        return kept;
    };
    CHECK(outer_sinks_kept("[[3.5,1],[4,1]]") == 0);      // an end on the right wall
    CHECK(outer_sinks_kept("[[4,1],[3.5,1.2]]") == 0);    // the same, slanted, end first
    CHECK(outer_sinks_kept("[[0,1],[4,2]]") == 0);        // a chord, both ends on the walls
    CHECK(outer_sinks_kept("[[3.5,1],[3.999,1]]") == 0);  // short of the wall, as before
    CHECK(outer_sinks_kept("[[3.5,1],[4.5,1]]") == 4);    // through the wall: it sees them
    CHECK(outer_sinks_kept("[[4,1],[4.5,1]]") == 4);      // against the wall, outside
    CHECK(outer_sinks_kept("[[3.5,2.5],[4,3]]") == 4);    // an end on a corner: not proven
}

TEST_CASE("directional tables: the linear part is exact wherever every lobe faces") {
    // Lobes with normals in an arc of width < pi: for every direction u all
    // of them face (engine/normal_cone.h), sum w cos+(n . u) = (sum w n) . u
    // to rounding; for arrivals from such directions, an element reads its
    // exact cosine. Rounding of sums of ~10 terms of size ~1.
    constexpr double tol = 1e-14;
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> U(0, 1);
    int facing = 0;
    for (int trial = 0; trial < 200; ++trial) {
        const RandomLobes r = random_lobes(rng);
        const double* table = r.table;
        const auto& lobes = r.lobes;
        const NormalCone& cone = r.cone;
        for (int q = 0; q < 20; ++q) {
            const double a = 2 * std::numbers::pi * U(rng);
            const Vec2 u{std::cos(a), std::sin(a)};
            const std::array<Vec2, 4> origin{Vec2{0, 0}, Vec2{0, 0}, Vec2{0, 0}, Vec2{0, 0}}, far{u, u, u, u};
            if (!cone.faces_all(origin, far)) continue;
            ++facing;
            double exact = 0;
            for (const auto& [n, w] : lobes) exact += w * std::max(0.0, dot(n, u));
            CHECK(std::abs(read_linear(table, u) - exact) <= tol);
            // An arrival of weight 1 from u, read by each member.
            double arrivals[directional_table_width] = {};
            add_linear(arrivals, u, 1.0);
            for (const auto& lobe : lobes) CHECK(std::abs(read_cosine_lobe(arrivals, lobe.first) - dot(lobe.first, u)) <= tol);
        }
    }
    CHECK(facing > 200);  // not vacuous
}

TEST_CASE("directional tables: facing u only, the table leaves its linear part over the spread by at most linear_departure") {
    // Lobes in an arc narrower than pi, read around a direction u they all
    // face (facing_margin >= 0) but not every direction within delta of it
    // (a wall's neighbour along a curve): at u the linear part is exact;
    // at u' within delta, |sum w cos+(n . u') - (sum w n) . u'| <=
    // linear_departure(u, delta) |sum w n|. Rounding of sums of ~10 terms.
    constexpr double tol = 1e-13;
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> U(0, 1);
    int departed = 0, checked = 0;
    double tightest = 0;  // the largest share of the bound reached
    for (int trial = 0; trial < 300; ++trial) {
        const RandomLobes r = random_lobes(rng);
        const double* table = r.table;
        const auto& lobes = r.lobes;
        const NormalCone& cone = r.cone;
        auto exact = [&](Vec2 u) {
            double s = 0;
            for (const auto& [n, w] : lobes) s += w * std::max(0.0, dot(n, u));
            return s;
        };
        const double norm_lin = std::hypot(table[directional_bins], table[directional_bins + 1]);
        for (int q = 0; q < 20; ++q) {
            const double a = 2 * std::numbers::pi * U(rng), delta = 1.2 * U(rng);
            const Vec2 u{std::cos(a), std::sin(a)};
            const double bound = cone.linear_departure(u, delta);
            // Not every member faces u exactly when the bound is negative.
            bool all_face = true;
            for (const auto& lobe : lobes) all_face = all_face && dot(lobe.first, u) >= 0;
            CHECK((bound >= 0) == (all_face && cone.width < std::numbers::pi));
            if (bound < 0) continue;
            CHECK(std::abs(read_linear(table, u) - exact(u)) <= tol);
            for (int j = 0; j <= 40; ++j) {
                const double t = a + delta * (j / 20.0 - 1);
                const Vec2 v{std::cos(t), std::sin(t)};
                const double off = std::abs(exact(v) - read_linear(table, v));
                ++checked;
                CHECK(off <= bound * norm_lin + tol);
                if (off > tol) {
                    ++departed;
                    tightest = std::max(tightest, off / (bound * norm_lin));
                }
            }
        }
    }
    // Not vacuous: members did turn away within the spread, and the bound
    // was approached (a single lobe turning away reaches it up to the
    // cos(width / 2) slack).
    CHECK(departed > 100);
    CHECK(tightest > 0.5);
    CHECK(checked > 10000);
}

TEST_CASE("directional tables: the opposite direction's bin is half the table on, with the same weight") {
    // bin_of(-u) computed by atan2 agrees with opposite(bin_of(u)) to the
    // rounding of an angle of size ~2 pi, divided by the step (~1e-15 in t).
    constexpr double tol = 1e-12;
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> U(0, 2 * std::numbers::pi);
    for (int q = 0; q < 2000; ++q) {
        const double a = U(rng);
        const Vec2 u{std::cos(a), std::sin(a)};
        const BinWeight o = opposite(bin_of(u)), b = bin_of(-u);
        // The same point of the circle: k + t equal modulo the table.
        double d = (o.k + o.t) - (b.k + b.t);
        d -= directional_bins * std::round(d / directional_bins);
        CHECK(std::abs(d) <= tol);
    }
}
