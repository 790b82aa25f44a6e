// Tests for engine/connectivity.h: objects and loops of the endpoint graph
// (exact endpoint equality, T-junctions, two-segment cycles), the
// escape-free rule (rooms, objects inside and outside, crossing and touching
// segments, nested, non-convex and self-crossing loops), the scenes in data/,
// invariance under scale and translation, and soundness against brute-force
// rays on random scenes.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

using namespace flatrad;

namespace {

// ---- scene text -----------------------------------------------------------------

std::string num(double x) {
    std::ostringstream o;
    o.precision(17);
    o << x;
    return o.str();
}

std::string points_json(const std::vector<Vec2>& pts) {
    std::string s = "[";
    for (size_t k = 0; k < pts.size(); ++k)
        s += (k ? ", [" : "[") + num(pts[k].x) + ", " + num(pts[k].y) + "]";
    return s + "]";
}

/// An open polyline (side left/right/both) or, with closed, a polygon (side in/out/both).
std::string poly(const std::string& name, const std::vector<Vec2>& pts, const std::string& side,
                 bool closed = false, const std::string& material = "white") {
    return R"({"name": ")" + name + R"(", "material": ")" + material + R"(", "points": )" + points_json(pts) +
           (closed ? R"(, "closed": true)" : "") + R"(, "side": ")" + side + R"("})";
}

std::string circle(const std::string& name, Vec2 c, double r, int segments, const std::string& side) {
    return R"({"name": ")" + name + R"(", "material": "white", "circle": {"center": [)" + num(c.x) + ", " +
           num(c.y) + "], \"radius\": " + num(r) + ", \"segments\": " + std::to_string(segments) +
           R"(}, "side": ")" + side + R"("})";
}

Scene scene_of(const std::vector<std::string>& surfaces) {
    std::string s = R"({"flatrad": 1, "materials": {"white": {"reflectance": 0.5}, "lamp": {"emission": 1}},
                        "surfaces": [)";
    for (size_t k = 0; k < surfaces.size(); ++k) s += (k ? ", " : "") + surfaces[k];
    return parse_scene(s + "]}", "test/connectivity.json");
}

/// The escape-free flags of the patches of surface `name`.
std::vector<char> flags_of(const Scene& scene, const std::vector<char>& free, const std::string& name) {
    const int surf = scene.find_surface(name);
    REQUIRE(surf >= 0);
    std::vector<char> out;
    for (size_t p = 0; p < scene.patches.size(); ++p)
        if (scene.patches[p].surface == surf) out.push_back(free[p]);
    REQUIRE(!out.empty());
    return out;
}
bool all_free(const Scene& scene, const std::vector<char>& free, const std::string& name) {
    const auto f = flags_of(scene, free, name);
    return std::all_of(f.begin(), f.end(), [](char c) { return c == 1; });
}
bool none_free(const Scene& scene, const std::vector<char>& free, const std::string& name) {
    const auto f = flags_of(scene, free, name);
    return std::none_of(f.begin(), f.end(), [](char c) { return c == 1; });
}

/// prefix + k (a helper: GCC 12 warns, wrongly, on "literal" + std::to_string).
std::string named(const char* prefix, int k) {
    std::string s(prefix);
    s += std::to_string(k);
    return s;
}

const std::vector<Vec2> square4 = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};

// ---- brute-force rays (for the soundness property) ------------------------------

// Shoelace areas of loops of up to 64 segments of size ~1, compensated: a
// few ulps; 1e-14 is about 50 ulps.
constexpr double area_tol = 1e-14;
// A ray starts on its patch; hits closer than this (relative to scenes of
// size ~10) are the patch itself or rounding, not a blocker.
constexpr double ray_start_slack = 1e-12;

/// The ray o + t d (t > 0) hits segment s (closed), in plain doubles; used
/// only on random configurations far from grazing.
bool ray_hits(Vec2 o, Vec2 d, const Segment& s) {
    const Vec2 e = s.b - s.a;
    const double den = cross(d, e);
    if (den == 0) return false;
    const Vec2 w = s.a - o;
    const double t = cross(w, e) / den, u = cross(w, d) / den;
    return t > ray_start_slack && u >= 0 && u <= 1;
}

}  // namespace

// ---- the graph --------------------------------------------------------------------

