// Tests for engine/scene.h: every refusal SPEC.md lists (with the file and
// JSON path the error must name), channel broadcasting, point handling,
// patch numbering and lit sides, and the scenes in data/.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "engine/error.h"
#include "engine/scene.h"

using namespace flatrad;

namespace {

const std::string label = "test/scene.json";

/// A scene around the given surfaces (JSON text of the array's items).
std::string scene_json(const std::string& surfaces,
                       const std::string& materials = R"({"white": {"reflectance": 0.5},
                                                          "lamp": {"emission": 1}})") {
    return R"({"flatrad": 1, "materials": )" + materials + R"(, "surfaces": [)" + surfaces + "]}";
}

const std::string floor_surface = R"({"name": "floor", "material": "white", "points": [[0, 0], [1, 0]]})";

/// A surface with the given shape keys (points/circle/closed/side).
std::string surface(const std::string& shape, const std::string& name = "s") {
    return R"({"name": ")" + name + R"(", "material": "white", )" + shape + "}";
}

std::optional<InputError> refusal(const std::string& text) {
    try {
        parse_scene(text, label);
    } catch (const InputError& e) {
        return e;
    }
    return std::nullopt;
}

}  // namespace

/// The text must be refused with an InputError naming `label` and `json_path`.
#define CHECK_REFUSED(text, json_path)                                  \
    do {                                                                \
        const auto err_ = refusal(text);                                \
        REQUIRE_MESSAGE(err_.has_value(), "accepted: " << (text));     \
        CHECK(err_->file() == label);                                   \
        CHECK_MESSAGE(err_->path() == (json_path), err_->what());      \
    } while (0)

// ---- refusals ---------------------------------------------------------------

TEST_CASE("scene: malformed JSON names line and column") {
    const auto err = refusal("{\"flatrad\": 1,\n  \"materials\": {,}\n}");
    REQUIRE(err);
    CHECK(err->file() == label);
    CHECK(err->path() == "");
    CHECK(err->message().find("malformed JSON at line 2, column 17") != std::string::npos);
    CHECK(err->message().find("unexpected ','") != std::string::npos);

    CHECK_REFUSED("", "");
    CHECK_REFUSED("{\"flatrad\": 1", "");
    CHECK_REFUSED(R"({"flatrad": NaN})", "");
    CHECK_REFUSED(R"({"flatrad": Infinity})", "");
}

TEST_CASE("scene: the top level must be an object") {
    CHECK_REFUSED("[1, 2]", "");
    CHECK_REFUSED("1", "");
}

TEST_CASE("scene: a repeated key is refused where it repeats") {
    CHECK_REFUSED(R"({"flatrad": 1, "flatrad": 1, "materials": {}, "surfaces": []})", "flatrad");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": 0.5}, "white": {}})"), "materials.white");
    CHECK_REFUSED(scene_json(floor_surface + ", " +
                             R"({"name": "b", "material": "white", "points": [[0, 1], [1, 1]], "side": "left",
                                 "side": "right"})"),
                  "surfaces[1].side");
    // Objects with many keys are tested with a hash set (beyond 8 keys):
    // the repeat is still named where it repeats, however far apart.
    std::string many;
    for (int k = 0; k < 40; ++k) many += R"(, "extra)" + std::to_string(k) + R"(": )" + std::to_string(k);
    CHECK_NOTHROW(parse_scene(R"({"flatrad": 1)" + many + R"(, "materials": {"white": {}}, "surfaces": [)" +
                                  floor_surface + "]}",
                              label));
    CHECK_REFUSED(R"({"flatrad": 1)" + many + R"(, "extra3": 0, "materials": {}, "surfaces": []})", "extra3");
    CHECK_REFUSED(R"({"flatrad": 1)" + many + R"(, "flatrad": 1, "materials": {}, "surfaces": []})", "flatrad");
    std::string materials;
    for (int k = 0; k < 30; ++k) materials += (k ? ", " : "") + std::string(R"("m)") + std::to_string(k) + R"(": {})";
    CHECK_REFUSED(scene_json(floor_surface, "{" + materials + R"(, "m12": {"reflectance": 0.5}})"), "materials.m12");
    CHECK_REFUSED(scene_json(floor_surface + ", " + surface(R"("points": [[0, 1], [1, 1]])" + many + ", " +
                                                            R"("extra39": 1)",
                                                            "b")),
                  "surfaces[1].extra39");
}

TEST_CASE("scene: missing required keys") {
    CHECK_REFUSED(R"({"materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}", "flatrad");
    CHECK_REFUSED(R"({"flatrad": 1, "surfaces": [)" + floor_surface + "]}", "materials");
    CHECK_REFUSED(R"({"flatrad": 1, "materials": {"white": {}}})", "surfaces");
    CHECK_REFUSED(scene_json(R"({"material": "white", "points": [[0, 0], [1, 0]]})"), "surfaces[0].name");
    CHECK_REFUSED(scene_json(R"({"name": "a", "points": [[0, 0], [1, 0]]})"), "surfaces[0].material");
    CHECK_REFUSED(scene_json(floor_surface + R"(, {"name": "a", "material": "white"})"), "surfaces[1].points");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"radius": 1, "segments": 8}, "side": "in")")),
                  "surfaces[0].circle.center");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "segments": 8}, "side": "in")")),
                  "surfaces[0].circle.radius");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "radius": 1}, "side": "in")")),
                  "surfaces[0].circle.segments");
}

