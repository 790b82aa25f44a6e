// Tests apps/cli/cli.h: the `flatrad` command line, driven in-process.
#include "cli/cli.h"
#include "support/cli_run.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using nlohmann::json;

using flatrad::test::is_one_error_line;
using flatrad::test::read_text;
using flatrad::test::Run;
using flatrad::test::run;
using flatrad::test::TempDir;

namespace {





// Two unit segments facing each other at distance 1: the lamp below (its
// left, +y, is lit) and a grey plate above (points right to left, so its
// left side faces down). Crossed strings: F = (2 sqrt 2 - 2) / 2 = sqrt 2 - 1
// both ways.
const char* const two_plates = R"({
  "flatrad": 1, "name": "two plates",
  "materials": { "lamp": { "emission": 1.0 }, "grey": { "reflectance": 0.5 } },
  "surfaces": [
    { "name": "lamp", "material": "lamp", "points": [[0, 0], [1, 0]] },
    { "name": "plate", "material": "grey", "points": [[1, 1], [0, 1]] }
  ]
})";

// A closed room lit from inside by a two-sided lamp: numbering covers a
// closed shape (closing segment last) and a `both` segment (left first).
const char* const lit_room = R"({
  "flatrad": 1, "name": "lit room",
  "materials": { "white": { "reflectance": 0.5 }, "lamp": { "emission": 2.0 } },
  "surfaces": [
    { "name": "room", "material": "white", "points": [[0, 0], [4, 0], [4, 4], [0, 4]],
      "closed": true, "side": "in" },
    { "name": "lamp", "material": "lamp", "points": [[1, 1], [3, 1]], "side": "both" }
  ]
})";

// F of two facing unit plates is sqrt 2 - 1 by a few square roots and sums,
// so about 1e-16 is expected; 1e-12 leaves room for the exact-visibility
// path's sums while any real mistake would be far larger.
constexpr double analytic_tol = 1e-12;
const double sqrt2_minus_1 = std::sqrt(2.0) - 1;

}  // namespace

TEST_CASE("cli: --help describes every command and flag") {
    const Run top = run({"--help"});
    CHECK(top.status == 0);
    CHECK(top.err.empty());
    for (const char* word : {"solve", "formfactor", "compare", "sweep"})
        CHECK_MESSAGE(top.out.find(word) != std::string::npos, word);

    const Run solve = run({"solve", "--help"});
    CHECK(solve.status == 0);
    for (const char* flag : {"SCENE", "--output", "--method", "--eps", "--vis-eps", "--subdivide",
                             "--svg", "--threads", "--quiet"})
        CHECK_MESSAGE(solve.out.find(flag) != std::string::npos, flag);

    const Run ff = run({"formfactor", "--help"});
    CHECK(ff.status == 0);
    for (const char* flag : {"SCENE", "--from", "--to", "--method", "--eps"})
        CHECK_MESSAGE(ff.out.find(flag) != std::string::npos, flag);

    CHECK(run({"compare", "--help"}).status == 0);
    CHECK(run({"sweep", "--help"}).status == 0);
}

TEST_CASE("cli: bad arguments give status 2 and one error line") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    const std::vector<std::vector<std::string>> bad = {
        {},                                          // no command
        {"frobnicate"},                              // unknown command
        {"solve", scene, "--bogus"},                 // unknown flag
        {"solve"},                                   // missing SCENE
        {"solve", scene, "--subdivide", "abc"},      // not a number
        {"solve", scene, "--subdivide", "0"},        // out of range
        {"solve", scene, "--subdivide", "-3"},
        {"solve", scene, "--threads", "-1"},
        {"solve", scene, "--eps", "-1"},
        {"solve", scene, "--method", "magic"},
        {"solve", scene, "-o"},                      // missing value
        {"formfactor", scene, "--from", "lamp"},     // missing --to
        {"formfactor", scene, "--from", "lamp,", "--to", "plate"},  // empty name
        {"formfactor", scene, "--from", "lamp", "--to", "plate", "--method", "magic"},
        {"sweep"},                                   // missing SCENE, --from, --to
        // Tolerances: the one check of every command (cli/tolerance_flag.h).
        {"solve", scene, "--vis-eps", "-1"},
        {"compare", scene, "--vis-eps", "-5"},       // was taken for the default (eps / 10)
        {"compare", scene, "--eps", "0"},
        {"sweep", scene, "--vis-eps", "-1"},
    };
    for (const auto& args : bad) {
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        CAPTURE(joined);
        const Run r = run(args);
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.out.empty());
    }
}

