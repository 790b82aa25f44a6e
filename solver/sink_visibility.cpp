#include "solver/sink_visibility.h"

#include "solver/polygon_tests.h"

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
        std::vector<char> on_loop(S, 0);
        for (int s : L.segments) on_loop[static_cast<size_t>(s)] = 1;
        bool all_inside = true, none_inside = true;
        for (size_t s = 0; s < S && (all_inside || none_inside); ++s) {
            if (on_loop[s]) continue;
            const Segment& g = scene.segments[s].seg;
            const Where wa = locate(g.a, L.polygon), wb = locate(g.b, L.polygon);
            const bool touches = wa == Where::Unsure || wb == Where::Unsure || meets(g, L.polygon);
            bool in = !touches && wa == Where::Inside && wb == Where::Inside;
            bool out = !touches && wa == Where::Outside && wb == Where::Outside;
            // Touching with no end on the far side (a shelf or a lamp
            // against a wall): it stays on its side of L when it crosses no
            // edge and meets no corner (polygon_tests.h), its midpoint
            // telling which side (both ends on L: a chord, inside or out).
            // L stays closed where it is touched, so such a segment sees
            // nothing beyond L, and nothing beyond L sees it.
            const bool no_end_out = wa != Where::Outside && wb != Where::Outside;
            if (touches && no_end_out && !crosses(g, L.polygon)) in = locate(0.5 * (g.a + g.b), L.polygon) == Where::Inside;
            if (!in) all_inside = false;
            if (!out) none_inside = false;
        }
        // L's own lit sides see its unlit ones on the same side of it: a
        // lit interior side sees the interior sinks, a lit exterior side (of
        // a non-convex loop) the exterior ones.
        bool lit_interior = false, lit_exterior = false;
        for (size_t k = 0; k < L.segments.size(); ++k) {
            const SceneSegment& ss = scene.segments[static_cast<size_t>(L.segments[k])];
            // The interior is left of the traversal when counter-clockwise;
            // traversal runs a -> b when forward.
            const bool interior_left = (L.orientation > 0) == static_cast<bool>(L.forward[k]);
            lit_interior = lit_interior || (interior_left ? ss.lit_left : ss.lit_right);
            lit_exterior = lit_exterior || (interior_left ? ss.lit_right : ss.lit_left);
        }
        for (size_t k = 0; k < L.segments.size(); ++k) {
            const size_t s = static_cast<size_t>(L.segments[k]);
            const bool interior_left = (L.orientation > 0) == static_cast<bool>(L.forward[k]);
            for (int side = 0; side < 2; ++side) {
                if (!visible[2 * s + static_cast<size_t>(side)]) continue;
                const bool faces_interior = (side == 0) == interior_left;
                if (faces_interior ? (none_inside && !lit_interior) : (all_inside && !lit_exterior))
                    visible[2 * s + static_cast<size_t>(side)] = 0;
            }
        }
    }
    return visible;
}

}  // namespace flatrad
