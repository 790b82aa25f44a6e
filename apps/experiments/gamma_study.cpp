// flatrad_gamma_study: does the criterion bound the error? (DESIGN.md §2,
// issue "multi-scale visibility": count how often |F_eps - F_exact| exceeds
// the error_bound the module reports, for each criterion.)
//
// Usage: flatrad_gamma_study [CONFIGS [SEED]]   (default 1000 configurations, seed 1)
// Configurations: two facing patches and a clumpy cloud of opaque segments
// between them (near and far, sparse and dense, small and large), from
// tests/support/clouds.h. For each configuration and each eps in
// {1e-4, 1e-3, 1e-2, 3e-2}, each rule's form factor is compared with the
// exact one.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "support/cloud_visibility.h"
#include "engine/formfactor.h"
#include "visibility/multiscale.h"

using namespace flatrad;

int main(int argc, char** argv) {
    const int configs = argc > 1 ? std::atoi(argv[1]) : 1000;
    const unsigned long seed = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 1;
    const double eps_list[] = {1e-4, 1e-3, 1e-2, 3e-2};
    const GammaRule rules[] = {GammaRule::Bound, GammaRule::BoundUniform, GammaRule::Paper, GammaRule::LineSpace};
    // Rounding floor: both values are sums exact to ~1e-15 of the
    // unoccluded F (a fully blocked pair has F = 0 but its arcs still sum
    // terms of that size), so 1e-12 of the unoccluded F.
    constexpr double rounding_floor = 1e-12;

    struct Tally {
        long runs = 0, approximating = 0, failures = 0;
        double worst_ratio = 0;   // largest error / bound among approximating runs
        double sum_ratio = 0;     // for the mean error / bound
        double time_s = 0;
        double worst_excess = 0;  // largest error - bound among failures
    };
    Tally tally[4][4];
    double exact_time = 0;
    std::mt19937_64 rng(seed);
    for (int t = 0; t < configs; ++t) {
        const test::Cloud c = test::make_cloud(rng);
        const test::CloudVisibility vis(c);
        const MultiscaleVisibility& ms = vis.multiscale;
        const ExactVisibility& ex = vis.exact;
        ExactWorkspace ws;
        VisibilityStats st;
        auto t0 = std::chrono::steady_clock::now();
        const double exact = ex.form_factor(c.i, c.j, 0, 1, ws, st);
        const double unoccluded = form_factor_unoccluded(c.i, c.j);
        exact_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        for (int r = 0; r < 4; ++r)
            for (int e = 0; e < 4; ++e) {
                t0 = std::chrono::steady_clock::now();
                const MultiscaleResult res = ms.form_factor(c.i, c.j, 0, 1, eps_list[e], rules[r], ws, st);
                Tally& y = tally[r][e];
                y.time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                ++y.runs;
                const double err = std::abs(res.F - exact);
                if (res.clusters_approximated > 0) {
                    ++y.approximating;
                    // Error / bound is only meaningful above rounding.
                    const double floor = rounding_floor * unoccluded;
                    const double ratio = res.error_bound > floor ? err / res.error_bound : 0;
                    y.worst_ratio = std::max(y.worst_ratio, ratio);
                    y.sum_ratio += ratio;
                }
                if (err > res.error_bound + rounding_floor * unoccluded) {
                    ++y.failures;
                    y.worst_excess = std::max(y.worst_excess, err - res.error_bound);
                }
            }
    }
    std::printf("# flatrad_gamma_study %d %lu: %d configurations, exact total %.3f s\n", configs, seed, configs,
                exact_time);
    std::printf("%-11s %-8s %6s %13s %9s %12s %12s %12s %10s\n", "rule", "eps", "runs", "approximating",
                "failures", "worst err/bd", "mean err/bd", "worst excess", "time s");
    for (int r = 0; r < 4; ++r)
        for (int e = 0; e < 4; ++e) {
            const Tally& y = tally[r][e];
            std::printf("%-11s %-8g %6ld %13ld %9ld %12.3g %12.3g %12.3g %10.3f\n", gamma_rule_name(rules[r]),
                        eps_list[e], y.runs, y.approximating, y.failures, y.worst_ratio,
                        y.approximating ? y.sum_ratio / static_cast<double>(y.approximating) : 0.0,
                        y.worst_excess, y.time_s);
        }
    return 0;
}
