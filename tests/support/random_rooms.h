#pragma once
// Random closed rooms for property tests: a square room lit inside, its
// walls cut into pieces, with random two-sided plates inside that neither
// cross each other nor touch the walls. Every side of every segment is a
// patch, so in such a room sum_j F_ij = 1 exactly (closure).
#include <random>
#include <vector>

#include "engine/geometry.h"

namespace flatrad::test {

struct RoomPatch {
    Segment seg;  // oriented lit-left
    int segment;  // index into RandomRoom::segments
};

struct RandomRoom {
    std::vector<Segment> segments;  // geometry, one per scene segment
    std::vector<RoomPatch> patches;
};

inline bool segments_cross(const Segment& s, const Segment& t) {
    const double o1 = orient(s.a, s.b, t.a), o2 = orient(s.a, s.b, t.b);
    const double o3 = orient(t.a, t.b, s.a), o4 = orient(t.a, t.b, s.b);
    return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0));
}

/// Room [0, size]^2 with `per_wall` pieces per wall and `plates` plates of
/// length in [min_len, max_len] * size.
inline RandomRoom make_random_room(std::mt19937_64& rng, int per_wall, int plates, double min_len = 0.05,
                                   double max_len = 0.3, double size = 1.0) {
    RandomRoom room;
    // Walls counter-clockwise, so the inside is on the left of travel.
    const Vec2 corner[4] = {{0, 0}, {size, 0}, {size, size}, {0, size}};
    for (int w = 0; w < 4; ++w)
        for (int k = 0; k < per_wall; ++k) {
            const Vec2 a = lerp(corner[w], corner[(w + 1) % 4], static_cast<double>(k) / per_wall);
            const Vec2 b = lerp(corner[w], corner[(w + 1) % 4], static_cast<double>(k + 1) / per_wall);
            room.patches.push_back({{a, b}, static_cast<int>(room.segments.size())});
            room.segments.push_back({a, b});
        }
    std::uniform_real_distribution<double> U(0, 1);
    const double margin = 0.02 * size;
    int placed = 0, tries = 0;
    while (placed < plates && tries < 100000) {
        ++tries;
        const double len = size * (min_len + (max_len - min_len) * U(rng));
        const double ang = 6.283185307179586 * U(rng);
        const Vec2 c{margin + len / 2 + (size - 2 * margin - len) * U(rng),
                     margin + len / 2 + (size - 2 * margin - len) * U(rng)};
        const Vec2 t{std::cos(ang) * len / 2, std::sin(ang) * len / 2};
        const Segment s{c - t, c + t};
        bool ok = true;
        for (size_t q = static_cast<size_t>(4 * per_wall); q < room.segments.size() && ok; ++q)
            if (segments_cross(s, room.segments[q])) ok = false;
        if (!ok) continue;
        const int id = static_cast<int>(room.segments.size());
        room.segments.push_back(s);
        room.patches.push_back({s, id});
        room.patches.push_back({s.reversed(), id});
        ++placed;
    }
    return room;
}

}  // namespace flatrad::test
