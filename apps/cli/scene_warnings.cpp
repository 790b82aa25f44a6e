#include "cli/scene_warnings.h"

#include <fmt/format.h>

namespace flatrad {

void print_scene_warnings(std::ostream& err, const Scene& scene) {
    for (const std::string& line : scene.warnings) err << fmt::format("warning: {}: {}\n", scene.file, line);
}

Scene load_scene_reporting(const std::string& path, std::ostream& err) {
    Scene scene = load_scene(path);
    print_scene_warnings(err, scene);
    return scene;
}

}  // namespace flatrad
