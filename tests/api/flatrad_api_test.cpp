// The embedding API (include/flatrad/flatrad.h, api/flatrad_api.cpp):
// SceneBuilder against the same scene read from a file, errors with their
// JSON paths, option checks, form factors. Uses only the public header, as
// an embedding program would.
#include <flatrad/flatrad.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

namespace api = flatrad::api;

namespace {

constexpr double analytic_tol = 1e-14;  // a few sqrt and sums: ~50 ulps

/// Expects build() / f() to throw api::InputError at `path`.
template <class F>
void check_input_error(F&& f, const std::string& file, const std::string& path) {
    try {
        f();
        FAIL("expected InputError at " << path);
    } catch (const api::InputError& e) {
        CHECK(e.file() == file);
        CHECK(e.path() == path);
        CHECK(std::string(e.what()).find(path) != std::string::npos);
    }
}

/// data/closed_box.json, built in code.
api::SceneBuilder closed_box() {
    api::SceneBuilder b("closed unit box, one emissive wall", "box.json");
    b.add_material("white", {0.5})
        .add_material("lamp", {0.0}, {1.0})
        .add_polyline("floor", "lamp", {{0, 0}, {1, 0}}, api::Side::Left)
        .add_polyline("walls", "white", {{1, 0}, {1, 1}, {0, 1}, {0, 0}}, api::Side::Left);
    return b;
}

}  // namespace

TEST_CASE("api: a built scene solves exactly like the same scene read from its file") {
    const api::Scene built = closed_box().build();
    const api::Scene read = api::load_scene(std::string(FLATRAD_DATA_DIR) + "/closed_box.json");
    REQUIRE(built.patch_count() == 4);
    REQUIRE(read.patch_count() == 4);
    CHECK(built.channels() == 1);
    CHECK(built.segment_count() == 4);
    CHECK(built.surface_names() == std::vector<std::string>{"floor", "walls"});
    CHECK(built.warnings().empty());
    CHECK(read.warnings().empty());

    api::SolveOptions options;
    options.method = api::Method::Exact;
    options.subdivide = 3;
    const api::Result a = api::solve(built, options);
    const api::Result b = api::solve(read, options);
    CHECK(a.method == "exact");
    CHECK(a.elements == 12);
    REQUIRE(a.patch_count() == b.patch_count());
    for (std::size_t p = 0; p < a.patch_count(); ++p) {
        CHECK(a.patches[p].surface == b.patches[p].surface);
        CHECK(a.patches[p].segment == b.patches[p].segment);
        CHECK(a.patches[p].radiosity == b.patches[p].radiosity);  // same input, same bits
    }
    CHECK(a.patches[0].surface == "floor");
    CHECK(a.patches[0].radiosity.at(0) == doctest::Approx(1.0));  // reflectance 0: B = E
    CHECK(a.patches[3].surface == "walls");
    CHECK(a.patches[3].segment == 2);
    CHECK(a.patches[3].a.x == 0.0);
    CHECK(a.patches[3].a.y == 1.0);
    CHECK(a.patches[3].length == 1.0);
    // Closed and lamp-absorbing: all emitted power is absorbed.
    CHECK(a.emitted.at(0) == doctest::Approx(1.0));
    CHECK(a.absorbed.at(0) == doctest::Approx(1.0));
    CHECK(std::abs(a.balance.at(0)) < 1e-12);
}

TEST_CASE("api: polygons, circles, three channels and the hierarchical solver") {
    api::SceneBuilder b("room");
    b.add_material("white", {0.7, 0.6, 0.5})
        .add_material("lamp", {}, {3.0})
        .add_polygon("room", "white", {{0, 0}, {4, 0}, {4, 3}, {0, 3}, {0, 0}}, api::Side::In)
        .add_polyline("lamp", "lamp", {{1.5, 2.9}, {2.5, 2.9}}, api::Side::Right)
        .add_circle("pillar", "white", {2, 1}, 0.3, 12, api::Side::Out);
    const api::Scene scene = b.build();
    CHECK(scene.name() == "room");
    CHECK(scene.channels() == 3);
    CHECK(scene.patch_count() == 4 + 1 + 12);

    api::SolveOptions options;
    options.method = api::Method::Hierarchical;
    // 1e-3: the clustered solver's energy error on this closed room is
    // 6.8e-2 at eps 1e-2 and 4e-3 at 1e-3 (README, "Hierarchical").
    options.eps = 1e-3;
    const api::Result h = api::solve(scene, options);
    CHECK(h.method == "hierarchical");
    CHECK(h.refined_to_eps);  // (Result's own default is false)
    CHECK(h.patch_count() == scene.patch_count());
    CHECK(h.patches[4].side == api::Side::Right);
    CHECK(h.patches[5].side == api::Side::Out);
    api::SolveOptions exact_options;
    exact_options.method = api::Method::Exact;
    const api::Result e = api::solve(scene, exact_options);
    CHECK(e.refined_to_eps);
    for (int c = 0; c < 3; ++c) {
        const auto k = static_cast<std::size_t>(c);
        CHECK(h.emitted[k] == doctest::Approx(e.emitted[k]));
        CHECK(h.absorbed[k] == doctest::Approx(e.absorbed[k]).epsilon(0.02));
    }
}

