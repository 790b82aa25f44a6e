#include <string>

#include <fmt/format.h>

#include "engine/error.h"
#include "solver/exact_solver.h"

namespace flatrad {

namespace {

constexpr double gib = 1024.0 * 1024 * 1024;

}  // namespace

double exact_solver_memory_bytes(const Scene& scene, int K) {
    return exact_solver_memory_bytes_for(scene, static_cast<double>(scene.patches.size()) * static_cast<double>(K));
}

double exact_solver_memory_bytes_for(const Scene& scene, double n) {
    // The three dense n x n matrices: F, A = I - rho F, A's LU factors.
    const double matrices = 3 * n * n * sizeof(double);
    // Per element: its record (a segment, indices, parameters: ~64 bytes),
    // its fraction to unlit sides, and per channel E, B and F B.
    const double per_element = 64 + sizeof(double) * (1 + 3 * static_cast<double>(scene.channels));
    return matrices + n * per_element;
}

namespace {

// Throws when n elements would pass the limit; `what` says what they are,
// `path` and `advice` where the fault is and what to do.
void check_memory(const Scene& scene, double n, const std::string& what, const std::string& path,
                  const std::string& advice) {
    const double bytes = exact_solver_memory_bytes_for(scene, n);
    if (bytes <= exact_solver_memory_limit_bytes) return;
    throw InputError(scene.file, path,
                     fmt::format("{:.0f} elements ({}) would need {:.1f} GiB for the exact solver "
                                 "(three dense elements^2 matrices of doubles); the limit is {:.0f} GiB: {}",
                                 n, what, bytes / gib, exact_solver_memory_limit_bytes / gib, advice));
}

}  // namespace

void check_exact_solver_memory(const Scene& scene, int K) {
    check_memory(scene, static_cast<double>(scene.patches.size()) * static_cast<double>(K),
                 fmt::format("{} patches x {}", scene.patches.size(), K), K > 1 ? "--subdivide" : "",
                 K > 1 ? "lower --subdivide" : "use fewer segments");
}

void check_exact_solver_memory(const Scene& scene, const ExactMesh& mesh) {
    check_memory(scene, static_cast<double>(mesh.elements()), "a graded mesh", "", "use a coarser mesh");
}

}  // namespace flatrad