TEST_CASE("scene: flatrad must be 1") {
    CHECK_REFUSED(R"({"flatrad": 2, "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}", "flatrad");
    CHECK_REFUSED(R"({"flatrad": "1", "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}", "flatrad");
    CHECK_REFUSED(R"({"flatrad": 0.5, "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}", "flatrad");
    // 1.0 is the number 1.
    CHECK_NOTHROW(parse_scene(R"({"flatrad": 1.0, "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}",
                              label));
}

TEST_CASE("scene: unknown material") {
    const auto err = refusal(scene_json(R"({"name": "a", "material": "chrome", "points": [[0, 0], [1, 0]]})"));
    REQUIRE(err);
    CHECK(err->path() == "surfaces[0].material");
    CHECK(err->message().find("chrome") != std::string::npos);
    CHECK(err->message().find("white") != std::string::npos);  // lists the known ones
}

TEST_CASE("scene: duplicate surface name") {
    CHECK_REFUSED(scene_json(floor_surface + ", " + floor_surface), "surfaces[1].name");
}

TEST_CASE("scene: empty surfaces") {
    CHECK_REFUSED(scene_json(""), "surfaces");
}

TEST_CASE("scene: non-finite numbers") {
    // 1e999 overflows a double: refused with the path of the number itself.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1e999, 0]])")), "surfaces[0].points[1][0]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, -1e999]])")), "surfaces[0].points[1][1]");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": 1e400}})"), "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"emission": [1, 1e999, 1]}})"),
                  "materials.white.emission[1]");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "radius": 1e999, "segments": 8},
                                        "side": "in")")),
                  "surfaces[0].circle.radius");
    // Finite but so large that squared lengths would overflow.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1e200, 0]])")), "surfaces[0].points[1]");
}

TEST_CASE("scene: reflectance outside [0, 1]") {
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": 1.5}})"), "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": -0.1}})"), "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": [0.5, 1.01, 0.5]}})"),
                  "materials.white.reflectance[1]");
    // Unused materials are checked too.
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {}, "red": {"reflectance": [0.7, 0.1, -1]}})"),
                  "materials.red.reflectance[2]");
}

TEST_CASE("scene: negative emission") {
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"emission": -1}})"), "materials.white.emission");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"emission": [1, 2, -0.5]}})"),
                  "materials.white.emission[2]");
}

TEST_CASE("scene: mismatched channel counts") {
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": [0.5, 0.5, 0.5], "emission": [1]}})"),
                  "materials.white.emission");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": [0.5]}, "red": {"emission": [1, 1, 1]}})"),
                  "materials.red.emission");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": [0.5, 0.5]}})"),
                  "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": []}})"), "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": [1, 1, 1, 1]}})"),
                  "materials.white.reflectance");
}

TEST_CASE("scene: zero-length segments") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 0], [2, 0]])")), "surfaces[0].points[2]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [0, 0]])")), "surfaces[0].points[1]");
    // Closed: one closing repeat is dropped; a second one leaves a zero-length
    // closing segment.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1], [0, 0], [0, 0]], "closed": true,
                                        "side": "both")")),
                  "surfaces[0].points[3]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 0], [1, 1]], "closed": true,
                                        "side": "in")")),
                  "surfaces[0].points[2]");
    // Distinct points whose difference underflows to a zero length.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1e-320, 0]])")), "surfaces[0].points[1]");
}

TEST_CASE("scene: a closed shape needs a side") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1]], "closed": true)")),
                  "surfaces[0].side");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "radius": 1, "segments": 8})")),
                  "surfaces[0].side");
}

TEST_CASE("scene: side must match open or closed") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "side": "in")")), "surfaces[0].side");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "side": "out")")), "surfaces[0].side");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1]], "closed": true, "side": "left")")),
                  "surfaces[0].side");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "radius": 1, "segments": 8},
                                        "side": "right")")),
                  "surfaces[0].side");
}

TEST_CASE("scene: unknown side word") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "side": "up")")), "surfaces[0].side");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "side": "Left")")), "surfaces[0].side");
}

