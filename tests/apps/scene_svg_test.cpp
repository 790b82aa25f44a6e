// Tests apps/cli/scene_svg.h: `flatrad solve --svg`, driven through run_cli.
#include "cli/scene_svg.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "support/cli_run.h"

namespace fs = std::filesystem;

using flatrad::test::is_one_error_line;
using flatrad::test::read_text;
using flatrad::test::Run;
using flatrad::test::run;
using flatrad::test::TempDir;

namespace {



size_t count(const std::string& text, const std::string& word) {
    size_t n = 0;
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + word.size())) ++n;
    return n;
}

fs::path temp_dir() {
    const fs::path p = fs::temp_directory_path() / ("flatrad_scene_svg_test_" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p;
}

size_t element_count(const nlohmann::json& result) {
    size_t n = 0;
    for (const auto& p : result["patches"]) n += p["elements"].size();
    return n;
}

}  // namespace

TEST_CASE("solve --svg: one line per element, the scene's name, both methods") {
    const fs::path dir = temp_dir();
    const std::string data = FLATRAD_DATA_DIR;
    for (const std::string& scene : {data + "/tube_bank.json", data + "/closed_box.json"}) {
        for (const std::vector<std::string>& method :
             {std::vector<std::string>{"--method", "exact", "--subdivide", "2"},
              std::vector<std::string>{"--method", "hierarchical", "--eps", "0.05"}}) {
            CAPTURE(scene);
            CAPTURE(method[1]);
            const fs::path svg = dir / "out.svg", result = dir / "out.json";
            fs::remove(svg);
            std::vector<std::string> args{"solve", scene, "-q", "-o", result.string(), "--svg", svg.string()};
            args.insert(args.end(), method.begin(), method.end());
            const Run r = run(args);
            REQUIRE(r.status == 0);
            REQUIRE(fs::exists(svg));
            const std::string text = read_text(svg);
            CHECK(text.rfind("<svg", 0) == 0);
            CHECK(text.size() > 6);
            CHECK(text.substr(text.size() - 7) == "</svg>\n");
            const nlohmann::json j = nlohmann::json::parse(read_text(result));
            CHECK(count(text, "<line class=\"element\"") == element_count(j));
            CHECK(text.find(j["scene"].get<std::string>()) != std::string::npos);
            CHECK(text.find(method[1]) != std::string::npos);  // the caption names the method
            CHECK(text.find("NaN") == std::string::npos);
            CHECK(text.find("nan") == std::string::npos);
        }
    }
    fs::remove_all(dir);
}

TEST_CASE("solve --svg: three channels in true color, no legend, one channel has a legend") {
    const fs::path dir = temp_dir();
    const fs::path svg = dir / "room.svg";
    REQUIRE(run({"solve", std::string(FLATRAD_DATA_DIR) + "/furnished_room.json", "-q", "-o",
                 (dir / "room.json").string(), "--svg", svg.string()})
                .status == 0);
    const std::string text = read_text(svg);
    CHECK(text.find("furnished room") != std::string::npos);
    CHECK(text.find("class=\"legend\"") == std::string::npos);
    CHECK(text.find("tone map") != std::string::npos);

    const fs::path svg1 = dir / "box.svg";
    REQUIRE(run({"solve", std::string(FLATRAD_DATA_DIR) + "/closed_box.json", "-q", "-o",
                 (dir / "box.json").string(), "--svg", svg1.string()})
                .status == 0);
    CHECK(read_text(svg1).find("class=\"legend\"") != std::string::npos);
    fs::remove_all(dir);
}

TEST_CASE("solve --svg: a bad path is refused before solving, and nothing is written") {
    const fs::path dir = temp_dir();
    const Run r = run({"solve", std::string(FLATRAD_DATA_DIR) + "/closed_box.json", "-q", "-o",
                       (dir / "r.json").string(), "--svg", (dir / "no such dir" / "x.svg").string()});
    CHECK(r.status == 2);
    CHECK_FALSE(fs::exists(dir / "r.json"));
    fs::remove_all(dir);
}

TEST_CASE("false_color and tone_map: ends, clamping, NaN") {
    const flatrad::Rgb8 lo = flatrad::false_color(0), hi = flatrad::false_color(1);
    CHECK(lo.r == 68);
    CHECK(hi.g == 231);
    const flatrad::Rgb8 nan = flatrad::false_color(std::nan(""));
    CHECK(nan.r == lo.r);
    CHECK(flatrad::false_color(7).b == hi.b);
    CHECK(flatrad::tone_map(0, 1) == 0);
    CHECK(flatrad::tone_map(1, 1) == 255);
    CHECK(flatrad::tone_map(5, 1) == 255);
    CHECK(flatrad::tone_map(-1, 1) == 0);
    CHECK(flatrad::tone_map(std::nan(""), 1) == 0);
    CHECK(flatrad::tone_map(0.5, 1) == 186);  // 255 * 0.5^(1/2.2) = 186.0
}
