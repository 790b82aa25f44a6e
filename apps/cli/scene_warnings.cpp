#include "cli/scene_warnings.h"

#include <fmt/format.h>

namespace flatrad {

Scene load_scene_reporting(const std::string& path, std::ostream& err) {
    Scene scene = load_scene(path);
    for (const std::string& line : scene.warnings) err << fmt::format("warning: {}: {}\n", scene.file, line);
    return scene;
}

}  // namespace flatrad