TEST_CASE("scene: too few points") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0]])")), "surfaces[0].points");
    CHECK_REFUSED(scene_json(surface(R"("points": [])")), "surfaces[0].points");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "closed": true, "side": "both")")),
                  "surfaces[0].points");
    // Three points of which the last repeats the first: two after dropping it.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [0, 0]], "closed": true, "side": "in")")),
                  "surfaces[0].points");
}

TEST_CASE("scene: zero area with side in or out") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [2, 0]], "closed": true, "side": "in")")),
                  "surfaces[0].points");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 1], [1, 0], [0, 1]], "closed": true,
                                        "side": "out")")),
                  "surfaces[0].points");
    // "both" needs no area: a thin closed shape is still a set of blocking
    // segments...
    CHECK_NOTHROW(parse_scene(scene_json(surface(R"("points": [[0, 0], [1, 0], [2, 0.5]], "closed": true,
                                                    "side": "both")")),
                              label));
    // ... but a flat one lies on itself (its closing segment covers the
    // others): refused as overlapping segments, naming the closing one.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [2, 0]], "closed": true, "side": "both")")),
                  "surfaces[0].points[2]");
}

TEST_CASE("scene: a self-crossing polygon with side in or out") {
    // An asymmetric bow tie: non-zero area, crossing itself.
    const std::string bow_tie = R"("points": [[0, 0], [2, 2], [2, 0], [0, 1]], "closed": true)";
    const auto err = refusal(scene_json(surface(bow_tie + R"(, "side": "in")")));
    REQUIRE(err);
    CHECK(err->path() == "surfaces[0].points");
    CHECK(err->message().find("segment 0") != std::string::npos);
    CHECK(err->message().find("segment 2") != std::string::npos);
    CHECK_REFUSED(scene_json(surface(bow_tie + R"(, "side": "out")")), "surfaces[0].points");
    CHECK_NOTHROW(parse_scene(scene_json(surface(bow_tie + R"(, "side": "both")")), label));

    // Touching: a vertex on a non-neighbouring edge.
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [4, 0], [4, 4], [2, 0], [0, 4]], "closed": true,
                                        "side": "in")")),
                  "surfaces[0].points");
    // Folding back along a neighbouring edge (a spike).
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [4, 0], [4, 4], [4, 2], [0, 4]], "closed": true,
                                        "side": "in")")),
                  "surfaces[0].points");
    // A concave (but simple) polygon is fine.
    CHECK_NOTHROW(parse_scene(scene_json(surface(R"("points": [[0, 0], [4, 0], [4, 4], [2, 1], [0, 4]],
                                                    "closed": true, "side": "in")")),
                              label));
}

TEST_CASE("scene: bad circles") {
    const auto circle = [](const std::string& body) {
        return scene_json(surface(R"("circle": {)" + body + R"(}, "side": "out")"));
    };
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": 0, "segments": 8)"), "surfaces[0].circle.radius");
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": -1, "segments": 8)"), "surfaces[0].circle.radius");
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": 1, "segments": 2)"), "surfaces[0].circle.segments");
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": 1, "segments": 3.5)"), "surfaces[0].circle.segments");
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": 1, "segments": "8")"), "surfaces[0].circle.segments");
    CHECK_REFUSED(circle(R"("center": [0, 0], "radius": 1, "segments": 1e12)"), "surfaces[0].circle.segments");
    CHECK_REFUSED(circle(R"("center": [0], "radius": 1, "segments": 8)"), "surfaces[0].circle.center");
    CHECK_REFUSED(circle(R"("center": [1e6, 0], "radius": 1e-15, "segments": 64)"), "surfaces[0].circle");
    CHECK_REFUSED(scene_json(surface(R"("circle": [0, 0, 1], "side": "out")")), "surfaces[0].circle");
    CHECK_REFUSED(scene_json(surface(R"("circle": {"center": [0, 0], "radius": 1, "segments": 8},
                                        "closed": false, "side": "out")")),
                  "surfaces[0].closed");
    // 8.0 is a whole number.
    CHECK_NOTHROW(parse_scene(circle(R"("center": [0, 0], "radius": 1, "segments": 8.0)"), label));
}

TEST_CASE("scene: both points and circle") {
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]],
                                        "circle": {"center": [0, 0], "radius": 1, "segments": 8}, "side": "in")")),
                  "surfaces[0]");
}