TEST_CASE("api: bad scenes are refused at build() with the JSON path a file would have") {
    check_input_error([] { api::SceneBuilder("s", "b").add_material("m", {1.5}).build(); }, "b",
                      "materials.m.reflectance");
    check_input_error([] { api::SceneBuilder("s", "b").add_material("m", {0.5}).add_material("m", {0.2}).build(); },
                      "b", "materials.m");
    check_input_error(
        [] {
            api::SceneBuilder("s", "b")
                .add_material("m", {0.5})
                .add_polyline("p", "m", {{0, 0}, {1, 0}})
                .add_polyline("q", "m", {{0, 0}, {std::numeric_limits<double>::quiet_NaN(), 1}})
                .build();
        },
        "b", "surfaces[1].points[1]");
    // A closed polygon must say which side is lit, and an open one cannot take "in".
    check_input_error(
        [] {
            api::SceneBuilder("s", "b")
                .add_material("m", {0.5})
                .add_polyline("p", "m", {{0, 0}, {1, 0}}, api::Side::In)
                .build();
        },
        "b", "surfaces[0].side");
    // Building leaves the builder usable: fix it and build again.
    api::SceneBuilder ok("s", "b");
    ok.add_material("m", {0.5}).add_polyline("p", "m", {{0, 0}, {1, 0}});
    CHECK_NOTHROW(ok.build());
    CHECK(ok.to_json().find("\"flatrad\": 1") != std::string::npos);
    CHECK(api::parse_scene(ok.to_json(), "copy").patch_count() == 1);

    check_input_error([] { api::load_scene("/nonexistent/scene.json"); }, "/nonexistent/scene.json", "");
}

TEST_CASE("api: solve options are checked") {
    const api::Scene scene = closed_box().build();
    api::SolveOptions options;
    options.method = api::Method::Exact;
    options.subdivide = 0;
    check_input_error([&] { api::solve(scene, options); }, "box.json", "subdivide");
    options = {};
    options.threads = -1;
    check_input_error([&] { api::solve(scene, options); }, "box.json", "threads");
    options = {};
    options.method = api::Method::Hierarchical;
    options.eps = 0;
    check_input_error([&] { api::solve(scene, options); }, "box.json", "eps");
}

TEST_CASE("api: form factors between groups of surfaces") {
    api::SceneBuilder b("two plates", "plates");
    b.add_material("m", {0.5})
        .add_polyline("bottom", "m", {{0, 0}, {1, 0}}, api::Side::Left)
        .add_polyline("top", "m", {{1, 1}, {0, 1}}, api::Side::Left);
    const api::Scene plates = b.build();
    // Facing unit plates at distance 1: crossed strings give sqrt(2) - 1.
    for (auto method : {api::FormFactorMethod::Exact, api::FormFactorMethod::Unoccluded,
                        api::FormFactorMethod::Multiscale})
        CHECK(api::form_factor(plates, {"bottom"}, {"top"}, method) ==
              doctest::Approx(std::sqrt(2.0) - 1).epsilon(analytic_tol).scale(0));
    check_input_error([&] { api::form_factor(plates, {"nope"}, {"top"}); }, "plates", "from");
    check_input_error([&] { api::form_factor(plates, {"bottom"}, {}); }, "plates", "to");
    check_input_error(
        [&] { api::form_factor(plates, {"bottom"}, {"top"}, api::FormFactorMethod::Multiscale, -1); },
        "plates", "eps");

    // In the closed box the floor sees the walls, and nothing else.
    const api::Scene box = closed_box().build();
    CHECK(api::form_factor(box, {"floor"}, {"walls", "walls"}) == doctest::Approx(1.0).epsilon(1e-12));
}

TEST_CASE("api: a scene's ignored keys are there to show") {
    const api::Scene s = api::parse_scene(R"({"flatrad": 1, "materials": {"lamp": {"emision": 1}},
        "surfaces": [{"name": "a", "material": "lamp", "points": [[0, 0], [1, 0]]}]})", "typo.json");
    REQUIRE(s.warnings().size() == 1);
    CHECK(s.warnings()[0] == "materials.lamp.emision: unknown key, ignored (did you mean \"emission\"?)");
}
