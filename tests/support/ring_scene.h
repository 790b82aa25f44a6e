#pragma once
// Round rooms for the solver's tests: n walls on the unit circle, one
// closed loop lit inside, and a lamp (emission 1) that is either one of the
// walls (every segment on the hull: nothing can block) or a short segment
// inside, lit on both sides (the one segment that can block).
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <string>

#include "engine/scene.h"

namespace flatrad::test {

inline Scene ring_scene(int n, double rho, double wall_emission, bool lamp_inside = false) {
    auto point = [n](int k) {
        const double t = 2 * std::numbers::pi * (k % n) / n;
        return fmt::format("[{:.17g},{:.17g}]", std::cos(t), std::sin(t));
    };
    std::string wall = point(1);
    for (int k = 2; k <= n; ++k) wall += "," + point(k);
    const std::string lamp = lamp_inside ? R"("side": "both", "points": [[-0.05, 0.5], [0.05, 0.5]])"
                                         : fmt::format(R"("side": "left", "points": [{},{}])", point(0), point(1));
    return parse_scene(fmt::format(R"({{"flatrad": 1, "name": "ring",
        "materials": {{"w": {{"reflectance": {}, "emission": {}}}, "l": {{"reflectance": {}, "emission": 1}}}},
        "surfaces": [{{"name": "lamp", "material": "l", {}}},
                     {{"name": "wall", "material": "w", "side": "left", "points": [{}]}}]}})",
                                   rho, wall_emission, rho, lamp, lamp_inside ? point(0) + "," + wall : wall),
                       "ring.json");
}

}  // namespace flatrad::test
