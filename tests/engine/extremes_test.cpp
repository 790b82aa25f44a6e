// The extreme-case matrix (hardening issue) at the engine level: the scene
// reader (engine/scene.h) and the unoccluded kernels (engine/formfactor.h)
// on scenes at the edge of what doubles hold. Each case states what must
// happen: a value with a justified tolerance, or a clear refusal.
// The exact (occluded) path and the solver at the same extremes are in
// tests/solver/extremes_test.cpp.
#include <doctest/doctest.h>

#include <cmath>
#include <fmt/format.h>
#include <string>

#include "engine/error.h"
#include "engine/formfactor.h"
#include "engine/scene.h"

using namespace flatrad;

namespace {

// Crossed strings are a dozen roundings (DESIGN §1: a few 1e-15 relative);
// the closed forms below are a few more. 1e-13 leaves a 20x margin, as in
// tests/engine/formfactor_test.cpp.
constexpr double closed_form_tol = 1e-13;
// Scaling by 10^k is not exact in binary: every coordinate is rounded once
// (half an ulp), which moves F by a few ulps times its condition (~1 for
// these well-separated shapes). 1e-13 again.
constexpr double scale_tol = 1e-13;

double rel_err(double x, double ref) { return std::abs(x - ref) / std::abs(ref); }

std::string num(double x) { return fmt::format("{}", x); }  // shortest round-trip text

}  // namespace

// ---- coordinates from 1e-9 to 1e9 -------------------------------------------

TEST_CASE("extremes: coordinates 1e-9 .. 1e9 are read exactly and F is scale-free") {
    // Two facing plates of side s at distance s: F = sqrt(2) - 1 at every
    // scale, read through the scene reader (the literal round-trips).
    const double ref = std::sqrt(2.0) - 1;
    for (int k = -9; k <= 9; ++k) {
        const double s = std::pow(10.0, k);
        const std::string text = fmt::format(
            R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}},
                "surfaces": [{{"name": "a", "material": "m", "points": [[0, 0], [{0}, 0]]}},
                             {{"name": "b", "material": "m", "points": [[{0}, {0}], [0, {0}]]}}]}})",
            num(s));
        CAPTURE(s);
        const Scene scene = parse_scene(text, "scaled.json");
        REQUIRE(scene.patches.size() == 2);
        CHECK(scene.segments[0].seg.b.x == s);  // exact: the literal is the double
        CHECK(scene.patches[0].length == s);
        const double F = form_factor_unoccluded(scene.patch_segment(0), scene.patch_segment(1));
        CHECK(rel_err(F, ref) <= scale_tol);
        CHECK(rel_err(form_factor_unoccluded(scene.patch_segment(1), scene.patch_segment(0)), ref) <= scale_tol);
    }
}

TEST_CASE("extremes: a tilted configuration keeps F from 1e-9 to 1e9, translated far from the origin") {
    // Reference at scale 1 by crossed strings; each scaled copy sits at
    // (3 s, -2 s) so that coordinates, not only lengths, span the range.
    const Segment i{{0, 0}, {1, 0.2}}, j{{1.3, 0.9}, {-0.1, 1.2}};
    const double F = form_factor_unoccluded(i, j);
    REQUIRE(F > 0.1);
    for (int k = -9; k <= 9; ++k) {
        const double s = std::pow(10.0, k);
        const Vec2 shift{3 * s, -2 * s};
        const Segment is{i.a * s + shift, i.b * s + shift}, js{j.a * s + shift, j.b * s + shift};
        CAPTURE(s);
        CHECK(rel_err(form_factor_unoccluded(is, js), F) <= scale_tol);
    }
}

