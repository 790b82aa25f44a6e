#include "solver/loop_sides.h"

#include "solver/polygon_tests.h"

namespace flatrad {

std::vector<LoopSide> loop_sides(const Scene& scene, const SceneLoop& L, bool in_line_contacts) {
    const size_t S = scene.segments.size();
    std::vector<LoopSide> where(2 * S, LoopSide::Unknown);
    std::vector<char> on_loop(S, 0);
    for (size_t k = 0; k < L.segments.size(); ++k) {
        const size_t s = static_cast<size_t>(L.segments[k]);
        on_loop[s] = 1;
        // The interior is left of the traversal when counter-clockwise;
        // traversal runs a -> b when forward.
        const bool interior_left = (L.orientation > 0) == static_cast<bool>(L.forward[k]);
        where[2 * s] = interior_left ? LoopSide::In : LoopSide::Out;
        where[2 * s + 1] = interior_left ? LoopSide::Out : LoopSide::In;
    }
    for (size_t s = 0; s < S; ++s) {
        if (on_loop[s]) continue;
        const Segment& g = scene.segments[s].seg;
        const Where wa = locate(g.a, L.polygon), wb = locate(g.b, L.polygon);
        const bool touches = wa == Where::Unsure || wb == Where::Unsure ||
                             (in_line_contacts ? meets_or_in_line(g, L.polygon) : meets(g, L.polygon));
        LoopSide w = LoopSide::Unknown;
        if (!touches && wa == Where::Inside && wb == Where::Inside) w = LoopSide::In;
        if (!touches && wa == Where::Outside && wb == Where::Outside) w = LoopSide::Out;
        // Touching with no end on the far side (a shelf or a lamp against a
        // wall): it stays on its side of L when it crosses no edge and meets
        // no corner (polygon_tests.h), its midpoint telling which side (both
        // ends on L: a chord, inside or out). L stays closed where it is
        // touched, so such a segment sees nothing beyond L, and nothing
        // beyond L sees it. (Only the inner side is taken so: the sink rule
        // keeps its interior case strict, see solver/sink_visibility.h.)
        const bool no_end_out = wa != Where::Outside && wb != Where::Outside;
        if (touches && no_end_out && !crosses(g, L.polygon) && locate(0.5 * (g.a + g.b), L.polygon) == Where::Inside)
            w = LoopSide::In;
        where[2 * s] = where[2 * s + 1] = w;
    }
    return where;
}

}  // namespace flatrad
