#include "cli/summary.h"

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <ostream>
#include <vector>

#include <fmt/format.h>

namespace flatrad {

namespace {

// One value as is, several as (r, g, b).
std::string channels(const std::vector<double>& v) {
    if (v.size() == 1) return fmt::format("{:.6g}", v[0]);
    std::string s = "(";
    for (std::size_t c = 0; c < v.size(); ++c) s += fmt::format("{}{:.6g}", c ? ", " : "", v[c]);
    return s + ")";
}

// A residual this far above the solvers' own targets (1e-12 for the
// hierarchical GMRES, a few ulps for the exact LU; the reported residual is
// a max norm against the 2-norm GMRES stops at, which may differ by a few
// times) means the linear solve stopped short: said, not only shown.
constexpr double residual_warning = 1e-9;

// An energy balance above this (the transport's own loss or gain, as a
// share of the emitted light) is past the default eps's "about 1%" (README):
// said, with what it means. Where walls reflect most of the light, the error
// in B is larger still (the share comes back 1 / (1 - rho) times): at the
// default eps a room at reflectance 0.94 with a one-sided plate in it (its
// rows open: solver/closed_rows.h) shows a balance of 1.2e-2 with B off by
// 1.1e-2 relative L2 (docs/solver-history.md, forty-second session); the
// data scenes at the default eps: 2e-4 to 4.2e-3.
constexpr double balance_warning = 1e-2;

double mean(const std::vector<double>& v) {
    return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

void print_summary(std::ostream& os, const Scene& scene, const Solution& solution,
                   const std::string& written_to, int brightest) {
    const SolveStats& s = solution.stats;
    const std::string settings = solution.method == "hierarchical"
                                     ? fmt::format("eps {:g}, vis-eps {:g}", solution.eps, solution.vis_eps)
                                     : fmt::format("subdivide {}", solution.subdivide);
    os << fmt::format("flatrad: \"{}\" solved by {} ({}): {} patches, {} elements, {} links\n", scene.name,
                      solution.method, settings, scene.patches.size(), s.elements, s.links);
    os << fmt::format("  time {:.4g} s (form factors {:.4g} s, linear solve {:.4g} s, {} thread{})\n",
                      s.time_s, s.form_factor_time_s, s.linear_solve_time_s, s.threads,
                      s.threads == 1 ? "" : "s");
    const Totals& t = solution.totals;
    os << fmt::format("  energy: emitted {}, absorbed {}, escaped {}, balance {}; residual {:.3g}\n",
                      channels(t.emitted), channels(t.absorbed), channels(t.escaped),
                      channels(t.balance), s.residual);
    if (s.residual > residual_warning)
        os << fmt::format("  warning: the linear solve stopped at residual {:.3g}, short of its target; reflectance "
                          "near 1 makes the system stiff, and B may be off by about the residual over (1 - rho)\n",
                          s.residual);
    if (!s.refined_to_eps)
        os << fmt::format("  warning: refinement stopped after {} round{} with links still above the error bar: the "
                          "error may exceed what eps promises\n",
                          s.passes, s.passes == 1 ? "" : "s");
    const double worst_balance = t.balance.empty() ? 0.0 : *std::max_element(t.balance.begin(), t.balance.end());
    if (worst_balance > balance_warning)
        os << fmt::format("  warning: energy balance {:.3g}: the solution loses or makes that share of the emitted "
                          "light, and B may be off by as much or more where surfaces reflect most of it; a smaller "
                          "--eps tightens it\n",
                          worst_balance);

    std::vector<std::size_t> order(std::min(scene.patches.size(), solution.patches.size()));
    std::iota(order.begin(), order.end(), std::size_t{0});
    const std::size_t shown = std::min(order.size(), static_cast<std::size_t>(std::max(brightest, 0)));
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
                      [&](std::size_t i, std::size_t j) {
                          return mean(solution.patches[i].radiosity) > mean(solution.patches[j].radiosity);
                      });
    if (shown > 0) os << "  brightest patches (radiosity):\n";
    for (std::size_t k = 0; k < shown; ++k) {
        const std::size_t p = order[k];
        const Patch& patch = scene.patches[p];
        os << fmt::format("    {} segment {} {}: {}\n",
                          scene.surfaces[static_cast<std::size_t>(patch.surface)].name,
                          scene.segments[static_cast<std::size_t>(patch.segment)].index,
                          side_name(patch.side), channels(solution.patches[p].radiosity));
    }
    os << (written_to.empty() ? std::string("  result written to stdout\n")
                              : fmt::format("  result written to {}\n", written_to));
}

}  // namespace flatrad