TEST_CASE("scene: wrong JSON types") {
    CHECK_REFUSED(R"({"flatrad": 1, "name": 7, "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}",
                  "name");
    CHECK_REFUSED(R"({"flatrad": 1, "materials": [], "surfaces": [)" + floor_surface + "]}", "materials");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": 0.5})"), "materials.white");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"reflectance": "0.5"}})"), "materials.white.reflectance");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"emission": [1, "2", 3]}})"), "materials.white.emission[1]");
    CHECK_REFUSED(scene_json(floor_surface, R"({"white": {"emission": true}})"), "materials.white.emission");
    CHECK_REFUSED(R"({"flatrad": 1, "materials": {"white": {}}, "surfaces": {}})", "surfaces");
    CHECK_REFUSED(scene_json("[]"), "surfaces[0]");
    CHECK_REFUSED(scene_json(R"({"name": 3, "material": "white", "points": [[0, 0], [1, 0]]})"), "surfaces[0].name");
    CHECK_REFUSED(scene_json(R"({"name": "", "material": "white", "points": [[0, 0], [1, 0]]})"), "surfaces[0].name");
    CHECK_REFUSED(scene_json(R"({"name": "a", "material": ["white"], "points": [[0, 0], [1, 0]]})"),
                  "surfaces[0].material");
    CHECK_REFUSED(scene_json(surface(R"("points": {"x": 0})")), "surfaces[0].points");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0, 0]])")), "surfaces[0].points[1]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, "0"]])")), "surfaces[0].points[1]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], 1, 0])")), "surfaces[0].points[1]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [null, 0]])")), "surfaces[0].points[1]");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1]], "closed": "yes", "side": "in")")),
                  "surfaces[0].closed");
    CHECK_REFUSED(scene_json(surface(R"("points": [[0, 0], [1, 0]], "side": 1)")), "surfaces[0].side");

    // The message says what was expected and what was found.
    const auto err = refusal(scene_json(floor_surface + ", " + surface(R"("points": [[0, 0], [1, "a"]])", "b")));
    REQUIRE(err);
    CHECK(err->path() == "surfaces[1].points[1]");
    CHECK(err->message() == R"(expected [x, y] with finite numbers, found [1, "a"])");
    CHECK(std::string(err->what()) == label + R"(: surfaces[1].points[1]: expected [x, y] with finite numbers, )"
                                              R"(found [1, "a"])");
}

TEST_CASE("scene: unreadable file") {
    const std::string missing = "/nonexistent/flatrad/no_such_scene.json";
    try {
        load_scene(missing);
        FAIL("a missing file was read");
    } catch (const InputError& e) {
        CHECK(e.file() == missing);
        CHECK(e.path() == "");
        CHECK(e.message().find("cannot open") != std::string::npos);
    }
    CHECK_THROWS_AS(load_scene(FLATRAD_DATA_DIR), InputError);  // a directory
}

// ---- what is accepted ---------------------------------------------------------

TEST_CASE("scene: unknown keys are accepted") {
    const Scene s = parse_scene(R"({"flatrad": 1, "author": "x", "materials": {"white": {"gloss": 3}},
        "surfaces": [{"name": "a", "material": "white", "points": [[0, 0], [1, 0]], "tags": ["x"]}]})",
                                label);
    CHECK(s.surfaces.size() == 1);
}

TEST_CASE("scene: channel broadcasting") {
    SUBCASE("numbers only: one channel") {
        const Scene s = parse_scene(scene_json(floor_surface, R"({"white": {"reflectance": 0.5, "emission": 2}})"),
                                    label);
        CHECK(s.channels == 1);
        CHECK(s.materials[0].reflectance == std::vector<double>{0.5});
        CHECK(s.materials[0].emission == std::vector<double>{2});
    }
    SUBCASE("one array of 3 makes every value 3 channels") {
        const Scene s = parse_scene(scene_json(floor_surface, R"({"white": {"reflectance": 0.5},
                                                                   "lamp": {"emission": [1, 2, 3]},
                                                                   "black": {}})"),
                                    label);
        CHECK(s.channels == 3);
        REQUIRE(s.materials.size() == 3);
        // Materials keep the file's order.
        CHECK(s.materials[0].name == "white");
        CHECK(s.materials[1].name == "lamp");
        CHECK(s.materials[2].name == "black");
        CHECK(s.materials[0].reflectance == std::vector<double>{0.5, 0.5, 0.5});
        CHECK(s.materials[0].emission == std::vector<double>{0, 0, 0});
        CHECK(s.materials[1].reflectance == std::vector<double>{0, 0, 0});
        CHECK(s.materials[1].emission == std::vector<double>{1, 2, 3});
        CHECK(s.materials[2].reflectance == std::vector<double>{0, 0, 0});
    }
    SUBCASE("arrays of 1") {
        const Scene s = parse_scene(scene_json(floor_surface, R"({"white": {"reflectance": [0.25], "emission": 4}})"),
                                    label);
        CHECK(s.channels == 1);
        CHECK(s.materials[0].reflectance == std::vector<double>{0.25});
        CHECK(s.materials[0].emission == std::vector<double>{4});
    }
}

TEST_CASE("scene: name and file") {
    CHECK(parse_scene(scene_json(floor_surface), "some/dir/my_room.json").name == "my_room");
    CHECK(parse_scene(scene_json(floor_surface), "some/dir/my_room.json").file == "some/dir/my_room.json");
    const Scene named = parse_scene(R"({"flatrad": 1, "name": "box", "materials": {"white": {}}, "surfaces": [)" +
                                        floor_surface + "]}",
                                    label);
    CHECK(named.name == "box");
}

