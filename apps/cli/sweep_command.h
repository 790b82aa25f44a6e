#pragma once
/// `flatrad sweep` (SPEC.md, "Command line"; DESIGN.md §5), two modes:
///  - with --from A --to B (this file): the multi-scale form factor between
///    two groups of surfaces over a range of tolerances eps, each point's
///    value, error against the exact form factor, claimed error bound, run
///    time and clusters visited, as a CSV table and three SVG plots (Soler
///    1995, Fig. 6 and 7, and error against run time);
///  - without them: whole hierarchical solutions over a list of eps, each
///    one's error against one exact reference beside its run time
///    (cli/solution_sweep.h).
///
/// Form-factor mode:
/// The visibility structures are built once (FormFactorContext); the exact
/// value is computed first; the lazily built cluster tables are then warmed
/// by one query at the largest eps and one at the smallest positive eps, so
/// that the sweep's times are query times alone. Table building is
/// reported apart, as "precomputation".
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "visibility/multiscale.h"

namespace CLI {
class App;
}

namespace flatrad {

class FormFactorContext;

/// Default --eps of the form-factor sweep (the paper's Fig. 6 and 7 range).
inline constexpr const char* default_form_factor_sweep_eps = "0:0.04:800";

struct SweepArgs {
    std::string scene;               ///< scene file
    std::optional<std::string> from, to;  ///< comma-separated surface names; both absent: whole-solution sweep
    std::string eps;                 ///< the --eps spec; empty: the mode's default
    std::optional<std::string> gamma;  ///< form-factor mode: bound (default), bound-uniform, paper or line-space
    int repeat = 3;                  ///< runs per point; times are medians
    std::string output;              ///< CSV file; empty: stdout
    std::string svg;                 ///< plot file prefix; empty: no plots
    bool quiet = false;              ///< no summary (nor progress line) on stderr
    // Whole-solution mode only (refused with --from/--to):
    std::optional<double> vis_eps;   ///< fixed visibility tolerance; absent: eps / 10 for each eps
    std::optional<int> subdivide;    ///< first reference K (default 16)
    std::optional<long> max_elements;  ///< largest exact mesh (default default_reference_max_elements)
    std::optional<int> threads;      ///< solver threads (default 0: all cores)
};

/// Largest N of an --eps spec: a sweep is meant to be drawn, and 1e5
/// points already exceed any plot's resolution many times over.
inline constexpr int max_sweep_points = 100000;

/// The eps values of "LO:HI:N": N values linearly spaced from LO to HI,
/// both included (N = 1: LO alone). Throws UsageError (one line naming
/// --eps) unless LO and HI are finite numbers with 0 <= LO <= HI and N is
/// an integer in [1, max_sweep_points].
std::vector<double> parse_eps_range(const std::string& spec);

struct SweepRow {
    double eps = 0;
    double F = 0;
    double error = 0;           ///< |F - F_exact|
    double relative_error = 0;  ///< error / |F_exact| (0 when both are 0, +inf when only F_exact is)
    double error_bound = 0;     ///< the bound the method claims on error
    double time_s = 0;          ///< median over the repeats
    long clusters_visited = 0, clusters_approximated = 0;
};

struct Sweep {
    GammaRule rule = GammaRule::Bound;
    int repeat = 1;
    double F_exact = 0;
    double exact_time_s = 0;     ///< median over the repeats
    double precomputation_s = 0; ///< cluster table building, warm-up and sweep together
    long tables_built = 0;
    long tables_built_in_sweep = 0;  ///< after the warm-up (expected 0: the warm-up covers all)
    std::size_t table_bytes = 0;
    std::vector<SweepRow> rows;  ///< one per eps, in the given order
};

/// Runs the sweep on a built context: exact value (median time of
/// `repeat` runs), warm-up, then `repeat` multiscale runs per eps.
/// `progress`, when given, receives the exact value and the precomputation
/// as soon as they are known (one line each). Runs with at most one OpenMP
/// thread per patch of `from` (the previous setting restored afterwards):
/// compute() shares those patches among threads, and idle threads only add
/// a join, which on a loaded machine costs more than a fast query.
Sweep run_form_factor_sweep(const FormFactorContext& context, const std::vector<int>& from,
                            const std::vector<int>& to, const std::vector<double>& eps, GammaRule rule,
                            int repeat, std::ostream* progress = nullptr);

/// A row counts as exceeding its bound when error > error_bound + this
/// times |F_exact|: F and F_exact are compensated sums, equal values can
/// differ by a few ulps, and a bound of 0 (nothing approximated) must not
/// be "violated" by rounding.
inline constexpr double bound_rounding_slack = 64 * 2.220446049250313e-16;

/// The CSV table: one comment line ("# ...", naming the scene, surfaces,
/// rule, exact time and precomputation), the header
/// eps,F,F_exact,error,relative_error,error_bound,time_s,clusters_visited,clusters_approximated
/// and one row per eps, doubles with round-trip precision.
std::string sweep_csv(const Sweep& sweep, const std::string& scene_label, const std::string& from,
                      const std::string& to);

/// Registers the `sweep` sub-command's flags on `app`, filling `args`.
CLI::App* add_sweep_command(CLI::App& app, SweepArgs& args);

/// Validates `args` (UsageError; --from without --to or the reverse, and a
/// flag of the other mode, are refused), then runs the whole-solution sweep
/// (run_solution_sweep_command, cli/solution_sweep.h) when both are absent.
/// Form-factor mode: loads the scene (InputError), sweeps, writes the CSV
/// to args.output atomically (or to `out`) and, with args.svg,
/// PREFIX-time.svg, PREFIX-F.svg and PREFIX-error.svg; then a summary on
/// `err` unless args.quiet.
int run_sweep(const SweepArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
