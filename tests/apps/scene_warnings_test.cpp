// cli/scene_warnings.h: a scene's ignored keys said on stderr, and the
// program's hook told of each scene file right before it is read.
#include <doctest/doctest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/scene_warnings.h"
#include "support/cli_run.h"

using flatrad::test::TempDir;

namespace {

const char* const room = R"({"flatrad": 1, "colour": 1,
  "materials": {"glow": {"reflectance": 0.5, "emission": 1.0}},
  "surfaces": [{"name": "room", "material": "glow", "closed": true, "side": "in",
                "points": [[0, 0], [1, 0], [1, 1], [0, 1]]}]})";

std::vector<std::string> g_seen;
std::string g_write_text;

// Writes the scene at the path it is told of: the read that follows can
// only succeed if the hook ran first.
void write_then_read(const std::string& path) {
    g_seen.push_back(path);
    std::ofstream(path) << g_write_text;
}

}  // namespace

TEST_CASE("load_scene_reporting says each ignored key on stderr and tells the hook of the file first") {
    TempDir tmp;
    const std::string path = tmp.path("room.json");  // not written yet
    g_seen.clear();
    g_write_text = room;
    flatrad::set_before_scene_read(&write_then_read);
    std::ostringstream err;
    const flatrad::Scene scene = flatrad::load_scene_reporting(path, err);
    flatrad::set_before_scene_read(nullptr);
    REQUIRE(g_seen.size() == 1);
    CHECK(g_seen[0] == path);
    CHECK(scene.segments.size() == 4);
    // The unknown key "colour", once, with the file and its JSON path.
    const std::string said = err.str();
    CHECK(said.rfind("warning: " + path + ": ", 0) == 0);
    CHECK(said.find("colour") != std::string::npos);
    CHECK(std::count(said.begin(), said.end(), '\n') == 1);
    // Without a hook, nothing is called.
    g_seen.clear();
    std::ostringstream err2;
    (void)flatrad::load_scene_reporting(path, err2);
    CHECK(g_seen.empty());
}
