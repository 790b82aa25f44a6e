#pragma once
/// Loading a scene for a command: what the reader ignored (engine/scene.h,
/// Scene::warnings: unknown keys) is said on stderr, one line each,
/// "warning: FILE: PATH: ...", whatever --quiet says (a misspelt key is
/// part of the answer's story). Nothing is refused for it.
#include <ostream>
#include <string>

#include "engine/scene.h"

namespace flatrad {

Scene load_scene_reporting(const std::string& path, std::ostream& err);

}  // namespace flatrad
