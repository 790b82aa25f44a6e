#pragma once
/// The scene's connectivity, from geometry alone (DESIGN.md §4, "Pay for
/// what the scene uses", and the issue "segments sharing endpoints form
/// objects and rooms"): segments that share endpoints form objects, and an
/// object that closes on itself is a loop (a room, a pillar, a circle).
/// The solver uses it to know which patches' light cannot leave the scene,
/// so that the energy balance it reports, |emitted - absorbed - escaped| /
/// emitted (SPEC.md, "totals"), is a measure and not a tautology: escaped
/// power is only assumed zero where the geometry proves it.
///
/// The graph (Boost.Graph, connected_components): vertices are distinct
/// segment endpoints, edges are segments. Two endpoints are the same vertex
/// only when their coordinates are *exactly* equal (see connectivity.cpp for
/// why no tolerance).
///
/// Escape-free rule (sufficient, never necessary). A patch is escape-free
/// when some loop L proves that every ray leaving its lit side hits L:
///  1. the patch's segment is not on L, is certainly disjoint from every
///     segment of L (no crossing and no touching), and lies inside L (odd
///     crossing number; for a closed curve, simple or not, a point of odd
///     crossing number cannot reach infinity without crossing it); or
///  2. the patch's segment is on L, L is certified simple, and the patch's
///     lit side is L's interior side (left of the traversal when L is
///     counter-clockwise).
/// Every predicate is evaluated on doubles with a rounding bound; a result
/// within the bound counts as "unsure" and the answer is 0 (not proven),
/// which is always safe. So touching geometry (a table leg standing on the
/// floor without sharing a vertex, a segment lying along a wall) is not
/// proven; nor are rooms with a T-junction (a partition wall sharing a
/// vertex with the outer wall makes the room's object have a vertex of
/// degree 3, so it is not a loop). Closed faces of such general graphs
/// are not handled yet.
///
/// Cost: O(N log N) for the graph (a sort of the 2N endpoints) and typical
/// scenes; each loop of more than a few dozen segments gets its own cluster
/// hierarchy for its crossing-number and contact tests. Worst cases (see
/// escape_free_patches) degrade towards O(N x loop size). Measured with 2
/// busy cores: 10^6 segments from scripts/make-scene 1000000 --density 3,
/// 0.55 s for the graph and 0.06 s for escape_free_patches; a 460 000-
/// segment circle room holding 10^4 diamonds and 5 x 10^5 dashes, 0.9 s
/// and 0.45 s (tests/engine/connectivity_test.cpp, the skipped timing case).
#include <memory>
#include <vector>

#include "engine/geometry.h"
#include "engine/scene.h"

namespace flatrad {

class Hierarchy;

/// Segments connected through shared endpoints.
struct SceneObject {
    std::vector<int> segments;  ///< indices into Scene::segments, ascending
    int loop = -1;              ///< index into Connectivity::loops, or -1
};

/// An object whose every vertex has degree 2: one closed cycle (a closed
/// polygon, a circle, or several polylines meeting end to end).
struct SceneLoop {
    int object = -1;                 ///< index into Connectivity::objects
    std::vector<int> segments;       ///< in cycle order, starting at the object's first segment
    std::vector<char> forward;       ///< per cycle position: traversed a -> b (else b -> a)
    std::vector<Vec2> polygon;       ///< polygon[k] = where segments[k] starts as traversed
    double signed_area = 0;          ///< shoelace (compensated); > 0 when the cycle runs counter-clockwise
    Box box;                         ///< bounding box of the polygon
    /// Certified simple: at least 3 segments, no two meet except consecutive
    /// ones at their shared vertex (every test decided beyond rounding).
    bool simple = false;
    /// +1 counter-clockwise, -1 clockwise: the sign of the turn at the
    /// lowest-leftmost vertex, certain beyond rounding. 0 when not simple
    /// or not certain. A simple loop's interior is on the left of every
    /// segment as traversed when +1, on the right when -1.
    int orientation = 0;
    /// The cluster hierarchy of the polygon's edges, for loops too long to
    /// scan (null for the others): built once to certify the loop simple
    /// and used again by escape_free_patches (at 10^6 walls each build took
    /// 0.3-0.45 s, on the path the solver waits for).
    std::shared_ptr<const Hierarchy> edge_tree;
};

struct Connectivity {
    int vertex_count = 0;                ///< distinct endpoints
    std::vector<int> segment_vertex;     ///< 2 per segment: vertex of a, vertex of b
    std::vector<int> vertex_degree;      ///< segments at each vertex
    std::vector<int> segment_object;     ///< per segment, index into objects
    std::vector<SceneObject> objects;    ///< numbered by their lowest segment
    std::vector<SceneLoop> loops;        ///< in the order of their objects
};

/// Objects and loops of `scene` (Boost.Graph connected_components over the
/// endpoint graph). O(N log N).
Connectivity scene_connectivity(const Scene& scene);

/// One entry per patch, in SPEC patch order: 1 when the geometry proves
/// that no light leaving the patch's lit side escapes the scene (the rule
/// in this header's comment), 0 when not proven.
///
/// Cost: per segment, the loops whose box holds the segment's box are found
/// through a hierarchy of loop boxes and tried until one proves it; each try
/// is a contact query and a crossing-number ray in that loop's hierarchy.
/// Typically O(log N) per segment. Worst cases: many nested loop boxes that
/// hold a segment without proving it (k nested U shapes: O(k) tries), and
/// loops that a horizontal ray crosses many times (a comb of t teeth: O(t)
/// per ray); certifying a loop simple checks each of its segments against
/// the segments whose boxes overlap its box (a star of long spikes through
/// one region: quadratic in the loop's size).
std::vector<char> escape_free_patches(const Scene& scene, const Connectivity& connectivity);
std::vector<char> escape_free_patches(const Scene& scene);

/// Every patch is escape-free: the scene is closed and no light can leave it.
bool scene_enclosed(const Scene& scene);

}  // namespace flatrad