TEST_CASE("cli: solve --method hierarchical runs and records its tolerances") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    const Run h = run({"solve", scene, "--method", "hierarchical", "--eps", "0.001", "--vis-eps", "0.0001",
                       "--quiet"});
    CHECK(h.status == 0);
    CHECK(h.err.empty());
    const json result = json::parse(h.out);
    CHECK(result["method"] == "hierarchical");
    CHECK(result["settings"]["eps"] == 0.001);
    CHECK(result["settings"]["vis_eps"] == 0.0001);
    CHECK(result["patches"].size() > 0);
    CHECK(result["stats"]["elements"].get<long>() >= static_cast<long>(result["patches"].size()));
    // Refined until a round split nothing (stats.refined_to_eps: the
    // hierarchical method's alone).
    CHECK(result["stats"]["refined_to_eps"] == true);
    const json exact = json::parse(run({"solve", scene, "--method", "exact", "--quiet"}).out);
    CHECK_FALSE(exact["stats"].contains("refined_to_eps"));

    // 0 and -1 refused alike, with the bound that holds (> 0, not >= 0).
    for (const char* bad : {"0", "-1"}) {
        const Run r = run({"solve", scene, "--method", "hierarchical", "--eps", bad});
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.err.find("--eps: expected a finite number > 0") != std::string::npos);
    }
    // The exact method ignores --eps: 0 is no error there.
    CHECK(run({"solve", scene, "--method", "exact", "--eps", "0", "--quiet"}).status == 0);
}

TEST_CASE("cli: --svg and compare have landed (no more \"not available yet\")") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    const Run r = run({"solve", scene, "-q", "-o", tmp.path("r.json"), "--svg", tmp.path("x.svg")});
    CHECK(r.status == 0);
    CHECK(fs::exists(tmp.path("x.svg")));
    const Run help = run({"compare", "--help"});
    CHECK(help.status == 0);
    CHECK(help.out.find("not available yet") == std::string::npos);
}

TEST_CASE("cli: bad scene files give status 2 and one line naming file and path") {
    TempDir tmp;
    SUBCASE("missing file") {
        const std::string missing = tmp.path("no_such_scene.json");
        const Run r = run({"solve", missing});
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.err.find("no_such_scene.json") != std::string::npos);
    }
    SUBCASE("reflectance out of range") {
        const std::string bad = tmp.file("bad_reflectance.json", R"({
          "flatrad": 1,
          "materials": { "grey": { "reflectance": 1.5 } },
          "surfaces": [ { "name": "a", "material": "grey", "points": [[0, 0], [1, 0]] } ]
        })");
        for (const char* command : {"solve", "formfactor"}) {
            std::vector<std::string> args = {command, bad};
            if (std::string(command) == "formfactor") args.insert(args.end(), {"--from", "a", "--to", "a"});
            const Run r = run(args);
            CHECK(r.status == 2);
            CHECK(is_one_error_line(r.err));
            CHECK(r.err.rfind("error: " + bad + ": materials.grey.reflectance: ", 0) == 0);
            CHECK(r.out.empty());
        }
    }
    SUBCASE("a closed room of reflectance 1 that nothing absorbs: no unique solution") {
        // Found by the solvers, not the reader: every command that solves
        // refuses it with the one line, the path of the reflectance at
        // fault, and no output (sweep says nothing before it either).
        const std::string white = tmp.file("white.json", R"({
          "flatrad": 1,
          "materials": { "w": { "reflectance": 1, "emission": 1 } },
          "surfaces": [ { "name": "room", "material": "w", "points": [[0, 0], [4, 0], [4, 3], [0, 3]],
                          "closed": true, "side": "in" } ]
        })");
        const std::string out = tmp.path("out.json");
        const std::vector<std::vector<std::string>> commands = {
            {"solve", white, "-o", out},
            {"solve", white, "--method", "exact", "-o", out},
            {"compare", white, "-o", out},
            {"sweep", white, "--eps", "0.1", "--repeat", "1", "-o", out}};
        for (const auto& args : commands) {
            CAPTURE(args[0]);
            CAPTURE(args.size());
            const Run r = run(args);
            CHECK(r.status == 2);
            CHECK(is_one_error_line(r.err));
            CHECK(r.err.rfind("error: " + white + ": materials.w.reflectance: no unique solution", 0) == 0);
            CHECK(r.out.empty());
            CHECK_FALSE(std::filesystem::exists(out));
        }
    }
}

