#include "solver/sink_visibility.h"

#include "solver/loop_sides.h"

namespace flatrad {

std::vector<char> visible_sinks(const Scene& scene, const Connectivity& conn) {
    const size_t S = scene.segments.size();
    std::vector<char> visible(2 * S, 0);
    for (size_t s = 0; s < S; ++s) {
        visible[2 * s] = scene.segments[s].lit_left ? 0 : 1;
        visible[2 * s + 1] = scene.segments[s].lit_right ? 0 : 1;
    }
    double budget = 1e8;
    for (const SceneLoop& L : conn.loops) {
        if (!L.simple || L.orientation == 0) continue;
        bool any_unlit = false;
        for (int s : L.segments) any_unlit = any_unlit || visible[2 * static_cast<size_t>(s)] || visible[2 * static_cast<size_t>(s) + 1];
        if (!any_unlit) continue;
        // Each segment off L costs two point-in-polygon tests and a contact
        // test, O(|L|) each; segments on L cost nothing.
        const double cost = static_cast<double>(S - L.segments.size()) * static_cast<double>(L.polygon.size());
        if (cost > budget) continue;
        budget -= cost;
        const std::vector<LoopSide> where = loop_sides(scene, L, true);
        std::vector<char> on_loop(S, 0);
        for (int s : L.segments) on_loop[static_cast<size_t>(s)] = 1;
        bool all_inside = true, none_inside = true;
        for (size_t s = 0; s < S && (all_inside || none_inside); ++s) {
            if (on_loop[s]) continue;
            if (where[2 * s] != LoopSide::In) all_inside = false;
            if (where[2 * s] != LoopSide::Out) none_inside = false;
        }
        // L's own lit sides see its unlit ones on the same side of it: a
        // lit interior side sees the interior sinks, a lit exterior side (of
        // a non-convex loop) the exterior ones.
        bool lit_interior = false, lit_exterior = false;
        for (int s : L.segments) {
            const SceneSegment& ss = scene.segments[static_cast<size_t>(s)];
            for (size_t side = 0; side < 2; ++side) {
                const size_t x = 2 * static_cast<size_t>(s) + side;
                const bool lit = side == 0 ? ss.lit_left : ss.lit_right;
                lit_interior = lit_interior || (lit && where[x] == LoopSide::In);
                lit_exterior = lit_exterior || (lit && where[x] == LoopSide::Out);
            }
        }
        for (int s : L.segments)
            for (size_t side = 0; side < 2; ++side) {
                const size_t x = 2 * static_cast<size_t>(s) + side;
                if (visible[x] && (where[x] == LoopSide::In ? none_inside && !lit_interior : all_inside && !lit_exterior))
                    visible[x] = 0;
            }
    }
    return visible;
}

}  // namespace flatrad