TEST_CASE("scene: a closing repeat is dropped") {
    const Scene s = parse_scene(
        scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1], [0, 0]], "closed": true, "side": "in")")), label);
    REQUIRE(s.surfaces.size() == 1);
    CHECK(s.surfaces[0].points.size() == 3);
    CHECK(s.surfaces[0].segment_count == 3);
    CHECK(s.segments.size() == 3);
    // The closing segment runs from the last kept point back to the first.
    CHECK(s.segments[2].seg.a == Vec2{1, 1});
    CHECK(s.segments[2].seg.b == Vec2{0, 0});
    CHECK(s.segments[2].index == 2);

    // An open polyline keeps a last point equal to the first.
    const Scene open = parse_scene(scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1], [0, 0]])")), label);
    CHECK(open.surfaces[0].points.size() == 4);
    CHECK(open.segments.size() == 3);
}

TEST_CASE("scene: patch numbering for open surfaces") {
    const Scene s = parse_scene(scene_json(surface(R"("points": [[0, 0], [1, 0], [2, 0]], "side": "left")", "a") +
                                           ", " + surface(R"("points": [[0, 1], [1, 1]], "side": "right")", "b") +
                                           ", " + surface(R"("points": [[0, 2], [1, 2], [1, 3]], "side": "both")", "c") +
                                           ", " + surface(R"("points": [[5, 5], [6, 5]])", "d")),
                                label);
    REQUIRE(s.segments.size() == 6);
    REQUIRE(s.patches.size() == 8);
    CHECK(s.surfaces[2].first_segment == 3);
    CHECK(s.surfaces[2].segment_count == 2);
    CHECK(s.surfaces[3].side == Side::Left);  // the default

    struct Expected {
        int segment, surface;
        bool lit_left;
        Side side;
    };
    const Expected expected[] = {{0, 0, true, Side::Left},  {1, 0, true, Side::Left},  {2, 1, false, Side::Right},
                                 {3, 2, true, Side::Left},  {3, 2, false, Side::Right}, {4, 2, true, Side::Left},
                                 {4, 2, false, Side::Right}, {5, 3, true, Side::Left}};
    for (size_t p = 0; p < s.patches.size(); ++p) {
        CAPTURE(p);
        CHECK(s.patches[p].segment == expected[p].segment);
        CHECK(s.patches[p].surface == expected[p].surface);
        CHECK(s.patches[p].lit_left == expected[p].lit_left);
        CHECK(s.patches[p].side == expected[p].side);
        CHECK(s.patches[p].material == 0);
    }
    CHECK(s.patches[0].length == doctest::Approx(1));
    CHECK(s.segments[2].lit_left == false);
    CHECK(s.segments[2].lit_right == true);
    CHECK(s.segments[3].lit_left);
    CHECK(s.segments[3].lit_right);

    // A right-lit patch is the segment reversed (lit side on its left).
    const Segment oriented = s.patch_segment(2);
    CHECK(oriented.a == Vec2{1, 1});
    CHECK(oriented.b == Vec2{0, 1});
}

namespace {

/// Mean of a polygon's vertices: inside a convex polygon.
Vec2 vertex_mean(const std::vector<Vec2>& points) {
    Vec2 sum;
    for (Vec2 p : points) sum += p;
    return sum / static_cast<double>(points.size());
}

/// Every patch of surface 0 (convex) faces the interior when `in` is true.
void check_patches_face(const Scene& s, bool inward) {
    const Vec2 inside = vertex_mean(s.surfaces[0].points);
    for (size_t p = 0; p < s.patches.size(); ++p) {
        CAPTURE(p);
        const Segment o = s.patch_segment(static_cast<int>(p));
        const double facing = dot(o.left_normal(), inside - o.midpoint());
        CHECK((inward ? facing > 0 : facing < 0));
        CHECK(s.patches[p].side == (inward ? Side::In : Side::Out));
    }
}

}  // namespace

TEST_CASE("scene: winding decides which side is in") {
    const std::string ccw = R"("points": [[0, 0], [2, 0], [2, 1], [0, 1]], "closed": true)";
    const std::string cw = R"("points": [[0, 0], [0, 1], [2, 1], [2, 0]], "closed": true)";
    for (const std::string& shape : {ccw, cw}) {
        CAPTURE(shape);
        const bool is_ccw = shape == ccw;
        const Scene in = parse_scene(scene_json(surface(shape + R"(, "side": "in")")), label);
        REQUIRE(in.patches.size() == 4);
        check_patches_face(in, true);
        CHECK(in.patches[0].lit_left == is_ccw);
        CHECK(in.segments[0].lit_left == is_ccw);
        CHECK(in.segments[0].lit_right == !is_ccw);

        const Scene out = parse_scene(scene_json(surface(shape + R"(, "side": "out")")), label);
        REQUIRE(out.patches.size() == 4);
        check_patches_face(out, false);
        CHECK(out.patches[0].lit_left == !is_ccw);
    }
}

