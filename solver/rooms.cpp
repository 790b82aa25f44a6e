#include "solver/rooms.h"

#include <algorithm>
#include <cmath>

#include "solver/polygon_tests.h"

namespace flatrad {

std::vector<int> side_rooms(const Scene& scene, const Connectivity& conn) {
    const size_t S = scene.segments.size();
    // Usable loops, smallest first (the first that contains a segment is the innermost).
    std::vector<int> order;
    for (size_t k = 0; k < conn.loops.size(); ++k)
        if (conn.loops[k].simple && conn.loops[k].orientation != 0) order.push_back(static_cast<int>(k));
    std::sort(order.begin(), order.end(), [&](int a, int b) {
        return std::abs(conn.loops[static_cast<size_t>(a)].signed_area) < std::abs(conn.loops[static_cast<size_t>(b)].signed_area);
    });
    // Segment -> (loop, position) for segments on usable loops.
    std::vector<int> seg_loop(S, -1), seg_pos(S, -1);
    for (int k : order) {
        const SceneLoop& L = conn.loops[static_cast<size_t>(k)];
        for (size_t q = 0; q < L.segments.size(); ++q) {
            seg_loop[static_cast<size_t>(L.segments[q])] = k;
            seg_pos[static_cast<size_t>(L.segments[q])] = static_cast<int>(q);
        }
    }
    double budget = 1e8;
    // A loop is a wall between rooms only if nothing off it crosses or
    // touches it (segments may cross: two crossing loops, or a plate
    // through a wall, would let light pass between its sides' rooms).
    {
        std::vector<int> clean;
        for (int k : order) {
            const SceneLoop& L = conn.loops[static_cast<size_t>(k)];
            budget -= static_cast<double>(S) * static_cast<double>(L.polygon.size());
            if (budget < 0) break;  // too costly to prove: not used (unknown rooms are always safe)
            bool ok = true;
            for (size_t s = 0; s < S && ok; ++s) {
                if (seg_loop[s] == k) continue;
                const Segment& g = scene.segments[s].seg;
                const bool near = std::max(g.a.x, g.b.x) >= L.box.lo.x && std::min(g.a.x, g.b.x) <= L.box.hi.x &&
                                  std::max(g.a.y, g.b.y) >= L.box.lo.y && std::min(g.a.y, g.b.y) <= L.box.hi.y;
                if (near && meets(g, L.polygon)) ok = false;
            }
            if (ok) clean.push_back(k);
        }
        for (int k : order)
            if (std::find(clean.begin(), clean.end(), k) == clean.end())
                for (int s : conn.loops[static_cast<size_t>(k)].segments) seg_loop[static_cast<size_t>(s)] = -1;
        order = clean;
        budget = 1e8;
    }
    // Innermost usable loop strictly containing segment s (not one it is on).
    auto container = [&](size_t s) -> int {
        const Segment& g = scene.segments[s].seg;
        for (int k : order) {
            if (k == seg_loop[s]) continue;
            const SceneLoop& M = conn.loops[static_cast<size_t>(k)];
            const bool in_box = M.box.lo.x <= std::min(g.a.x, g.b.x) && std::max(g.a.x, g.b.x) <= M.box.hi.x &&
                                M.box.lo.y <= std::min(g.a.y, g.b.y) && std::max(g.a.y, g.b.y) <= M.box.hi.y;
            if (!in_box) continue;
            budget -= 3.0 * static_cast<double>(M.polygon.size());
            if (budget < 0) return room_unknown;
            const Where wa = locate(g.a, M.polygon), wb = locate(g.b, M.polygon);
            if (wa == Where::Unsure || wb == Where::Unsure || wa != wb) return room_unknown;
            if (wa == Where::Outside) continue;
            if (meets(g, M.polygon)) return room_unknown;
            return k;
        }
        return room_outside;
    };
    std::vector<int> room(2 * S, room_unknown);
    for (size_t s = 0; s < S; ++s) {
        int outside_of_s = room_unknown;
        bool known = false;
        for (int side = 0; side < 2; ++side) {
            const bool left = side == 0;
            if (seg_loop[s] >= 0) {
                const SceneLoop& L = conn.loops[static_cast<size_t>(seg_loop[s])];
                const bool interior_left = (L.orientation > 0) == static_cast<bool>(L.forward[static_cast<size_t>(seg_pos[s])]);
                if (left == interior_left) {
                    room[2 * s + static_cast<size_t>(side)] = seg_loop[s];
                    continue;
                }
            }
            if (!known) {
                outside_of_s = container(s);
                known = true;
            }
            room[2 * s + static_cast<size_t>(side)] = outside_of_s;
        }
    }
    return room;
}

}  // namespace flatrad