TEST_CASE("extremes: coordinates beyond +-1e100 and non-finite numbers are refused") {
    // The reader's documented range (engine/scene.cpp, max_coordinate).
    const auto plate = [](const std::string& x) {
        return R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [{"name": "a", "material": "m", "points": [[0, 0], [)" +
               x + R"(, 0]]}]})";
    };
    CHECK_NOTHROW(parse_scene(plate("1e100"), "edge.json"));
    for (const char* bad : {"1e101", "-1e101", "1e999", "NaN", "Infinity"}) {
        CAPTURE(bad);
        CHECK_THROWS_AS(parse_scene(plate(bad), "bad.json"), InputError);
    }
}

// ---- segments from 1e-8 to 1e8 long in one scene ----------------------------

TEST_CASE("extremes: segments 1e-8 and 1e8 long in one scene") {
    // A 1e-8 segment centred under a 1e8 one at distance 1, both lit toward
    // each other. With e = 1e-8, H = 5e7 (half the long one):
    //   X = sqrt((H + e/2)^2 + 1) - sqrt((H - e/2)^2 + 1) = 2 H e / (s1 + s2),
    // written without cancellation, so F_short = X / e = 2 H / (s1 + s2)
    // (= 1 - 2e-16) and F_long = X / 1e8 (= 1e-16).
    const double e = 1e-8, H = 5e7;
    const std::string text = fmt::format(
        R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}},
            "surfaces": [{{"name": "short", "material": "m", "points": [[{}, 0], [{}, 0]]}},
                         {{"name": "long", "material": "m", "points": [[{}, 1], [{}, 1]]}}]}})",
        num(-e / 2), num(e / 2), num(H), num(-H));
    const Scene scene = parse_scene(text, "lengths.json");
    REQUIRE(scene.patches.size() == 2);
    CHECK(rel_err(scene.patches[0].length, e) <= 1e-15);  // e/2 - (-e/2): exact up to one rounding
    CHECK(scene.patches[1].length == 2 * H);
    const double s1 = std::sqrt((H + e / 2) * (H + e / 2) + 1), s2 = std::sqrt((H - e / 2) * (H - e / 2) + 1);
    const double X = 2 * H * e / (s1 + s2);
    const Segment a = scene.patch_segment(0), b = scene.patch_segment(1);
    CHECK(rel_err(form_factor_unoccluded(a, b), X / e) <= closed_form_tol);
    CHECK(rel_err(form_factor_unoccluded(b, a), X / (2 * H)) <= closed_form_tol);
    // Reciprocity across 16 orders of magnitude in length.
    CHECK(rel_err(e * form_factor_unoccluded(a, b), 2 * H * form_factor_unoccluded(b, a)) <= closed_form_tol);
}

TEST_CASE("extremes: a segment too short to measure at its coordinates is refused") {
    // At x = 1e8 neighbouring doubles are 1.5e-8 apart: two points 1e-9
    // apart there are the same double (zero-length segment), a clear refusal.
    const std::string text =
        R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [{"name": "a", "material": "m",
            "points": [[100000000, 0], [100000000.000000001, 0]]}]})";
    try {
        parse_scene(text, "short.json");
        FAIL("accepted a zero-length segment");
    } catch (const InputError& err) {
        CHECK(err.path() == "surfaces[0].points[1]");
        CHECK(err.message().find("zero-length") != std::string::npos);
    }
}

// ---- nearly collinear and overlapping segments ------------------------------

TEST_CASE("extremes: collinear and overlapping segments exchange nothing") {
    // On one line neither is in front of the other: F = 0 exactly (no
    // sliver of rounding), whichever way each is lit and however they overlap.
    const Segment i{{0, 0}, {2, 0}};
    for (const Segment& j : {Segment{{1, 0}, {3, 0}}, Segment{{3, 0}, {1, 0}}, Segment{{0.5, 0}, {1.5, 0}},
                             Segment{{2, 0}, {0, 0}}, Segment{{2, 0}, {4, 0}}}) {
        CAPTURE(j.a.x);
        CAPTURE(j.b.x);
        CHECK(form_factor_unoccluded(i, j) == 0);
        CHECK(form_factor_unoccluded(j, i) == 0);
    }
    // The reader refuses overlapping surfaces: two surfaces in one place
    // would each be seen twice (row sums of F above 1; the fuzzer found a
    // stiff scene solving to negative radiosity). Meeting end to end is fine.
    CHECK_THROWS_AS(parse_scene(
                        R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [
            {"name": "a", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "b", "material": "m", "points": [[1, 0], [3, 0]], "side": "both"}]})",
                        "overlap.json"),
                    InputError);
    CHECK_NOTHROW(parse_scene(
        R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [
            {"name": "a", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "b", "material": "m", "points": [[2, 0], [3, 0]], "side": "both"}]})",
        "touching.json"));
}