TEST_CASE("scene: a closed both surface numbers its in patch first") {
    SUBCASE("counter-clockwise: in is left") {
        const Scene s = parse_scene(
            scene_json(surface(R"("points": [[0, 0], [1, 0], [1, 1]], "closed": true, "side": "both")")), label);
        REQUIRE(s.patches.size() == 6);
        for (size_t k = 0; k < 3; ++k) {
            CHECK(s.patches[2 * k].segment == static_cast<int>(k));
            CHECK(s.patches[2 * k].side == Side::In);
            CHECK(s.patches[2 * k].lit_left);
            CHECK(s.patches[2 * k + 1].segment == static_cast<int>(k));
            CHECK(s.patches[2 * k + 1].side == Side::Out);
            CHECK_FALSE(s.patches[2 * k + 1].lit_left);
        }
    }
    SUBCASE("clockwise: in is right") {
        const Scene s = parse_scene(
            scene_json(surface(R"("points": [[0, 0], [1, 1], [1, 0]], "closed": true, "side": "both")")), label);
        REQUIRE(s.patches.size() == 6);
        for (size_t k = 0; k < 3; ++k) {
            CHECK(s.patches[2 * k].side == Side::In);
            CHECK_FALSE(s.patches[2 * k].lit_left);
            CHECK(s.patches[2 * k + 1].side == Side::Out);
            CHECK(s.patches[2 * k + 1].lit_left);
        }
        // The in patch faces the triangle's inside.
        const Vec2 inside = vertex_mean(s.surfaces[0].points);
        const Segment o = s.patch_segment(0);
        CHECK(dot(o.left_normal(), inside - o.midpoint()) > 0);
    }
}

TEST_CASE("scene: circle points and patches") {
    constexpr double trig_tol = 1e-15;  // one cos/sin and a multiply-add: a few ulps of r
    const Scene s = parse_scene(scene_json(surface(R"("circle": {"center": [2, 1], "radius": 0.5, "segments": 8},
                                                      "side": "out")",
                                                   "pillar") +
                                           ", " + surface(R"("circle": {"center": [0, 0], "radius": 3, "segments": 6},
                                                               "side": "both")",
                                                          "ring")),
                                label);
    const Surface& c = s.surfaces[0];
    CHECK(c.is_circle);
    CHECK(c.closed);
    REQUIRE(c.points.size() == 8);
    for (int k = 0; k < 8; ++k) {
        CAPTURE(k);
        const double angle = 2 * std::numbers::pi * k / 8;
        const Vec2 p = c.points[static_cast<size_t>(k)];
        CHECK(p.x == doctest::Approx(2 + 0.5 * std::cos(angle)).epsilon(trig_tol));
        CHECK(p.y == doctest::Approx(1 + 0.5 * std::sin(angle)).epsilon(trig_tol));
    }
    CHECK(c.points[0] == Vec2{2.5, 1});  // quarter turns are exact
    CHECK(c.points[2] == Vec2{2, 1.5});
    CHECK(c.points[4] == Vec2{1.5, 1});
    CHECK(c.points[6] == Vec2{2, 0.5});

    // Counter-clockwise, so out is the right of travel; closing segment last.
    REQUIRE(s.surfaces[0].segment_count == 8);
    CHECK(s.segments[7].seg.a == c.points[7]);
    CHECK(s.segments[7].seg.b == c.points[0]);
    for (int p = 0; p < 8; ++p) {
        CHECK(s.patches[static_cast<size_t>(p)].segment == p);
        CHECK_FALSE(s.patches[static_cast<size_t>(p)].lit_left);
        CHECK(s.patches[static_cast<size_t>(p)].side == Side::Out);
        const Segment o = s.patch_segment(p);
        CHECK(dot(o.left_normal(), o.midpoint() - Vec2{2, 1}) > 0);  // faces away from the center
    }
    // Chord length 2 r sin(pi / n).
    CHECK(s.patches[0].length == doctest::Approx(2 * 0.5 * std::sin(std::numbers::pi / 8)));

    // The "both" ring: per segment in (left) then out (right).
    REQUIRE(s.patches.size() == 8 + 12);
    CHECK(s.surfaces[1].first_segment == 8);
    for (int k = 0; k < 6; ++k) {
        const Patch& in = s.patches[static_cast<size_t>(8 + 2 * k)];
        const Patch& out = s.patches[static_cast<size_t>(8 + 2 * k + 1)];
        CHECK(in.segment == 8 + k);
        CHECK(in.side == Side::In);
        CHECK(in.lit_left);
        CHECK(out.segment == 8 + k);
        CHECK(out.side == Side::Out);
        CHECK_FALSE(out.lit_left);
    }
}

