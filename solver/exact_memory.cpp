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

void check_exact_solver_memory(const Scene& scene, int K) {
    const double bytes = exact_solver_memory_bytes(scene, K);
    if (bytes <= exact_solver_memory_limit_bytes) return;
    const double n = static_cast<double>(scene.patches.size()) * static_cast<double>(K);
    throw InputError(
        scene.file, K > 1 ? "--subdivide" : "",
        fmt::format("{:.0f} elements ({} patches x {}) would need {:.1f} GiB for the exact solver "
                    "(three dense elements^2 matrices of doubles); the limit is {:.0f} GiB: {}",
                    n, scene.patches.size(), K, bytes / gib, exact_solver_memory_limit_bytes / gib,
                    K > 1 ? "lower --subdivide" : "use fewer segments"));
}

}  // namespace flatrad