TEST_CASE("extremes: facing plates 1e-9 apart, and nearly flat wedges") {
    // Overlapping facing plates at separation d: F = sqrt(1 + d^2) - d, as
    // 1 / (sqrt(1 + d^2) + d) (no cancellation).
    for (double d : {1e-3, 1e-6, 1e-9, 1e-12}) {
        const Segment i{{0, 0}, {1, 0}}, j{{1, d}, {0, d}};
        CAPTURE(d);
        CHECK(rel_err(form_factor_unoccluded(i, j), 1 / (std::sqrt(1 + d * d) + d)) <= closed_form_tol);
    }
    // Unit segments sharing the origin, opening angle pi - eps (nearly one
    // line, lit on the concave side): F = 1 - sin(alpha / 2) = 1 - cos(eps / 2)
    // = 2 sin^2(eps / 4), down to 1e-17 at eps = 1e-8. The relative error
    // comes from rounding the far end's coordinates (eps is known to ~1e-16
    // relative through sin(eps / 2)); F ~ eps^2 doubles it: 1e-13 is ample.
    for (double eps : {1e-2, 1e-4, 1e-6, 1e-8}) {
        const Segment i{{0, 0}, {1, 0}};
        const Segment j{{-std::cos(eps), std::sin(eps)}, {0, 0}};  // angle pi - eps from i
        const double ref = 2 * std::sin(eps / 4) * std::sin(eps / 4);
        // The far end's exact angle: pi - atan2(sin eps, cos eps) rounds; use
        // the computed point's own angle for the reference.
        const double eps_actual = std::atan2(j.a.y, -j.a.x);
        const double ref_actual = 2 * std::sin(eps_actual / 4) * std::sin(eps_actual / 4);
        CAPTURE(eps);
        CHECK(rel_err(ref_actual, ref) <= 1e-12);
        CHECK(rel_err(form_factor_unoccluded(i, j), ref_actual) <= closed_form_tol);
    }
}

// ---- T-junctions and shared endpoints ---------------------------------------

TEST_CASE("extremes: shared endpoints of a 3-4-5 triangle give (a + b - c) / 2a") {
    // Three polylines meeting end to end (shared endpoints, no closed flag):
    // in a triangle F_ab = (L_a + L_b - L_c) / (2 L_a), and each row sums to 1.
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [
            {"name": "a", "material": "m", "points": [[0, 0], [3, 0]]},
            {"name": "b", "material": "m", "points": [[3, 0], [3, 4]]},
            {"name": "c", "material": "m", "points": [[3, 4], [0, 0]]}]})",
        "triangle.json");
    REQUIRE(scene.patches.size() == 3);
    const double L[3] = {3, 4, 5};
    for (int p = 0; p < 3; ++p) {
        double row = 0;
        for (int q = 0; q < 3; ++q) {
            if (p == q) continue;
            const int r = 3 - p - q;
            const double F = form_factor_unoccluded(scene.patch_segment(p), scene.patch_segment(q));
            CAPTURE(p);
            CAPTURE(q);
            CHECK(rel_err(F, (L[p] + L[q] - L[r]) / (2 * L[p])) <= closed_form_tol);
            row += F;
        }
        CHECK(std::abs(row - 1) <= closed_form_tol);
    }
}