TEST_CASE("connectivity: four polylines joined end to end form one loop") {
    // Clockwise in the file, pieces in scrambled order and directions.
    const Scene scene = scene_of({poly("south", {{4, 0}, {0, 0}}, "right"),
                                  poly("north", {{0, 3}, {4, 3}}, "right"),
                                  poly("west", {{0, 0}, {0, 3}}, "right"),
                                  poly("east", {{4, 0}, {4, 3}}, "left")});
    const Connectivity cx = scene_connectivity(scene);
    CHECK(cx.vertex_count == 4);
    REQUIRE(cx.objects.size() == 1);
    CHECK(cx.objects[0].segments == std::vector<int>{0, 1, 2, 3});
    REQUIRE(cx.loops.size() == 1);
    const SceneLoop& loop = cx.loops[0];
    CHECK(cx.objects[0].loop == 0);
    CHECK(loop.object == 0);
    // Starts at segment 0 traversed a -> b: (4,0) -> (0,0) -> (0,3) -> (4,3) -> back.
    CHECK(loop.segments == std::vector<int>{0, 2, 1, 3});
    CHECK(loop.forward == std::vector<char>{1, 1, 1, 0});
    CHECK(loop.polygon == std::vector<Vec2>{{4, 0}, {0, 0}, {0, 3}, {4, 3}});
    CHECK(loop.signed_area == -12.0);  // clockwise, exact in doubles
    CHECK(loop.simple);
    CHECK(loop.orientation == -1);
    CHECK(loop.box.lo == Vec2{0, 0});
    CHECK(loop.box.hi == Vec2{4, 3});
    for (int d : cx.vertex_degree) CHECK(d == 2);
    // Every wall is lit inside (each piece's own side says so): enclosed.
    CHECK(scene_enclosed(scene));
}

TEST_CASE("connectivity: closed polygons and circles are loops with their area") {
    const Scene scene = scene_of({poly("room", square4, "in", true), circle("pillar", {2, 2}, 1, 64, "out"),
                                  poly("tri", {{0.5, 0.5}, {1, 0.5}, {0.5, 1}}, "both", true)});
    const Connectivity cx = scene_connectivity(scene);
    REQUIRE(cx.loops.size() == 3);
    CHECK(cx.loops[0].signed_area == 16.0);
    CHECK(cx.loops[0].orientation == 1);
    CHECK(cx.loops[1].segments.size() == 64);
    // A regular 64-gon of radius 1: (n / 2) sin(2 pi / n).
    CHECK(cx.loops[1].signed_area == doctest::Approx(32 * std::sin(2 * std::numbers::pi / 64)).epsilon(area_tol));
    CHECK(cx.loops[1].simple);
    CHECK(cx.loops[1].orientation == 1);  // circles run counter-clockwise (SPEC)
    CHECK(cx.loops[2].signed_area == doctest::Approx(0.125).epsilon(area_tol));
    CHECK(cx.vertex_count == 4 + 64 + 3);
}

TEST_CASE("connectivity: an open polyline is an object but not a loop") {
    const Scene scene = load_scene(FLATRAD_DATA_DIR "/two_plates.json");
    const Connectivity cx = scene_connectivity(scene);
    CHECK(cx.objects.size() == 2);
    CHECK(cx.loops.empty());
    for (const SceneObject& o : cx.objects) CHECK(o.loop == -1);
    const auto free = escape_free_patches(scene, cx);
    CHECK(std::none_of(free.begin(), free.end(), [](char c) { return c; }));
    CHECK(!scene_enclosed(scene));

    // An L-shaped open polyline: degrees 1, 2, 1.
    const Scene l = scene_of({poly("l", {{0, 0}, {1, 0}, {1, 1}}, "left")});
    const Connectivity lc = scene_connectivity(l);
    CHECK(lc.vertex_degree == std::vector<int>{1, 2, 1});
    CHECK(lc.loops.empty());
}

