#include "solver/closed_enclosure.h"

#include <fmt/format.h>

#include <string>

#include "engine/compensated_sum.h"
#include "engine/error.h"

namespace flatrad {

std::vector<int> closed_white_set(const Eigen::MatrixXd& F, const std::vector<double>& rho) {
    const int n = static_cast<int>(rho.size());
    std::vector<char> in(static_cast<size_t>(n));
    for (int a = 0; a < n; ++a) in[static_cast<size_t>(a)] = rho[static_cast<size_t>(a)] == 1.0;
    bool changed = true;
    while (changed) {
        changed = false;
        for (int a = 0; a < n; ++a) {
            if (!in[static_cast<size_t>(a)]) continue;
            CompensatedSum kept;
            for (int b = 0; b < n; ++b)
                if (in[static_cast<size_t>(b)]) kept.add(F(a, b));
            if (kept.value() < 1 - closure_tolerance) {
                in[static_cast<size_t>(a)] = 0;
                changed = true;
            }
        }
    }
    std::vector<int> set;
    for (int a = 0; a < n; ++a)
        if (in[static_cast<size_t>(a)]) set.push_back(a);
    return set;
}

void refuse_closed_white(const Scene& scene, const std::vector<int>& patches, int channel) {
    std::string names;
    for (int p : patches) {
        const std::string name = "'" + scene.surfaces[static_cast<size_t>(scene.patches[static_cast<size_t>(p)].surface)].name + "'";
        if (names.find(name) == std::string::npos) names += (names.empty() ? "" : ", ") + name;
    }
    // The path names the reflectance at fault: that of the first patch's
    // material (every patch of the set has reflectance 1 in `channel`).
    const int material = patches.empty() ? -1 : scene.patches[static_cast<size_t>(patches.front())].material;
    const std::string path =
        material >= 0 ? "materials." + scene.materials[static_cast<size_t>(material)].name + ".reflectance" : std::string{};
    throw InputError(scene.file, path,
                     fmt::format("no unique solution: {} enclose(s) light with reflectance 1{} and "
                                 "nothing absorbs it; lower a reflectance below 1",
                                 names, scene.channels > 1 ? fmt::format(" in channel {}", channel) : std::string{}));
}

}  // namespace flatrad