TEST_CASE("extremes: a T-junction splits the lamp into what each side of the stem sees") {
    // Lamp [0, 2] on y = 0 lit up; a two-sided stem from (1, 0) to (1, 1)
    // stands on it (the T). Each stem patch sees the lamp half in front of
    // it as perpendicular plates sharing an edge: 1 - sqrt(2)/2; the half
    // behind is clipped away exactly.
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [
            {"name": "lamp", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "stem", "material": "m", "points": [[1, 0], [1, 1]], "side": "both"}]})",
        "t.json");
    REQUIRE(scene.patches.size() == 3);
    const double ref = 1 - std::sqrt(2.0) / 2;
    for (int p : {1, 2}) {
        CAPTURE(p);
        CHECK(rel_err(form_factor_unoccluded(scene.patch_segment(p), scene.patch_segment(0)), ref) <= closed_form_tol);
    }
}

// ---- a single segment, no emitter --------------------------------------------

TEST_CASE("extremes: a single segment is a valid scene and cannot see itself") {
    const Scene one = parse_scene(
        R"({"flatrad": 1, "materials": {"lamp": {"emission": 1}}, "surfaces": [
            {"name": "lamp", "material": "lamp", "points": [[0, 0], [1, 0]], "side": "both"}]})",
        "one.json");
    REQUIRE(one.segments.size() == 1);
    REQUIRE(one.patches.size() == 2);
    CHECK(form_factor_unoccluded(one.patch_segment(0), one.patch_segment(1)) == 0);
    CHECK(form_factor_unoccluded(one.patch_segment(0), one.patch_segment(0)) == 0);
    CHECK(one.extent() == 1);
}

TEST_CASE("extremes: a scene without any emitter is read (emission defaults to 0)") {
    const Scene dark = parse_scene(
        R"({"flatrad": 1, "materials": {"grey": {"reflectance": [0.5, 0, 0.999999]}}, "surfaces": [
            {"name": "a", "material": "grey", "points": [[0, 0], [1, 0]]}]})",
        "dark.json");
    REQUIRE(dark.channels == 3);
    for (double e : dark.materials[0].emission) CHECK(e == 0);
    CHECK(dark.materials[0].reflectance[2] == 0.999999);
}

// ---- memory -------------------------------------------------------------------

TEST_CASE("extremes: a scene too big to hold is refused before it is built, with the size") {
    // Five circles of 2^20 segments: 5.2 million segments, about 1.1 GiB
    // with their patches and hierarchy, over the 1 GiB limit
    // (scene_memory_limit_bytes). A few hundred bytes of JSON; refused at the
    // circle that takes the scene over, before any point is made.
    std::string surfaces;
    for (int k = 0; k < 5; ++k)
        surfaces += fmt::format(R"({}{{"name": "c{}", "material": "m", "circle": {{"center": [{}, 0], "radius": 1, "segments": 1048576}}, "side": "both"}})",
                                k ? ", " : "", k, 3 * k);
    const std::string text = R"({"flatrad": 1, "materials": {"m": {}}, "surfaces": [)" + surfaces + "]}";
    CHECK(scene_memory_bytes(5 * 1048576.0) > scene_memory_limit_bytes);
    CHECK(scene_memory_bytes(4 * 1048576.0) <= scene_memory_limit_bytes);
    try {
        parse_scene(text, "big.json");
        FAIL("a 1.1 GiB scene was accepted");
    } catch (const InputError& err) {
        CHECK(err.path() == "surfaces[4].circle.segments");
        CHECK(err.message().find("5242880 segments") != std::string::npos);
        CHECK(err.message().find("GiB to hold; the limit is 1 GiB") != std::string::npos);
    }
}

// ---- regressions found by the fuzzer (fuzz/corpus/regress_*.json) -------------

