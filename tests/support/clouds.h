#pragma once
// Random multi-scale test configurations: two facing patches with a cloud
// of small opaque segments between them, clustered at several scales
// (clumps of clumps), like the paper's Fig. 5 but randomized: near and far,
// sparse and dense, small and large.
#include <random>
#include <vector>

#include "engine/geometry.h"

namespace flatrad::test {

struct Cloud {
    Segment i, j;                   // lit-left, facing; scene segments 0 and 1
    std::vector<Segment> segments;  // i, j, then the cloud
};

inline Cloud make_cloud(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> U(0, 1);
    Cloud c;
    const double D = 0.5 + 20 * U(rng) * U(rng);   // separation
    const double wi = 0.3 + 2 * U(rng), wj = 0.3 + 2 * U(rng);
    const double tilt_i = 0.6 * (U(rng) - 0.5), tilt_j = 0.6 * (U(rng) - 0.5);
    const Vec2 ti{std::cos(tilt_i), std::sin(tilt_i)}, tj{-std::cos(tilt_j), -std::sin(tilt_j)};
    const Vec2 cj{(U(rng) - 0.5) * D * 0.5, D};
    c.i = {ti * (-wi / 2), ti * (wi / 2)};
    c.j = {cj - tj * (wj / 2), cj + tj * (wj / 2)};
    c.segments = {c.i, c.j};
    // The cloud: a box between the patches, filled with clumps.
    const double t = 0.2 + 0.6 * U(rng);              // where along the way
    const double size = (0.05 + 0.6 * U(rng)) * std::min(D * 0.8, wi + wj);
    const Vec2 centre = lerp(Vec2{0, 0}, cj, t) + Vec2{(U(rng) - 0.5) * 0.3 * size, 0};
    const int clumps = 1 + static_cast<int>(8 * U(rng));
    const int per_clump = 2 + static_cast<int>(60 * U(rng) * U(rng));
    const double seg_len = size * (0.005 + 0.08 * U(rng));
    for (int k = 0; k < clumps; ++k) {
        const Vec2 cc = centre + Vec2{(U(rng) - 0.5) * size, (U(rng) - 0.5) * size};
        const double spread = size * (0.05 + 0.3 * U(rng));
        for (int q = 0; q < per_clump; ++q) {
            const Vec2 p = cc + Vec2{(U(rng) - 0.5) * spread, (U(rng) - 0.5) * spread};
            const double a = 6.283185307179586 * U(rng);
            const Vec2 d{std::cos(a) * seg_len / 2, std::sin(a) * seg_len / 2};
            c.segments.push_back({p - d, p + d});
        }
    }
    return c;
}

}  // namespace flatrad::test