TEST_CASE("connectivity: a T-junction (degree 3) is not a loop") {
    // A room with a partition wall sharing the vertex (2, 0) of the floor:
    // one object, a vertex of degree 3, so no loop and nothing proven.
    const Scene scene = scene_of({poly("walls", {{0, 0}, {2, 0}, {4, 0}, {4, 4}, {0, 4}}, "in", true),
                                  poly("partition", {{2, 0}, {2, 2}}, "both")});
    const Connectivity cx = scene_connectivity(scene);
    CHECK(cx.objects.size() == 1);
    CHECK(cx.loops.empty());
    CHECK(std::count(cx.vertex_degree.begin(), cx.vertex_degree.end(), 3) == 1);
    const auto free = escape_free_patches(scene, cx);
    CHECK(none_free(scene, free, "walls"));
    CHECK(none_free(scene, free, "partition"));

    // The same T-shaped object inside a room is escape-free on every side.
    const Scene inside = scene_of({poly("room", {{-1, -1}, {5, -1}, {5, 5}, {-1, 5}}, "in", true),
                                   poly("walls", {{0, 0}, {2, 0}, {4, 0}, {4, 4}, {0, 4}}, "both", true),
                                   poly("partition", {{2, 0}, {2, 2}}, "both")});
    const auto f2 = escape_free_patches(inside);
    CHECK(scene_connectivity(inside).loops.size() == 1);
    CHECK(all_free(inside, f2, "walls"));
    CHECK(all_free(inside, f2, "partition"));
}

TEST_CASE("connectivity: endpoints merge only when exactly equal") {
    // A gap of 1e-12 at one corner: not joined, so no loop and no proof.
    const Scene gap = scene_of({poly("a", {{0, 0}, {1, 0}, {1, 1}}, "left"),
                                poly("b", {{1, 1}, {0, 1}, {0, 1e-12}}, "left")});
    const Connectivity gc = scene_connectivity(gap);
    CHECK(gc.vertex_count == 5);
    CHECK(gc.loops.empty());
    CHECK(!scene_enclosed(gap));
    // The same corner written as 0 and -0: the same point, a closed room.
    const Scene zero = scene_of({poly("a", {{0, 0}, {1, 0}, {1, 1}}, "left"),
                                 poly("b", {{1, 1}, {0, 1}, {-0.0, -0.0}}, "left")});
    CHECK(scene_connectivity(zero).loops.size() == 1);
    CHECK(scene_enclosed(zero));
}

// ---- the escape-free rule ---------------------------------------------------------

TEST_CASE("escape_free: a closed room's sides") {
    // Lit inside: every patch escape-free. Lit outside: none.
    CHECK(scene_enclosed(scene_of({poly("room", square4, "in", true)})));
    const Scene out = scene_of({poly("room", square4, "out", true)});
    const auto fo = escape_free_patches(out);
    CHECK(none_free(out, fo, "room"));
    // Both sides: the in patch of each segment (first, SPEC numbering) yes, the out patch no.
    const Scene both = scene_of({poly("room", square4, "both", true)});
    const auto fb = escape_free_patches(both);
    CHECK(fb == std::vector<char>{1, 0, 1, 0, 1, 0, 1, 0});
    // A polyline room lit on the right of a counter-clockwise walk: outward.
    const Scene right = scene_of({poly("room", {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 0}}, "right")});
    CHECK(!scene_enclosed(right));
    CHECK(scene_connectivity(right).loops.size() == 1);
}

TEST_CASE("escape_free: objects inside a room on all their sides, outside or crossing, not") {
    const Scene scene = scene_of({
        poly("room", square4, "in", true),
        circle("pillar", {1, 1}, 0.5, 24, "out"),
        poly("box", {{2.5, 2.5}, {3.5, 2.5}, {3.5, 3.5}, {2.5, 3.5}}, "both", true),
        poly("shelf", {{0.5, 3}, {1.5, 3}, {1.5, 2.5}}, "both"),
        poly("lamp", {{1.5, 3.9}, {2.5, 3.9}}, "right", false, "lamp"),
        poly("outside", {{5, 0}, {5, 4}}, "both"),
        poly("crossing", {{3.5, 1}, {4.5, 1}}, "both"),
        poly("pole", {{2, -1}, {2, 5}}, "both"),  // crosses floor and ceiling
    });
    const auto free = escape_free_patches(scene);
    CHECK(all_free(scene, free, "room"));
    CHECK(all_free(scene, free, "pillar"));
    CHECK(all_free(scene, free, "box"));
    CHECK(all_free(scene, free, "shelf"));
    CHECK(all_free(scene, free, "lamp"));
    CHECK(none_free(scene, free, "outside"));
    CHECK(none_free(scene, free, "crossing"));
    CHECK(none_free(scene, free, "pole"));
    CHECK(!scene_enclosed(scene));
}