TEST_CASE("extremes: a wall 4e57 long does not pull a unit lamp's end onto its corner") {
    // fuzz/corpus/regress_huge_wall_snap.json. Lamp [0, 1] on y = 0 lit up;
    // a wall from (2, Y) to (-1, 2), Y = 4.4e57, lit toward the lamp.
    // Clipping used to "snap" endpoints closer than 64 ulps of the largest
    // coordinate of the pair (here 1e43!), so the wall's end (-1, 2) was
    // moved onto the lamp's end (0, 0) and F came out 0.5. Now only points
    // made by a cut are snapped. Crossed strings, the Y terms written out:
    //   X = (sqrt(8) - sqrt(5) + 3 / (sqrt(4 + Y^2) + sqrt(1 + Y^2))) / 2.
    const double Y = 4444444444444444444444444444444444444444444444444444444442.0;
    const Segment lamp{{0, 0}, {1, 0}}, wall{{2, Y}, {-1, 2}};
    const double ref = (std::sqrt(8.0) - std::sqrt(5.0) + 3 / (std::hypot(2.0, Y) + std::hypot(1.0, Y))) / 2;
    CHECK(rel_err(form_factor_unoccluded(lamp, wall), ref) <= closed_form_tol);
    const auto clipped = clip_to_lit_halfplanes(lamp, wall);
    REQUIRE(clipped);
    CHECK(clipped->second.b == Vec2{-1, 2});  // not moved
}

TEST_CASE("extremes: crossed strings from a 1e33-long wall to a unit one is as exact as the other way") {
    // fuzz/corpus/regress_sliver_box_1e33.json: with the long segment as i,
    // the second-difference form subtracted values of size 1e33 and X (~3)
    // came out 3.8e17. The exchange is symmetric, so the shorter one now
    // plays i. Wall x = 2 from y = -1 up to Y, lit toward -x; the other
    // from (-2, 2) to (0, -1), lit toward +x. Crossed strings with the Y
    // terms written out (each |.| - |.| as a difference of squares).
    const double Y = 4.44444e33;
    const Segment wall{{2, -1}, {2, Y}}, other{{-2, 2}, {0, -1}};
    // i = other = [a, b], j = wall = [c, d]: X = (|a-c| + |b-d| - |a-d| - |b-c|) / 2,
    // |a - c| = 5, |b - c| = 2, |b - d| - |a - d| = (|b-d|^2 - |a-d|^2) / (|b-d| + |a-d|).
    const Vec2 a = other.a, b = other.b, d = wall.b;
    const double bd = std::hypot(d.x - b.x, d.y - b.y), ad = std::hypot(d.x - a.x, d.y - a.y);
    const double diff = ((b.x - a.x) * (b.x + a.x - 2 * d.x) + (b.y - a.y) * (b.y + a.y - 2 * d.y)) / (bd + ad);
    const double ref = (5 - 2 + diff) / 2;
    CHECK(rel_err(exchange_crossed_strings(other, wall), ref) <= closed_form_tol);
    CHECK(rel_err(exchange_crossed_strings(wall, other), ref) <= closed_form_tol);
    CHECK(rel_err(form_factor_unoccluded(wall, other) * wall.length(), ref) <= closed_form_tol);
}

TEST_CASE("extremes: lengths spanning 1e16 are read, beyond 2e16 refused") {
    // engine/scene.cpp max_length_range: the matrix's 1e-8 and 1e8 segments
    // in one scene (extent / shortest = 1e16) are read; 1e-9 beside 1e8 is
    // refused, naming the short segment.
    const auto scene = [](const char* short_end) {
        return fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{}}}}, "surfaces": [
            {{"name": "long", "material": "m", "points": [[0, 1], [100000000, 1]]}},
            {{"name": "short", "material": "m", "points": [[0, 0], [{}, 0]]}}]}})",
                           short_end);
    };
    CHECK_NOTHROW(parse_scene(scene("1e-8"), "range.json"));
    try {
        parse_scene(scene("1e-9"), "range.json");
        FAIL("accepted");
    } catch (const InputError& err) {
        CHECK(err.path() == "surfaces[1].points[1]");
        CHECK(err.message().find("range of lengths") != std::string::npos);
    }
}
