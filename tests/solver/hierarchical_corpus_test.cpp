// The clustered hierarchical solver (now the default method) on every scene
// of the fuzz corpus that the reader accepts: extreme coordinates, slivers,
// near-collinear and touching geometry, reflectance near 1. The fuzz target
// itself checks the exact solver (fuzz/fuzz_checks.h); this runs the same
// inputs through solve_hierarchical and checks what must hold whatever the
// approximation: it finishes, every radiosity and total is finite, B >= E
// up to the linear solve's residual, and no patch is brighter than the
// closed-room bound E_max / (1 - rho_max) allows (by 1%).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/error.h"
#include "engine/scene.h"
#include "solver/hierarchical_solver.h"

using namespace flatrad;

TEST_CASE("hierarchical: every fuzz-corpus scene the reader accepts solves to finite, bounded radiosity") {
    // Scenes above this many patches are skipped to keep the suite short
    // (the corpus is mostly small; the data/ scenes are solved elsewhere).
    constexpr size_t max_patches = 400;
    // B >= E - this x max E: GMRES stops at 1e-12 relative residual, and a
    // stiff corpus scene (rho 0.999999) amplifies it by up to 1e6.
    constexpr double below_emission_tol = 1e-5;
    // The closed-room bound may be exceeded by the refinement error (eps 1e-2
    // of the mean exitant power per link, summed over a patch's links).
    constexpr double bound_slack = 1.01;
    const std::filesystem::path corpus = std::filesystem::path(FLATRAD_DATA_DIR) / ".." / "fuzz" / "corpus";
    REQUIRE(std::filesystem::is_directory(corpus));
    int solved = 0;
    for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
        std::ifstream in(entry.path(), std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        Scene scene;
        try {
            scene = parse_scene(text.str(), entry.path().filename().string());
        } catch (const InputError&) {
            continue;  // refused: the reader's business (tests/engine, extremes_test)
        }
        if (scene.patches.empty() || scene.patches.size() > max_patches) continue;
        CAPTURE(entry.path().filename().string());
        HierarchicalOptions o;
        o.eps = 1e-2;
        o.threads = 1;
        Solution sol;
        try {
            sol = solve_hierarchical(scene, o);
        } catch (const InputError&) {
            continue;  // a closed reflectance-1 room, refused as it must be
        }
        double e_max = 0, rho_max = 0;
        for (const Material& m : scene.materials)
            for (int c = 0; c < scene.channels; ++c) {
                e_max = std::max(e_max, m.emission[static_cast<size_t>(c)]);
                rho_max = std::max(rho_max, m.reflectance[static_cast<size_t>(c)]);
            }
        const double bound = rho_max < 1 ? e_max / (1 - rho_max) : INFINITY;
        bool finite = true, above_e = true, within_bound = true;
        for (size_t p = 0; p < scene.patches.size(); ++p) {
            const Material& m = scene.materials[static_cast<size_t>(scene.patches[p].material)];
            for (int c = 0; c < scene.channels; ++c) {
                const double b = sol.patches[p].radiosity[static_cast<size_t>(c)];
                finite = finite && std::isfinite(b);
                above_e = above_e && b >= m.emission[static_cast<size_t>(c)] - below_emission_tol * std::max(1.0, e_max);
                within_bound = within_bound && b <= bound_slack * bound + 1e-12;
            }
        }
        CHECK(finite);
        CHECK(above_e);
        CHECK(within_bound);
        for (double v : sol.totals.balance) CHECK(std::isfinite(v));
        ++solved;
    }
    MESSAGE("solved " << solved << " corpus scenes hierarchically");
    CHECK(solved >= 10);  // 15 of the committed corpus are accepted scenes today
}