TEST_CASE("escape_free: touching a wall is not proven (conservative)") {
    const Scene scene = scene_of({
        poly("room", square4, "in", true),
        poly("leg", {{1, 0}, {1, 1}}, "both"),          // stands on the floor, no shared vertex
        poly("hang", {{2, 2}, {2, 4}}, "both"),         // touches the ceiling from inside
        poly("free", {{3.5, 0.001}, {3.5, 1}}, "both"),  // a millimetre above it
    });
    const auto free = escape_free_patches(scene);
    CHECK(all_free(scene, free, "room"));
    CHECK(none_free(scene, free, "leg"));
    CHECK(none_free(scene, free, "hang"));
    CHECK(all_free(scene, free, "free"));
}

TEST_CASE("escape_free: nested loops") {
    const Scene scene = scene_of({
        poly("outer", {{-2, -2}, {6, -2}, {6, 6}, {-2, 6}}, "both", true),
        poly("inner", square4, "both", true),
        circle("core", {2, 2}, 1, 32, "both"),
        poly("between", {{-1, -1}, {5, -1}}, "both"),
        poly("far", {{7, 0}, {7, 1}}, "both"),
    });
    const Connectivity cx = scene_connectivity(scene);
    CHECK(cx.loops.size() == 3);
    const auto free = escape_free_patches(scene, cx);
    // outer: in patches yes, out patches no (SPEC: in before out per segment).
    const auto outer = flags_of(scene, free, "outer");
    for (size_t k = 0; k < outer.size(); ++k) CHECK(outer[k] == (k % 2 == 0 ? 1 : 0));
    CHECK(all_free(scene, free, "inner"));
    CHECK(all_free(scene, free, "core"));
    CHECK(all_free(scene, free, "between"));
    CHECK(none_free(scene, free, "far"));
}

