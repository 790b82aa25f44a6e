#include "solver/exact_mesh.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace flatrad {

long ExactMesh::elements() const {
    long n = 0;
    for (const auto& c : cuts) n += static_cast<long>(c.size()) + 1;
    return n;
}

ExactMesh uniform_mesh(const Scene& scene, int K) {
    if (K < 1) throw std::invalid_argument(fmt::format("uniform_mesh: K = {}, expected >= 1", K));
    ExactMesh m;
    m.cuts.resize(scene.patches.size());
    for (auto& c : m.cuts)
        for (int k = 1; k < K; ++k) c.push_back(static_cast<double>(k) / K);
    return m;
}

namespace {

// Appends the cuts that halve [t0, t1] `level` times over, in order; a
// piece too short to halve in floating point stays whole.
void bisect(double t0, double t1, int level, std::vector<double>& out) {
    const double mid = 0.5 * (t0 + t1);
    if (level <= 0 || !(t0 < mid && mid < t1)) return;
    bisect(t0, mid, level - 1, out);
    out.push_back(mid);
    bisect(mid, t1, level - 1, out);
}

// One patch's cuts with element e (0-based, from t = 0) halved level(e)
// times over.
template <class Level>
std::vector<double> cut_patch(const std::vector<double>& cuts, Level level) {
    std::vector<double> out;
    out.reserve(2 * cuts.size() + 1);
    const size_t n = cuts.size() + 1;
    for (size_t e = 0; e < n; ++e) {
        const double t0 = e == 0 ? 0.0 : cuts[e - 1], t1 = e + 1 == n ? 1.0 : cuts[e];
        if (e > 0) out.push_back(t0);
        bisect(t0, t1, level(e), out);
    }
    return out;
}

}  // namespace

ExactMesh halved(const ExactMesh& mesh) {
    ExactMesh m;
    m.cuts.reserve(mesh.cuts.size());
    for (const auto& c : mesh.cuts) m.cuts.push_back(cut_patch(c, [](size_t) { return 1; }));
    return m;
}

ExactMesh split_levels(const ExactMesh& mesh, const std::vector<int>& level) {
    if (static_cast<long>(level.size()) != mesh.elements())
        throw std::invalid_argument(
            fmt::format("split_levels: {} levels for {} elements", level.size(), mesh.elements()));
    ExactMesh m;
    m.cuts.reserve(mesh.cuts.size());
    size_t first = 0;  // the patch's first element
    for (const auto& c : mesh.cuts) {
        m.cuts.push_back(cut_patch(c, [&](size_t e) { return level[first + e]; }));
        first += c.size() + 1;
    }
    return m;
}

void check_mesh(const Scene& scene, const ExactMesh& mesh) {
    if (mesh.cuts.size() != scene.patches.size())
        throw std::invalid_argument(
            fmt::format("exact mesh: {} patches' cuts for a scene of {} patches", mesh.cuts.size(), scene.patches.size()));
    for (size_t p = 0; p < mesh.cuts.size(); ++p) {
        double prev = 0;
        for (double t : mesh.cuts[p]) {
            // (NaN fails every comparison: refused here too.)
            if (!(t > prev && t < 1))
                throw std::invalid_argument(fmt::format(
                    "exact mesh: patch {}: cut {} is not strictly increasing inside (0, 1)", p, t));
            prev = t;
        }
    }
}

}  // namespace flatrad
