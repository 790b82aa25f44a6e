#pragma once
/// Loading a scene for a command: what the reader ignored (engine/scene.h,
/// Scene::warnings: unknown keys) is said on stderr, one line each,
/// "warning: FILE: PATH: ...", whatever --quiet says (a misspelt key is
/// part of the answer's story). Nothing is refused for it.
///
/// A program may also be told of each scene file right before it is read
/// (set_before_scene_read): the flatrad tool picks its allocator's page
/// size by the file's size there (apps/large_pages.h).
#include <ostream>
#include <string>

#include "engine/scene.h"

namespace flatrad {

Scene load_scene_reporting(const std::string& path, std::ostream& err);

/// Called with the path of every scene file load_scene_reporting reads,
/// right before it reads it; null (the default): nothing. For the whole
/// process (set it first thing in main()).
using BeforeSceneRead = void (*)(const std::string& path);
void set_before_scene_read(BeforeSceneRead hook);

}  // namespace flatrad