TEST_CASE("cli: a misspelt key is said on stderr, and the scene solved as written") {
    // engine/scene.h, Scene::warnings: one line each, "warning: FILE: PATH:
    // ...", with or without --quiet; the exit status and result as without
    // the key.
    TempDir tmp;
    const std::string typo = tmp.file("typo.json", R"({
      "flatrad": 1,
      "materials": { "lamp": { "emission": 1.0 }, "grey": { "reflectance": 0.5, "emision": 3 } },
      "surfaces": [
        { "name": "lamp", "material": "lamp", "points": [[0, 0], [1, 0]] },
        { "name": "plate", "material": "grey", "points": [[1, 1], [0, 1]] }
      ]
    })");
    const std::string clean = tmp.file("clean.json", two_plates);
    for (const char* quiet : {"-q", "--threads=1"}) {
        CAPTURE(quiet);
        const Run r = run({"solve", typo, "--method", "exact", quiet});
        const Run c = run({"solve", clean, "--method", "exact", quiet});
        CHECK(r.status == 0);
        const std::string line = "warning: " + typo + ": materials.grey.emision: unknown key, ignored (did you mean \"emission\"?)\n";
        CHECK(r.err.rfind(line, 0) == 0);
        CHECK(r.err.find("warning", line.size()) == std::string::npos);  // that one line only
        const json a = json::parse(r.out), b = json::parse(c.out);
        CHECK(a["patches"] == b["patches"]);
        CHECK(c.err.find("warning") == std::string::npos);
    }
}

TEST_CASE("cli: solve writes the SPEC result file to stdout") {
    TempDir tmp;
    const std::string scene = tmp.file("room.json", lit_room);
    const Run r = run({"solve", scene, "--method", "exact", "--subdivide", "3"});
    REQUIRE(r.status == 0);
    const json result = json::parse(r.out);  // stdout is pure JSON
    CHECK(r.err.find("lit room") != std::string::npos);  // summary on stderr

    CHECK(result["flatrad"] == 1);
    CHECK(result["scene"] == "lit room");
    CHECK(result["method"] == "exact");
    CHECK(result["settings"]["subdivide"] == 3);
    CHECK_FALSE(result["settings"].contains("eps"));  // exact ignores it

    // SPEC numbering: room's four segments (closing one last), then the
    // lamp's left patch before its right one.
    struct Expected {
        const char* surface;
        int segment;
        const char* side;
        double ax, ay, bx, by;
    };
    const Expected expected[] = {
        {"room", 0, "in", 0, 0, 4, 0}, {"room", 1, "in", 4, 0, 4, 4}, {"room", 2, "in", 4, 4, 0, 4},
        {"room", 3, "in", 0, 4, 0, 0}, {"lamp", 0, "left", 1, 1, 3, 1}, {"lamp", 0, "right", 1, 1, 3, 1},
    };
    const json& patches = result["patches"];
    REQUIRE(patches.size() == std::size(expected));
    for (std::size_t p = 0; p < patches.size(); ++p) {
        CAPTURE(p);
        const json& patch = patches[p];
        const Expected& e = expected[p];
        CHECK(patch["surface"] == e.surface);
        CHECK(patch["segment"] == e.segment);
        CHECK(patch["side"] == e.side);
        CHECK(patch["a"] == json::array({e.ax, e.ay}));
        CHECK(patch["b"] == json::array({e.bx, e.by}));
        CHECK(patch["length"].get<double>() == doctest::Approx(std::hypot(e.bx - e.ax, e.by - e.ay)));
        CHECK(patch["radiosity"].size() == 1);
        REQUIRE(patch["elements"].size() == 3);
        double t = 0;
        for (const json& element : patch["elements"]) {
            REQUIRE(element.size() == 3);  // [t0, t1, B]
            CHECK(element[0].get<double>() == doctest::Approx(t));
            t = element[1].get<double>();
        }
        CHECK(t == doctest::Approx(1.0));
    }
    for (const char* key : {"emitted", "absorbed", "escaped", "balance"})
        CHECK_MESSAGE(result["totals"][key].size() == 1, key);
    // Both sides of the 2-long lamp emit 2: 8 in all, and the room is closed.
    CHECK(result["totals"]["emitted"][0].get<double>() == doctest::Approx(8.0));
    CHECK(result["totals"]["balance"][0].get<double>() < 1e-9);
    for (const char* key : {"time_s", "elements", "links", "iterations", "residual", "threads",
                            "form_factor_time_s", "linear_solve_time_s", "phases", "visibility"})
        CHECK_MESSAGE(result["stats"].contains(key), key);
    REQUIRE(result["stats"]["phases"].is_array());
    REQUIRE(!result["stats"]["phases"].empty());
    CHECK(result["stats"]["phases"].front()["name"] == "form factors");  // this run is exact
    CHECK(result["stats"]["phases"].back()["name"] == "result");
    CHECK(result["stats"]["elements"] == 18);
    for (const char* key : {"queries", "clusters_visited", "approximated"})
        CHECK_MESSAGE(result["stats"]["visibility"].contains(key), key);
}

