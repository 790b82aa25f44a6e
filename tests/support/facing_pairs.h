#pragma once
// Random facing pairs for shaft tests (direction bounds, bands): patch i
// along y = 0, patch j 0.3 to 3.3 above it, both of random extent and j a
// little tilted, mutually clipped to each other's lit half-planes (lit on
// the left, facing each other), drawn again until the clipped pair exists.
#include <random>
#include <utility>

#include "engine/formfactor.h"
#include "engine/geometry.h"

namespace flatrad::test {

inline std::pair<Segment, Segment> random_facing_pair(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    for (;;) {
        const double gap = 0.3 + 3 * u(rng);
        const Segment i{{u(rng) * 0.5, 0}, {1 + u(rng), 0}};
        const Segment j{{0.7 + 2 * u(rng), gap + 0.5 * (u(rng) - 0.5)}, {2 * u(rng) - 0.5, gap + 0.5 * (u(rng) - 0.5)}};
        if (const auto clipped = clip_to_lit_halfplanes(i, j)) return *clipped;
    }
}

}  // namespace flatrad::test