TEST_CASE("escape_free: a non-convex room's box is not its inside") {
    // A U-shaped room; a segment in the mouth of the U is inside the box but
    // outside the polygon; one across the mouth crosses the walls; one in an arm is inside.
    const std::vector<Vec2> u = {{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
    const Scene scene = scene_of({poly("u", u, "in", true),
                                  poly("mouth", {{1.2, 2}, {1.8, 2}}, "both"),
                                  poly("across", {{0.5, 2.5}, {2.5, 2.5}}, "both"),
                                  poly("arm", {{0.5, 1.5}, {0.5, 2.5}}, "both")});
    const auto free = escape_free_patches(scene);
    CHECK(all_free(scene, free, "u"));
    CHECK(none_free(scene, free, "mouth"));
    CHECK(none_free(scene, free, "across"));
    CHECK(all_free(scene, free, "arm"));
}

TEST_CASE("escape_free: a self-crossing loop proves by crossing number, not by its own sides") {
    // A bow tie (allowed with side "both"): not simple, so its own patches
    // are not proven; a segment inside one lobe is enclosed (odd crossing number).
    const Scene scene = scene_of({poly("bowtie", {{0, 0}, {4, 4}, {4, 0}, {0, 4}}, "both", true),
                                  poly("lobe", {{3.5, 1.5}, {3.5, 2.5}}, "both"),
                                  poly("gap", {{1.5, 0.2}, {2.5, 0.2}}, "both")});
    const Connectivity cx = scene_connectivity(scene);
    REQUIRE(cx.loops.size() == 1);
    CHECK(!cx.loops[0].simple);
    CHECK(cx.loops[0].signed_area == 0.0);
    const auto free = escape_free_patches(scene, cx);
    CHECK(none_free(scene, free, "bowtie"));
    CHECK(all_free(scene, free, "lobe"));
    CHECK(none_free(scene, free, "gap"));
}

TEST_CASE("escape_free: collinear pieces of a wall still make a simple room") {
    std::vector<Vec2> pts;
    for (int k = 0; k < 10; ++k) pts.push_back({0.1 * k, 0});
    for (int k = 0; k < 10; ++k) pts.push_back({1, 0.1 * k});
    for (int k = 0; k < 10; ++k) pts.push_back({1 - 0.1 * k, 1});
    for (int k = 0; k < 10; ++k) pts.push_back({0, 1 - 0.1 * k});
    const Scene scene = scene_of({poly("room", pts, "in", true)});
    const Connectivity cx = scene_connectivity(scene);
    REQUIRE(cx.loops.size() == 1);
    CHECK(cx.loops[0].simple);
    CHECK(scene_enclosed(scene));
    // A vertex touching another segment's interior ((2, 0) on the floor) is not simple.
    const Scene touch = scene_of({poly("touch", {{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}, "both", true)});
    const Connectivity tc = scene_connectivity(touch);
    REQUIRE(tc.loops.size() == 1);
    CHECK(!tc.loops[0].simple);
    CHECK(!scene_enclosed(touch));
}

TEST_CASE("escape_free: the scenes in data/") {
    for (const char* name : {"default", "closed_box", "furnished_room", "forest", "stiff_room", "uniform_box"}) {
        CAPTURE(name);
        const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/" + name + ".json");
        CHECK(scene_enclosed(scene));
    }
    for (const char* name : {"two_plates", "tube_bank", "soler95-fig5"}) {
        CAPTURE(name);
        const Scene scene = load_scene(std::string(FLATRAD_DATA_DIR) + "/" + name + ".json");
        CHECK(!scene_enclosed(scene));
    }
    // tube_bank: the tubes are loops lit outside between two open plates: nothing proven.
    const Scene tubes = load_scene(FLATRAD_DATA_DIR "/tube_bank.json");
    const Connectivity cx = scene_connectivity(tubes);
    CHECK(cx.loops.size() == tubes.surfaces.size() - 2);
    const auto free = escape_free_patches(tubes, cx);
    CHECK(std::none_of(free.begin(), free.end(), [](char c) { return c; }));
}

TEST_CASE("escape_free: no change under scale and translation") {
    for (double scale : {1e-6, 1.0, 1e6})
        for (double shift : {0.0, 1e6}) {
            CAPTURE(scale);
            CAPTURE(shift);
            auto at = [&](std::vector<Vec2> pts) {
                for (Vec2& p : pts) p = p * scale + Vec2{shift, shift} * scale;
                return pts;
            };
            const Scene scene = scene_of({poly("room", at(square4), "in", true),
                                          poly("inside", at({{1, 1}, {2, 1.5}}), "both"),
                                          poly("near", at({{1, 1e-6}, {2, 1e-6}}), "both"),
                                          poly("out", at({{5, 1}, {6, 1}}), "both")});
            const auto free = escape_free_patches(scene);
            CHECK(all_free(scene, free, "room"));
            CHECK(all_free(scene, free, "inside"));
            CHECK(all_free(scene, free, "near"));
            CHECK(none_free(scene, free, "out"));
        }
}

TEST_CASE("escape_free: sound against brute-force rays on random scenes") {
    // Random scenes: a star-shaped room (sometimes opened by a gap), small
    // polygons and segments anywhere (inside, outside, across the walls).
    // Every patch marked escape-free must have every sampled ray from its
    // lit side hit some other segment.
    std::mt19937_64 rng(20240611);
    std::uniform_real_distribution<double> U(0, 1);
    int proven = 0, total = 0;
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<std::string> surfaces;
        const int corners = 5 + static_cast<int>(U(rng) * 20);
        std::vector<Vec2> room;
        for (int k = 0; k < corners; ++k) {
            const double a = 2 * std::numbers::pi * (k + 0.3 * U(rng)) / corners;
            const double r = 3 + 2 * U(rng);
            room.push_back({r * std::cos(a), r * std::sin(a)});
        }
        if (trial % 4 == 3)
            surfaces.push_back(poly("room", room, "left"));  // open: a gap between last and first
        else
            surfaces.push_back(poly("room", room, trial % 2 ? "in" : "both", true));
        for (int k = 0; k < 12; ++k) {
            const Vec2 c{-6 + 12 * U(rng), -6 + 12 * U(rng)};
            const double r = 0.1 + 0.6 * U(rng);
            const std::string name = named("o", k);
            if (k % 3 == 0) {
                surfaces.push_back(circle(name, c, r, 3 + static_cast<int>(U(rng) * 8), k % 2 ? "out" : "both"));
            } else {
                const double a = 2 * std::numbers::pi * U(rng);
                const Vec2 d{r * std::cos(a), r * std::sin(a)};
                surfaces.push_back(poly(name, {c - d, c + d}, k % 2 ? "left" : "both"));
            }
        }
        const Scene scene = scene_of(surfaces);
        const auto free = escape_free_patches(scene);
        for (size_t p = 0; p < scene.patches.size(); ++p) {
            ++total;
            if (!free[p]) continue;
            ++proven;
            const Segment g = scene.patch_segment(static_cast<int>(p));
            const Vec2 dir = g.direction();
            for (int ray = 0; ray < 64; ++ray) {
                const Vec2 o = lerp(g.a, g.b, 0.01 + 0.98 * U(rng));
                const double ang = std::numbers::pi * (0.001 + 0.998 * U(rng));  // into the lit (left) half
                const Vec2 d = dir * std::cos(ang) + rot90(dir) * std::sin(ang);
                bool hit = false;
                for (size_t s = 0; s < scene.segments.size() && !hit; ++s)
                    if (static_cast<int>(s) != scene.patches[p].segment) hit = ray_hits(o, d, scene.segments[s].seg);
                CHECK_MESSAGE(hit, "escape from patch " << p << " of trial " << trial);
                if (!hit) break;
            }
        }
    }
    MESSAGE(proven << " of " << total << " patches proven escape-free");
    CHECK(proven > total / 4);  // the rule proves a good share, not nothing
}

// ---- scale ------------------------------------------------------------------------

TEST_CASE("escape_free: 10^5 segments in big loops, quickly") {
    // A 50 000-segment circle room holding 2 000 small 24-gons: every loop
    // large or many, so the loop-box and per-loop hierarchies are exercised.
    std::vector<std::string> surfaces = {circle("room", {0, 0}, 100, 50000, "in")};
    for (int k = 0; k < 2000; ++k)
        surfaces.push_back(circle(named("c", k), {-60 + 2.4 * (k % 50), -48 + 2.4 * (k / 50)}, 1, 24, "out"));
    const Scene scene = scene_of(surfaces);
    const auto t0 = std::chrono::steady_clock::now();
    const Connectivity cx = scene_connectivity(scene);
    CHECK(cx.loops.size() == 2001);
    CHECK(cx.loops[0].simple);
    const auto free = escape_free_patches(scene, cx);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    CHECK(std::all_of(free.begin(), free.end(), [](char c) { return c; }));
    MESSAGE(scene.segments.size() << " segments: " << seconds << " s");
    CHECK(seconds < 10);  // about 0.1 s; a quadratic method would take minutes
}

TEST_CASE("escape_free: timing on a large scene (slow: run with --no-skip)" * doctest::skip()) {
    // FLATRAD_CONNECTIVITY_SCENE=path times a scene file (e.g. from
    // scripts/make-scene 1000000 --density 3); otherwise a 10^6-segment
    // circle room with 10^4 small circles and 5 x 10^5 dashes is built here.
    Scene scene;
    const auto t_read = std::chrono::steady_clock::now();
    if (const char* path = std::getenv("FLATRAD_CONNECTIVITY_SCENE")) {
        scene = load_scene(path);
    } else {
        std::vector<std::string> surfaces = {circle("room", {0, 0}, 1000, 460000, "in")};
        for (int k = 0; k < 10000; ++k)
            surfaces.push_back(circle(named("c", k), {-600 + 12.0 * (k % 100), -600 + 12.0 * (k / 100)}, 1, 4,
                                      "out"));
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<double> U(-600, 600);
        for (int k = 0; k < 500000; ++k) {
            const Vec2 c{U(rng), U(rng)};
            surfaces.push_back(poly(named("d", k), {c, c + Vec2{0.01, 0.01}}, "both"));
        }
        scene = scene_of(surfaces);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const Connectivity cx = scene_connectivity(scene);
    const auto t1 = std::chrono::steady_clock::now();
    const auto free = escape_free_patches(scene, cx);
    const auto t2 = std::chrono::steady_clock::now();
    const auto secs = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    const long proven = std::count(free.begin(), free.end(), 1);
    MESSAGE(scene.segments.size() << " segments, " << scene.patches.size() << " patches, " << cx.objects.size()
                                  << " objects, " << cx.loops.size() << " loops; read " << secs(t_read, t0)
                                  << " s, connectivity " << secs(t0, t1) << " s, escape-free " << secs(t1, t2)
                                  << " s; " << proven << " proven");
}