TEST_CASE("scene: helpers") {
    const Scene s = parse_scene(scene_json(surface(R"("points": [[-1, 0], [2, 0]])", "a") + ", " +
                                           surface(R"("points": [[0, 4], [1, 4], [1, 3]])", "b")),
                                label);
    CHECK(s.find_surface("a") == 0);
    CHECK(s.find_surface("b") == 1);
    CHECK(s.find_surface("c") == -1);
    CHECK(s.extent() == doctest::Approx(5));  // box [-1, 2] x [0, 4]
    const std::vector<Segment> g = s.segment_geometry();
    REQUIRE(g.size() == 3);
    CHECK(g[2].a == Vec2{1, 4});
    CHECK(g[2].b == Vec2{1, 3});
    CHECK(std::string(side_name(Side::Left)) == "left");
    CHECK(std::string(side_name(Side::Right)) == "right");
    CHECK(std::string(side_name(Side::Both)) == "both");
    CHECK(std::string(side_name(Side::In)) == "in");
    CHECK(std::string(side_name(Side::Out)) == "out");
}

TEST_CASE("scene: a large simple polygon passes the crossing check") {
    // A 5000-point star-shaped (simple, concave) polygon: exercises the sweep.
    constexpr int n = 5000;
    std::string points;
    for (int k = 0; k < n; ++k) {
        const double angle = 2 * std::numbers::pi * k / n;
        const double r = k % 2 ? 1.0 : 0.8;
        points += (k ? ", " : "") + std::string("[") + std::to_string(r * std::cos(angle)) + ", " +
                  std::to_string(r * std::sin(angle)) + "]";
    }
    const Scene s =
        parse_scene(scene_json(surface(R"("points": [)" + points + R"(], "closed": true, "side": "in")")), label);
    CHECK(s.patches.size() == n);
    CHECK(s.patches[0].lit_left);  // counter-clockwise
}

// ---- the data directory ---------------------------------------------------------

TEST_CASE("scene: data/default.json") {
    const Scene s = load_scene(std::string(FLATRAD_DATA_DIR) + "/default.json");
    CHECK(s.channels == 3);
    CHECK(s.segments.size() >= 30);
    CHECK(s.segments.size() <= 60);
    const int lamp = s.find_surface("lamp");
    REQUIRE(lamp >= 0);
    // The lamp shines down.
    int lamp_patches = 0;
    for (size_t p = 0; p < s.patches.size(); ++p) {
        if (s.patches[p].surface != lamp) continue;
        ++lamp_patches;
        CHECK(s.patch_segment(static_cast<int>(p)).left_normal().y == doctest::Approx(-1));
    }
    CHECK(lamp_patches == 1);
    // The room is lit inside: its floor patch faces up.
    CHECK(s.patch_segment(0).left_normal().y == doctest::Approx(1));
}

TEST_CASE("scene: every data/*.json parses") {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(FLATRAD_DATA_DIR)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".json") continue;
        CAPTURE(entry.path().string());
        Scene s;
        CHECK_NOTHROW(s = load_scene(entry.path().string()));
        CHECK(!s.patches.empty());
        CHECK(s.warnings.empty());  // our own scenes use only keys the reader knows
        ++count;
    }
    CHECK(count >= 1);
}

TEST_CASE("scene: unknown keys are read past and said, with the key likely meant") {
    // A misspelt key would otherwise change the answer without a word (a
    // lamp whose "emision" is ignored is dark). Nothing is refused: the
    // scene is the one without the unknown keys.
    const std::string clean = R"({"flatrad": 1, "description": "known: free text",
        "materials": {"white": {"reflectance": 0.5}, "lamp": {"emission": 1}},
        "surfaces": [{"name": "room", "material": "white", "circle": {"center": [0, 0], "radius": 1, "segments": 8}, "side": "in"},
                     {"name": "lamp", "material": "lamp", "points": [[0, 0], [0.1, 0]], "side": "both"}]})";
    const Scene a = parse_scene(clean, label);
    CHECK(a.warnings.empty());
    const std::string typos = R"({"flatrad": 1, "comment": 1,
        "materials": {"white": {"reflectance": 0.5, "Reflectence": 2}, "lamp": {"emission": 1, "emision": 5}},
        "surfaces": [{"name": "room", "material": "white", "circle": {"center": [0, 0], "radius": 1, "segments": 8, "radious": 3}, "side": "in", "sides": "out"},
                     {"name": "lamp", "material": "lamp", "points": [[0, 0], [0.1, 0]], "side": "both", "xyz": []}]})";
    const Scene b = parse_scene(typos, label);
    const std::vector<std::string> want = {
        "comment: unknown key, ignored",
        "materials.white.Reflectence: unknown key, ignored (did you mean \"reflectance\"?)",
        "materials.lamp.emision: unknown key, ignored (did you mean \"emission\"?)",
        "surfaces[0].circle.radious: unknown key, ignored (did you mean \"radius\"?)",
        "surfaces[0].sides: unknown key, ignored (did you mean \"side\"?)",
        "surfaces[1].xyz: unknown key, ignored",
    };
    CHECK(b.warnings.size() == want.size());
    for (const std::string& w : want) {
        CAPTURE(w);
        CHECK(std::find(b.warnings.begin(), b.warnings.end(), w) != b.warnings.end());
    }
    // The same scene as without them.
    REQUIRE(a.patches.size() == b.patches.size());
    REQUIRE(a.materials.size() == b.materials.size());
    for (size_t m = 0; m < a.materials.size(); ++m) {
        CHECK(a.materials[m].reflectance == b.materials[m].reflectance);
        CHECK(a.materials[m].emission == b.materials[m].emission);
    }
    for (size_t s = 0; s < a.segments.size(); ++s) {
        CHECK(a.segments[s].seg.a == b.segments[s].seg.a);
        CHECK(a.segments[s].seg.b == b.segments[s].seg.b);
    }
}

