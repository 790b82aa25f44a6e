#pragma once
/// A flatland scene as SPEC.md describes it: materials (1 or 3 channels),
/// surfaces (polylines, closed polygons, circles) cut into segments, and the
/// patches (lit sides of segments) numbered in SPEC order.
///
/// Everything here is already validated: a Scene only exists if the whole
/// file was read and accepted (load_scene throws InputError otherwise).
#include <string>
#include <vector>

#include "engine/geometry.h"

namespace flatrad {

/// Which side of a surface is lit, as written in the file.
enum class Side { Left, Right, Both, In, Out };
const char* side_name(Side s);

struct Material {
    std::string name;
    std::vector<double> reflectance;  ///< one value per channel, each in [0, 1]
    std::vector<double> emission;     ///< one value per channel, each >= 0
};

struct Surface {
    std::string name;
    int material = -1;          ///< index into Scene::materials
    std::vector<Vec2> points;   ///< file order; a closing repeat is dropped
    bool closed = false;        ///< closed polygon or circle
    bool is_circle = false;
    Side side = Side::Left;
    int first_segment = 0;      ///< index of its first segment in Scene::segments
    int segment_count = 0;
};

/// One straight piece of a surface, endpoints in the file's point order.
struct SceneSegment {
    Segment seg;
    int surface = -1;    ///< index into Scene::surfaces
    int index = 0;       ///< segment number within its surface (closing one last)
    bool lit_left = false;   ///< the left side of a -> b is a patch
    bool lit_right = false;  ///< the right side of a -> b is a patch
};

/// One lit side of a segment. Radiosity lives on patches.
struct Patch {
    int segment = -1;        ///< index into Scene::segments
    int surface = -1;
    int material = -1;
    bool lit_left = true;    ///< lit on the left of the file-order a -> b
    Side side = Side::Left;  ///< SPEC's word for this side: left/right/in/out
    double length = 0;

    /// The segment oriented so that the lit side is on its left (a -> b
    /// reversed for a right-lit patch). All kernels take this form.
    Segment oriented(const std::vector<SceneSegment>& segments) const {
        const Segment& s = segments[static_cast<size_t>(segment)].seg;
        return lit_left ? s : s.reversed();
    }
};

struct Scene {
    std::string file;         ///< as given to load_scene, for messages
    std::string name;         ///< the scene's "name" (file stem if absent)
    int channels = 1;
    std::vector<Material> materials;
    std::vector<Surface> surfaces;
    std::vector<SceneSegment> segments;  ///< SPEC numbering: surface by surface, point order
    std::vector<Patch> patches;          ///< SPEC numbering: per segment, left/in before right/out
    /// What the file holds that the reader ignored: keys it does not know
    /// (a misspelt "emision" would otherwise leave a lamp dark without a
    /// word). One line each, "PATH: unknown key ..." (with a likely meant
    /// key when one is close), at most max_scene_warnings of them, then one
    /// line counting the rest. For the caller to show; nothing is refused.
    std::vector<std::string> warnings;

    /// Plain segment geometry, index-aligned with `segments` (for hierarchy building).
    std::vector<Segment> segment_geometry() const;
    /// Oriented geometry of patch p (lit side on the left).
    Segment patch_segment(int p) const { return patches[static_cast<size_t>(p)].oriented(segments); }
    /// Index of the surface called `name`, or -1.
    int find_surface(const std::string& name) const;
    /// Length of the scene's bounding box diagonal (the scale for length tolerances).
    double extent() const;
};

/// Scene::warnings keeps this many lines, then one saying how many more.
constexpr size_t max_scene_warnings = 10;

/// Most memory a scene may take to hold: its segments, its patches (two
/// per segment at most) and the cluster hierarchy built over them. 1 GiB,
/// about 4 million segments: far beyond what the exact solver can use
/// (exact_solver.h) and still a small part of a 24 GiB machine. A file
/// asking for more (a few circles of a million segments take a few
/// hundred bytes of JSON) is refused while being read, before it is built.
constexpr double scene_memory_limit_bytes = 1024.0 * 1024 * 1024;

/// Estimated bytes to hold a scene of `segments` segments (the worst case
/// of two patches each) and its cluster hierarchy.
double scene_memory_bytes(double segments);

/// Reads and validates a scene file (SPEC.md, "Scene file").
/// Throws InputError(file, json_path, message) on any fault SPEC.md lists,
/// and when the scene would need more than scene_memory_limit_bytes;
/// `file` in the error is `path` as given.
Scene load_scene(const std::string& path);

/// Same, from JSON text; `file_label` names it in errors.
Scene parse_scene(const std::string& json_text, const std::string& file_label);

}  // namespace flatrad
