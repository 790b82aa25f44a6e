#include "cli/scene_warnings.h"

#include <fmt/format.h>

namespace flatrad {

namespace {
BeforeSceneRead g_before_scene_read = nullptr;
}  // namespace

void set_before_scene_read(BeforeSceneRead hook) { g_before_scene_read = hook; }

Scene load_scene_reporting(const std::string& path, std::ostream& err) {
    if (g_before_scene_read) g_before_scene_read(path);
    Scene scene = load_scene(path);
    for (const std::string& line : scene.warnings) err << fmt::format("warning: {}: {}\n", scene.file, line);
    return scene;
}

}  // namespace flatrad