TEST_CASE("cli: solve two facing plates matches the analytic radiosity") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    const Run r = run({"solve", scene, "--quiet"});
    REQUIRE(r.status == 0);
    CHECK(r.err.empty());  // --quiet
    const json result = json::parse(r.out);
    // The lamp does not reflect, so B_plate = rho F B_lamp with F = sqrt 2 - 1.
    CHECK(result["patches"][0]["radiosity"][0].get<double>() == doctest::Approx(1.0).epsilon(analytic_tol));
    CHECK(result["patches"][1]["radiosity"][0].get<double>() ==
          doctest::Approx(0.5 * sqrt2_minus_1).epsilon(analytic_tol).scale(0));
}

TEST_CASE("cli: solve -o writes the file atomically") {
    TempDir tmp;
    const std::string scene = tmp.file("room.json", lit_room);
    const std::string result_path = tmp.path("room.result.json");

    SUBCASE("a good solve writes the whole file and no temporary") {
        const Run r = run({"solve", scene, "-o", result_path});
        REQUIRE(r.status == 0);
        CHECK(r.out.empty());
        CHECK(r.err.find("lit room") != std::string::npos);
        CHECK(r.err.find(result_path) != std::string::npos);
        const json result = json::parse(read_text(result_path));
        CHECK(result["patches"].size() == 6);
        for (const auto& entry : fs::directory_iterator(tmp.dir()))
            CHECK_MESSAGE(entry.path().filename().string().find(".tmp") == std::string::npos,
                          entry.path().string());
    }
    SUBCASE("a failed run leaves an existing file as it was") {
        tmp.file("room.result.json", "old");
        const std::string bad = tmp.file("bad.json", R"({"flatrad": 1, "materials": {}, "surfaces": [)");
        const Run r = run({"solve", bad, "-o", result_path});
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(read_text(result_path) == "old");
        const Run h = run({"solve", scene, "-o", result_path, "--subdivide", "0"});
        CHECK(h.status == 2);
        CHECK(read_text(result_path) == "old");
    }
    SUBCASE("a failed run writes nothing") {
        const std::string bad = tmp.file("bad.json", R"({"flatrad": 1, "materials": {}})");
        const Run r = run({"solve", bad, "-o", result_path});
        CHECK(r.status == 2);
        CHECK_FALSE(fs::exists(result_path));
        CHECK(std::distance(fs::directory_iterator(tmp.dir()), fs::directory_iterator{}) == 2);
    }
    SUBCASE("a missing output directory is refused before solving") {
        const Run r = run({"solve", scene, "-o", tmp.path("no_such_dir/result.json")});
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.err.find("no_such_dir") != std::string::npos);
    }
}

TEST_CASE("cli: --subdivide too large for memory is refused with the size") {
    TempDir tmp;
    const std::string scene = tmp.file("room.json", lit_room);
    // 6 patches x 100000 = 6e5 elements: 6e5^2 x 8 bytes = 2.6 TiB.
    const Run r = run({"solve", scene, "--method", "exact", "--subdivide", "100000"});
    CHECK(r.status == 2);
    CHECK(is_one_error_line(r.err));
    CHECK(r.err.find("GiB") != std::string::npos);
}