TEST_CASE("scene: unknown keys past ten are counted, not listed") {
    std::string surfaces;
    const int n = 25;
    for (int k = 0; k < n; ++k)
        surfaces += fmt::format(R"({}{{"name": "s{}", "material": "white", "points": [[{}, 0], [{}, 1]], "colour": 1}})",
                                k == 0 ? "" : ",", k, k, k);
    const Scene s = parse_scene(scene_json(surfaces), label);
    REQUIRE(s.warnings.size() == max_scene_warnings + 1);
    CHECK(s.warnings.front() == "surfaces[0].colour: unknown key, ignored");
    CHECK(s.warnings.back() == fmt::format("and {} more unknown keys, ignored", n - static_cast<int>(max_scene_warnings)));
    // At the boundary: ten are all listed, the eleventh is "1 more".
    for (const int m : {10, 11}) {
        CAPTURE(m);
        std::string some;
        for (int k = 0; k < m; ++k)
            some += fmt::format(R"({}{{"name": "s{}", "material": "white", "points": [[{}, 0], [{}, 1]], "colour": 1}})",
                                k == 0 ? "" : ",", k, k, k);
        const Scene t = parse_scene(scene_json(some), label);
        CHECK(t.warnings.size() == max_scene_warnings + (m > 10 ? 1 : 0));
        if (m == 11) CHECK(t.warnings.back() == "and 1 more unknown key, ignored");
    }
}

TEST_CASE("scene: an unknown key is shown on one line, and short keys are not over-corrected") {
    const Scene s = parse_scene(R"({"flatrad": 1, "note": 1, "a\nwarning: forged": 2,
        "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}", label);
    REQUIRE(s.warnings.size() == 2);
    CHECK(s.warnings[0] == "note: unknown key, ignored");  // not "did you mean name": two edits of four letters
    CHECK(s.warnings[1] == "a\\nwarning: forged: unknown key, ignored");
    for (const std::string& w : s.warnings) CHECK(w.find('\n') == std::string::npos);
}

TEST_CASE("scene: a missing required key names a close misspelling") {
    const auto near = [](const std::string& text) {
        const auto err = refusal(text);
        REQUIRE(err);
        return err->path() + ": " + err->message();
    };
    CHECK(near(scene_json(R"({"name": "a", "materail": "white", "points": [[0, 0], [1, 0]]})")) ==
          "surfaces[0].material: missing required key (found \"materail\": misspelt?)");
    CHECK(near(scene_json(R"({"name": "a", "material": "white", "circle": {"center": [0, 0], "radious": 1, "segments": 8}, "side": "in"})")) ==
          "surfaces[0].circle.radius: missing required key (found \"radious\": misspelt?)");
    CHECK(near(scene_json(R"({"name": "a", "material": "white", "closed": true, "sid": "in", "points": [[0, 0], [1, 0], [0, 1]]})")) ==
          "surfaces[0].side: missing required key (a closed shape needs \"side\": \"in\", \"out\" or \"both\") (found \"sid\": misspelt?)");
    CHECK(near(scene_json(R"({"name": "a", "material": "white", "point": [[0, 0], [1, 0]]})")) ==
          "surfaces[0].points: missing required key (a surface needs \"points\" or \"circle\") (found \"point\": misspelt?)");
    // Nothing close: the plain message.
    CHECK(near(scene_json(R"({"name": "a", "colour": "white", "points": [[0, 0], [1, 0]]})")) ==
          "surfaces[0].material: missing required key");
}

TEST_CASE("scene: a description must be text") {
    CHECK_REFUSED(R"({"flatrad": 1, "description": 5, "materials": {"white": {}}, "surfaces": [)" + floor_surface + "]}",
                  "description");
}
