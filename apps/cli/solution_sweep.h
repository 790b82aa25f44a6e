#pragma once
/// `flatrad sweep SCENE` without --from/--to (SPEC.md, "Command line";
/// DESIGN.md §5, "Error against run time"): the hierarchical solver over a
/// list of tolerances eps, each whole solution's error against ONE exact
/// reference beside its run time, as a CSV table and two SVG plots.
///
///   1. For each eps (in the order given): solve hierarchically, `repeat`
///      times; the time is the median of the runs' stats.time_s, the
///      solution (the solver is deterministic) that of the last run.
///   2. The reference (cli/reference_solution.h), exact K doubled until its
///      own error estimate is at most a tenth of the SMALLEST hierarchical
///      error of the sweep (so it is good enough for every row), or a cap
///      stops it (reported: `reached` false).
///   3. Each row's error against it (cli/solution_error.h): relative L2 and
///      max relative over patches; and every exact solve of the doubling
///      ladder against it too, which draws the exact solver's own error
///      against its run time beside the hierarchical curve.
#include <iosfwd>
#include <string>
#include <vector>

#include "cli/reference_solution.h"
#include "cli/solution_error.h"
#include "cli/svg_plot.h"
#include "cli/sweep_command.h"
#include "engine/scene.h"

namespace flatrad {

class ProgressLine;

/// Default --eps of the whole-solution sweep: nine values from 1e-1 down
/// to 1e-5, log-spaced (two per decade): a coarse picture to a fine one.
/// It reaches 1e-5 because that is where every closed data scene's energy
/// balance is within the 1e-4 (at 1e-4 data/closed_box.json is at
/// 1.9e-4 and data/furnished_room.json at 3.4e-4, forty-seventh session;
/// README, "Hierarchical solver", for the ninth's), so that the sweep's
/// tightest eps shows the goal. 4 to 12 s on data/default.json, 12 to 46 s
/// on data/tube_bank.json (one run per eps; the reference is graded further).
inline constexpr const char* default_solution_sweep_eps = "1e-1:1e-5:9log";

/// Largest number of eps values: each is a whole solve (up to seconds), so
/// a thousand is already hours; more is surely a typo.
inline constexpr int max_solution_sweep_points = 1000;

/// The eps values of a whole-solution --eps spec, in the order written:
///   E1,E2,...   a list (one value alone is a list too);
///   A:B:N       N values linearly spaced from A to B, both included;
///   A:B:Nlog    N values log-spaced (geometric) from A to B, both included.
/// Every value must be a finite number > 0 (the solver refines forever at
/// 0); A > B runs downwards. N = 1 gives A alone. Throws UsageError, one
/// line naming --eps, for anything else (empty fields, junk, N out of
/// [1, max_solution_sweep_points]).
std::vector<double> parse_eps_list(const std::string& spec);

struct SolutionSweepOptions {
    std::vector<double> eps;   ///< refinement tolerances, each > 0
    double vis_eps = -1;       ///< visibility tolerance for every eps; < 0: eps / 10 (the solver's default)
    int repeat = 3;            ///< solves per eps, >= 1; times are medians
    int threads = 0;           ///< hierarchical solver threads; 0: all cores
    ReferenceOptions reference;
    /// A line for the log once the first solve has succeeded, before its
    /// row's line (empty: none): a scene the solver refuses then leaves its
    /// one error line alone on stderr (SPEC.md).
    std::string header;
};

struct SolutionSweepRow {
    double eps = 0, vis_eps = 0;   ///< as the solver used them
    double time_s = 0;             ///< median of stats.time_s over the repeats
    CompareError error;            ///< against the reference
    double balance = 0;            ///< max over channels of totals.balance
    long elements = 0, links = 0, iterations = 0;
};

struct SolutionSweep {
    int repeat = 1;
    std::vector<SolutionSweepRow> rows;  ///< one per eps, in the given order
    Reference reference;
    /// Each exact solve of the ladder against the reference (the last, the
    /// reference itself, is 0 by definition: its own error is
    /// reference.error_estimate).
    std::vector<CompareError> ladder_error;
    double smallest_error = 0;  ///< the smallest hierarchical relative L2, which drove the reference
};

/// Runs steps 1-3 on `scene`. `log`, when given, gets one line per solve as
/// it finishes; `progress`, when given and enabled, draws each hierarchical
/// solve's progress (and is cleared before every log line).
/// Throws InputError from the solvers (a scene they refuse).
/// Pre: options valid (eps > 0, repeat >= 1, reference fits).
SolutionSweep run_solution_sweep(const Scene& scene, const SolutionSweepOptions& options, std::ostream* log = nullptr,
                                 ProgressLine* progress = nullptr);

/// The CSV table: comment lines ("# ..."): the scene, repeat and the
/// reference (K, 0 for a graded mesh; elements, time, error estimate,
/// target, reached, why it stopped), then one per exact ladder solve; the
/// header
/// eps,vis_eps,time_s,relative_l2,max_relative,balance,elements,links,iterations,reference_subdivide,reference_time_s,
/// patch_relative_median,patch_relative_p90 (cli/solution_error.h: each patch's error at its own scale;
/// reference_subdivide 0: a graded reference) and one row per eps, doubles with round-trip precision.
std::string solution_sweep_csv(const SolutionSweep& sweep, const Scene& scene);

/// Relative L2 error (log) against run time (log): the hierarchical rows
/// (each point labelled with its eps), the exact ladder (labelled K), the
/// reference at its estimated error, and a vertical line at its time.
SvgPlot solution_error_time_plot(const SolutionSweep& sweep, const Scene& scene);

/// Relative L2, max relative and energy balance against eps (log-log), with
/// the reference's own estimated error as a horizontal line (errors below it
/// are not resolved).
SvgPlot solution_error_eps_plot(const SolutionSweep& sweep, const Scene& scene);

/// `flatrad sweep SCENE` without --from/--to: validates the whole-solution
/// flags of `args` (UsageError), loads the scene (InputError), sweeps,
/// writes the CSV to args.output atomically (or to `out`), with args.svg
/// PREFIX-error.svg (solution_error_time_plot) and PREFIX-eps.svg
/// (solution_error_eps_plot), and a summary table on `err` unless
/// args.quiet.
int run_solution_sweep_command(const SweepArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