TEST_CASE("cli: formfactor of two facing unit plates is sqrt 2 - 1") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    for (const char* method : {"exact", "unoccluded"}) {
        CAPTURE(method);
        const Run r = run({"formfactor", scene, "--from", "lamp", "--to", "plate", "--method", method});
        REQUIRE(r.status == 0);
        CHECK(r.err.empty());
        CHECK(r.out.find('\n') == r.out.size() - 1);  // one JSON object on one line
        const json j = json::parse(r.out);
        CHECK(j["from"] == "lamp");
        CHECK(j["to"] == "plate");
        CHECK(j["method"] == method);
        CHECK(j["eps"] == 0.0);
        CHECK(j["F"].get<double>() == doctest::Approx(sqrt2_minus_1).epsilon(analytic_tol).scale(0));
        CHECK(j["F_reverse"].get<double>() ==
              doctest::Approx(sqrt2_minus_1).epsilon(analytic_tol).scale(0));
        CHECK(j.contains("time_s"));
        CHECK(j.contains("clusters_visited"));
        CHECK(j["stats"].contains("queries"));
    }
    // multiscale with nothing to block: exact value, nothing approximated, bound 0.
    const Run m = run({"formfactor", scene, "--from", "lamp", "--to", "plate", "--method", "multiscale", "--eps", "0.01"});
    REQUIRE(m.status == 0);
    const json jm = json::parse(m.out);
    CHECK(jm["eps"] == 0.01);
    CHECK(jm["F"].get<double>() == doctest::Approx(sqrt2_minus_1).epsilon(analytic_tol).scale(0));
    CHECK(jm["clusters_approximated"] == 0);
    CHECK(jm["error_bound"] == 0.0);
    CHECK(run({"formfactor", scene, "--from", "lamp", "--to", "plate", "--method", "multiscale", "--gamma", "nope"}).status == 2);
    // exact is the default; a group naming a surface twice counts it once.
    const Run d = run({"formfactor", scene, "--from", "lamp,lamp", "--to", "plate"});
    REQUIRE(d.status == 0);
    const json j = json::parse(d.out);
    CHECK(j["method"] == "exact");
    CHECK(j["F"].get<double>() == doctest::Approx(sqrt2_minus_1).epsilon(analytic_tol).scale(0));
}

TEST_CASE("cli: formfactor names an unknown surface") {
    TempDir tmp;
    const std::string scene = tmp.file("plates.json", two_plates);
    const Run r = run({"formfactor", scene, "--from", "lamp", "--to", "plate,ceiling"});
    CHECK(r.status == 2);
    CHECK(is_one_error_line(r.err));
    CHECK(r.err.find("\"ceiling\"") != std::string::npos);
    CHECK(r.err.find("--to") != std::string::npos);
    CHECK(r.out.empty());
}

TEST_CASE("cli: solve the data/ scenes closed_box and uniform_box") {
    const std::string data = FLATRAD_DATA_DIR;
    // A closed room: every emitted watt is absorbed. The form factors close
    // to ~1e-13 (exact solver), so the balance is far below 1e-10.
    constexpr double closed_balance_tol = 1e-10;
    {
        const Run r = run({"solve", data + "/closed_box.json", "--method", "exact", "-q"});
        REQUIRE(r.status == 0);
        const json result = json::parse(r.out);
        const json& patches = result["patches"];
        REQUIRE(patches.size() == 4);
        CHECK(patches[0]["surface"] == "floor");
        for (int k = 0; k < 3; ++k) {
            CHECK(patches[static_cast<std::size_t>(k + 1)]["surface"] == "walls");
            CHECK(patches[static_cast<std::size_t>(k + 1)]["segment"] == k);
        }
        CHECK(result["totals"]["balance"][0].get<double>() < closed_balance_tol);
    }
    {
        // Emission 1, reflectance 0.5, closed: B = E / (1 - rho) = 2 on every
        // element; the closure error (~1e-13) is amplified by 1 / (1 - rho) = 2.
        const Run r = run({"solve", data + "/uniform_box.json", "--subdivide", "4", "--method", "exact", "-q"});
        REQUIRE(r.status == 0);
        const json result = json::parse(r.out);
        for (const json& patch : result["patches"])
            for (const json& element : patch["elements"])
                CHECK(element[2].get<double>() == doctest::Approx(2.0).epsilon(closed_balance_tol));
    }
}
