#include "cli/sweep_command.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <ostream>
#include <system_error>
#include <utility>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli/atomic_write.h"
#include "cli/formfactor_command.h"
#include "cli/median.h"
#include "cli/parse_whole.h"
#include "cli/reference_solution.h"
#include "cli/scene_warnings.h"
#include "cli/solution_sweep.h"
#include "cli/svg_plot.h"
#include "cli/usage_error.h"
#include "engine/scene.h"
#include "solver/group_form_factor.h"

namespace flatrad {

namespace {

// The summary's accuracy target: "how fast for 1% error".
constexpr double target_relative_error = 0.01;

const char* const blue = "#1f77b4";
const char* const orange = "#ff7f0e";
const char* const red = "#d62728";
const char* const grey = "#7f7f7f";


GammaRule parse_gamma(const std::string& name) {
    if (const auto r = gamma_rule_from_name(name)) return *r;
    throw UsageError(fmt::format("--gamma {}: expected bound, bound-uniform, paper or line-space", name));
}

std::string one_line(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

std::string ms(double seconds) { return fmt::format("{:.3g} ms", 1e3 * seconds); }

std::string percent(double r) { return std::isfinite(r) ? fmt::format("{:.3g}%", 100 * r) : "inf"; }

// The row the summary quotes: the largest eps within the target (rows
// come in the given order, so compare eps, not positions).
const SweepRow* largest_within_target(const Sweep& s) {
    const SweepRow* best = nullptr;
    for (const SweepRow& r : s.rows)
        if (r.relative_error <= target_relative_error && (!best || r.eps >= best->eps)) best = &r;
    return best;
}

long bound_violations(const Sweep& s) {
    long n = 0;
    for (const SweepRow& r : s.rows)
        if (r.error > r.error_bound + bound_rounding_slack * std::abs(s.F_exact)) ++n;
    return n;
}

struct PlotContext {
    std::string scene_name, from, to;
    const Sweep* sweep;
    double eps_lo, eps_hi;
};

PlotAxis eps_axis(const PlotContext& c) {
    PlotAxis x;
    x.label = "eps (tolerance on each cluster's error in F)";
    if (c.eps_hi > c.eps_lo) x.min = c.eps_lo, x.max = c.eps_hi;
    return x;
}

std::string title_of(const PlotContext& c, const std::string& what) {
    return fmt::format("{}: {} (gamma {})", c.scene_name, what, gamma_rule_name(c.sweep->rule));
}

// Soler 1995, Fig. 6: cost against eps.
SvgPlot time_plot(const PlotContext& c) {
    const Sweep& s = *c.sweep;
    SvgPlot p;
    p.title = title_of(c, "run time and clusters visited against eps");
    p.subtitle = fmt::format("{} -> {}; median of {} run{}; precomputation {:.3g} s ({} tables) not included", c.from,
                             c.to, s.repeat, s.repeat == 1 ? "" : "s", s.precomputation_s, s.tables_built);
    p.x = eps_axis(c);
    // Times span three decades (a fast query against a refined one that
    // integrates many approximated clusters): a log axis keeps both legible.
    p.y.label = "run time (ms, log)";
    p.y.scale = AxisScale::Log;
    p.y.color = blue;
    PlotAxis y2;
    y2.label = "clusters";
    y2.include_zero = true;
    y2.color = orange;
    p.y2 = y2;
    PlotSeries time{"run time (ms)", {}, {}, PlotMark::Line, blue};
    PlotSeries visited{"clusters visited", {}, {}, PlotMark::Line, orange};
    visited.right_axis = true;
    PlotSeries approximated{"clusters approximated", {}, {}, PlotMark::Line, orange};
    approximated.right_axis = true;
    approximated.dashed = true;
    for (const SweepRow& r : s.rows) {
        time.x.push_back(r.eps), time.y.push_back(1e3 * r.time_s);
        visited.x.push_back(r.eps), visited.y.push_back(static_cast<double>(r.clusters_visited));
        approximated.x.push_back(r.eps), approximated.y.push_back(static_cast<double>(r.clusters_approximated));
    }
    p.series = {time, visited, approximated};
    PlotRefLine exact;
    exact.label = fmt::format("exact method ({})", ms(s.exact_time_s));
    exact.value = 1e3 * s.exact_time_s;
    exact.color = grey;
    p.lines.push_back(exact);
    return p;
}

// Soler 1995, Fig. 7: F against eps, with the exact value and the claimed bound.
SvgPlot value_plot(const PlotContext& c) {
    const Sweep& s = *c.sweep;
    SvgPlot p;
    p.title = title_of(c, "form factor against eps");
    p.subtitle = fmt::format("{} -> {}; band: F_exact +- the error bound the method claims (clipped)", c.from, c.to);
    p.x = eps_axis(c);
    p.y.label = fmt::format("F ({} -> {})", c.from, c.to);
    PlotSeries F{"F (multiscale)", {}, {}, PlotMark::Line, blue};
    PlotBand band;
    band.label = "F_exact +- error bound";
    band.color = blue;
    for (const SweepRow& r : s.rows) {
        F.x.push_back(r.eps), F.y.push_back(r.F);
        band.x.push_back(r.eps);
        band.lo.push_back(s.F_exact - r.error_bound);
        band.hi.push_back(s.F_exact + r.error_bound);
    }
    // The band's x must increase; the rows come in the user's order, which
    // parse_eps_range makes increasing, but keep it safe for any order.
    std::vector<size_t> order(band.x.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return band.x[a] < band.x[b]; });
    PlotBand sorted = band;
    for (size_t k = 0; k < order.size(); ++k)
        sorted.x[k] = band.x[order[k]], sorted.lo[k] = band.lo[order[k]], sorted.hi[k] = band.hi[order[k]];
    p.series = {F};
    p.bands = {sorted};
    PlotRefLine exact;
    exact.label = fmt::format("exact F = {:.10g}", s.F_exact);
    exact.value = s.F_exact;
    exact.color = red;
    p.lines.push_back(exact);
    return p;
}

// Error against run time, log-log: what each millisecond buys.
SvgPlot error_plot(const PlotContext& c) {
    const Sweep& s = *c.sweep;
    SvgPlot p;
    p.title = title_of(c, "error against run time");
    long zero = 0;
    PlotSeries error{"|F - F_exact|, one point per eps", {}, {}, PlotMark::Points, blue};
    PlotSeries bound{"claimed error bound", {}, {}, PlotMark::Points, grey};
    for (const SweepRow& r : s.rows) {
        error.x.push_back(1e3 * r.time_s), error.y.push_back(r.error);
        bound.x.push_back(1e3 * r.time_s), bound.y.push_back(r.error_bound);
        if (!(r.error > 0)) ++zero;
    }
    p.subtitle = fmt::format("{} -> {}; median of {} run{}; {} of {} eps with error 0 not shown (log axis)", c.from,
                             c.to, s.repeat, s.repeat == 1 ? "" : "s", zero, s.rows.size());
    p.x.label = "run time (ms, log)";
    p.x.scale = AxisScale::Log;
    p.y.label = "absolute error in F (log)";
    p.y.scale = AxisScale::Log;
    p.series = {bound, error};
    PlotRefLine exact;
    exact.label = fmt::format("exact method ({})", ms(s.exact_time_s));
    exact.value = 1e3 * s.exact_time_s;
    exact.vertical = true;
    exact.color = red;
    p.lines.push_back(exact);
    return p;
}

void print_summary_tail(std::ostream& err, const Sweep& s, double wall_s, const std::vector<std::string>& written) {
    const SweepRow* best = largest_within_target(s);
    if (best)
        err << fmt::format(
            "largest eps with relative error <= {}: eps = {:.6g} (F = {:.10g}, relative error {}), {}: "
            "speed-up {:.3g} over exact\n",
            percent(target_relative_error), best->eps, best->F, percent(best->relative_error), ms(best->time_s),
            s.exact_time_s / best->time_s);
    else
        err << fmt::format("largest eps with relative error <= {}: none in the sweep\n", percent(target_relative_error));
    if (!s.rows.empty()) {
        const SweepRow& last = *std::max_element(s.rows.begin(), s.rows.end(),
                                                 [](const SweepRow& a, const SweepRow& b) { return a.eps < b.eps; });
        err << fmt::format("at the largest eps {:.6g}: F = {:.10g}, relative error {}, error bound {:.3g}, {}\n",
                           last.eps, last.F, percent(last.relative_error), last.error_bound, ms(last.time_s));
    }
    err << fmt::format("error > error_bound at {} of {} eps values\n", bound_violations(s), s.rows.size());
    if (s.tables_built_in_sweep > 0)
        err << fmt::format("note: {} cluster tables were built during the sweep, after the warm-up\n",
                           s.tables_built_in_sweep);
    std::string files;
    for (const std::string& w : written) files += (files.empty() ? "" : ", ") + w;
    err << fmt::format("sweep took {:.3g} s{}{}\n", wall_s, files.empty() ? "" : "; wrote ", files) << std::flush;
}

}  // namespace

std::vector<double> parse_eps_range(const std::string& spec) {
    auto bad = [&](const std::string& why) {
        return UsageError(fmt::format("--eps \"{}\": expected LO:HI:N with 0 <= LO <= HI and N an integer in "
                                      "[1, {}]: {}",
                                      one_line(spec), max_sweep_points, why));
    };
    const size_t c1 = spec.find(':');
    const size_t c2 = c1 == std::string::npos ? c1 : spec.find(':', c1 + 1);
    if (c2 == std::string::npos || spec.find(':', c2 + 1) != std::string::npos)
        throw bad("not three fields separated by ':'");
    const std::string lo_s = spec.substr(0, c1), hi_s = spec.substr(c1 + 1, c2 - c1 - 1), n_s = spec.substr(c2 + 1);
    double lo = 0, hi = 0;
    long n = 0;
    if (!parse_whole(lo_s, lo) || !std::isfinite(lo)) throw bad(fmt::format("LO \"{}\" is not a finite number", lo_s));
    if (!parse_whole(hi_s, hi) || !std::isfinite(hi)) throw bad(fmt::format("HI \"{}\" is not a finite number", hi_s));
    if (!parse_whole(n_s, n)) throw bad(fmt::format("N \"{}\" is not an integer", n_s));
    if (lo < 0) throw bad("LO < 0");
    if (hi < lo) throw bad("HI < LO");
    if (n < 1 || n > max_sweep_points) throw bad(fmt::format("N = {} is out of range", n));
    std::vector<double> eps(static_cast<size_t>(n));
    for (long k = 0; k < n; ++k)
        eps[static_cast<size_t>(k)] = n == 1 ? lo : lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(n - 1);
    if (n > 1) eps.back() = hi;  // exactly, whatever the rounding
    return eps;
}

Sweep run_form_factor_sweep(const FormFactorContext& context, const std::vector<int>& from,
                            const std::vector<int>& to, const std::vector<double>& eps, GammaRule rule, int repeat,
                            std::ostream* progress) {
    Sweep s;
    s.rule = rule;
    s.repeat = std::max(1, repeat);

    // 1. The exact value, timed.
    std::vector<double> times;
    for (int r = 0; r < s.repeat; ++r) {
        const GroupFormFactor g = context.compute(from, to, FormFactorMethod::Exact);
        s.F_exact = g.F;
        times.push_back(g.time_s);
    }
    s.exact_time_s = median(times);
    if (progress)
        *progress << fmt::format("exact: F = {:.15g} in {} (median of {})\n", s.F_exact, ms(s.exact_time_s), s.repeat)
                  << std::flush;

    // 2. Warm the lazily built cluster tables: the smallest positive eps
    // opens the most clusters and so asks for the most tables; the largest
    // asks for the top ones. A cluster opened at some eps is opened at
    // every smaller one, so the two together should cover the sweep; any
    // table built later is still counted (tables_built_in_sweep).
    double positive_min = std::numeric_limits<double>::infinity(), largest = 0;
    for (double e : eps) {
        largest = std::max(largest, e);
        if (e > 0) positive_min = std::min(positive_min, e);
    }
    for (double e : {largest, positive_min})
        if (e > 0 && std::isfinite(e)) {
            const GroupFormFactor g = context.compute(from, to, FormFactorMethod::Multiscale, {e, rule});
            s.precomputation_s += g.table_seconds;
        }
    const long warm_tables = context.tables().built();
    if (progress)
        *progress << fmt::format("precomputation: {} cluster tables ({:.3g} MiB) in {:.3g} s; sweeping {} eps x {} run{}\n",
                                 warm_tables,
                                 static_cast<double>(warm_tables) *
                                     static_cast<double>(ClusterTables::bytes_per_table()) / (1024.0 * 1024.0),
                                 s.precomputation_s, eps.size(), s.repeat, s.repeat == 1 ? "" : "s")
                  << std::flush;

    // 3. The sweep proper.
    s.rows.reserve(eps.size());
    for (double e : eps) {
        SweepRow row;
        row.eps = e;
        times.clear();
        for (int r = 0; r < s.repeat; ++r) {
            const GroupFormFactor g = context.compute(from, to, FormFactorMethod::Multiscale, {e, rule});
            s.precomputation_s += g.table_seconds;
            times.push_back(g.time_s);
            // The method is deterministic: every run gives the same values.
            row.F = g.F;
            row.error_bound = g.error_bound;
            row.clusters_visited = g.stats.clusters_visited;
            row.clusters_approximated = g.stats.approximated;
        }
        row.time_s = median(times);
        row.error = std::abs(row.F - s.F_exact);
        row.relative_error = s.F_exact != 0 ? row.error / std::abs(s.F_exact)
                             : row.error == 0 ? 0.0
                                              : std::numeric_limits<double>::infinity();
        s.rows.push_back(row);
    }
    s.tables_built = context.tables().built();
    s.tables_built_in_sweep = s.tables_built - warm_tables;
    s.table_bytes = static_cast<size_t>(s.tables_built) * ClusterTables::bytes_per_table();
    return s;
}

std::string sweep_csv(const Sweep& s, const std::string& scene_label, const std::string& from,
                      const std::string& to) {
    std::string csv = one_line(fmt::format(
        "# flatrad sweep: scene {}, from {}, to {}, gamma {}, repeat {}, F_exact {}, exact_time_s {}, "
        "precomputation_s {}, tables_built {}, table_bytes {}, tables_built_in_sweep {}",
        scene_label, from, to, gamma_rule_name(s.rule), s.repeat, s.F_exact, s.exact_time_s, s.precomputation_s,
        s.tables_built, s.table_bytes, s.tables_built_in_sweep));
    csv += "\neps,F,F_exact,error,relative_error,error_bound,time_s,clusters_visited,clusters_approximated\n";
    for (const SweepRow& r : s.rows)
        csv += fmt::format("{},{},{},{},{},{},{},{},{}\n", r.eps, r.F, s.F_exact, r.error, r.relative_error,
                           r.error_bound, r.time_s, r.clusters_visited, r.clusters_approximated);
    return csv;
}

CLI::App* add_sweep_command(CLI::App& app, SweepArgs& a) {
    CLI::App* cmd = app.add_subcommand(
        "sweep", "Error against run time over a range of tolerances: a multiscale form factor (--from/--to) or "
                 "whole hierarchical solutions (CSV, SVG plots).");
    cmd->footer(fmt::format(
        "With --from A --to B: computes the exact form factor from A to B (timed, median of --repeat runs), warms "
        "the cluster tables (reported apart as precomputation), then the multiscale form factor at each eps, "
        "--repeat times, keeping the median time. Writes a CSV table: a '#' comment line, then "
        "eps,F,F_exact,error,relative_error,error_bound,time_s,clusters_visited,clusters_approximated. "
        "With --svg PREFIX also PREFIX-time.svg (run time and clusters against eps, Soler 1995 Fig. 6), "
        "PREFIX-F.svg (F against eps with the exact value and the claimed bound, Fig. 7) and "
        "PREFIX-error.svg (error against run time, log-log). A summary goes to stderr unless --quiet: "
        "the largest eps within 1% relative error, its time and speed-up, and how many eps had an error "
        "above the claimed bound. The default sweep (800 eps x 3 runs) takes a minute or more.\n"
        "Without --from/--to: solves the scene hierarchically at each eps (--repeat times, median time; "
        "--vis-eps fixed, or eps/10 for each eps), then one exact reference built as by "
        "'flatrad compare' (K doubled from --subdivide, then graded meshes) until its own error estimate (a "
        "mesh against its halves) is at most 1/10 of the SMALLEST hierarchical error of the sweep (or "
        "--max-elements or the exact solver's memory limit stops it, reported as reached false). Writes a "
        "CSV table: '#' comment lines (the reference; every exact solve of the doubling, with its error "
        "against the reference), then "
        "eps,vis_eps,time_s,relative_l2,max_relative,balance,elements,links,iterations,reference_subdivide,"
        "reference_time_s,patch_relative_median,patch_relative_p90 (errors over patch radiosities, "
        "length-weighted, all channels, as in compare; the last two each patch's error over its own "
        "reference value). "
        "With --svg PREFIX also PREFIX-error.svg (relative L2 error against run time, log-log, beside the exact "
        "solver's own error and time) and PREFIX-eps.svg (errors, the per-patch median and energy balance against "
        "eps). A table goes "
        "to stderr unless --quiet, and a progress line while a solve runs when stderr is a terminal.\n"
        "Exit status: 0 done; 2 bad input or bad arguments (one line on stderr); 1 anything else."));
    cmd->add_option("SCENE", a.scene, "Scene file (JSON).")->required()->type_name("FILE");
    cmd->add_option_function<std::string>(
           "--from", [&a](const std::string& v) { a.from = v; },
           "Form-factor sweep: sending surface name(s); several, separated by commas, form one group. "
           "Without --from and --to, whole solutions are swept.")
        ->type_name("A");
    cmd->add_option_function<std::string>(
           "--to", [&a](const std::string& v) { a.to = v; },
           "Form-factor sweep: receiving surface name(s), comma-separated as for --from.")
        ->type_name("B");
    cmd->add_option("--eps", a.eps,
                    fmt::format("Form-factor sweep: LO:HI:N, N tolerances linearly spaced from LO to HI, both "
                                "included (0 <= LO <= HI, 1 <= N <= {}; N = 1 runs LO alone); default {}. "
                                "Whole-solution sweep: a list E1,E2,..., or A:B:N (linear) or A:B:Nlog "
                                "(log-spaced) from A to B, both included, every value > 0, "
                                "1 <= N <= {}; default {} (9 values from 0.1 down to 1e-5).",
                                max_sweep_points, default_form_factor_sweep_eps, max_solution_sweep_points,
                                default_solution_sweep_eps))
        ->type_name("SPEC");
    cmd->add_option_function<std::string>(
           "--gamma", [&a](const std::string& v) { a.gamma = v; },
           "Form-factor sweep: the multiscale criterion: bound (rigorous L1 line-space bound, the default), "
           "bound-uniform, paper (Soler 1995's Gamma as written) or line-space (DESIGN's L2 variant).")
        ->type_name("RULE")
        ->check(CLI::IsMember({"bound", "bound-uniform", "paper", "line-space"}));
    cmd->add_option("--repeat", a.repeat, "Runs per point, >= 1; times are medians.")
        ->type_name("R")
        ->capture_default_str();
    cmd->add_option_function<double>(
           "--vis-eps", [&a](const double& v) { a.vis_eps = v; },
           "Whole-solution sweep: the hierarchical solver's visibility tolerance, >= 0, the same for every eps; "
           "default: eps / 10 for each eps (the solver's default). 0: exact visibility on every occluded link.")
        ->type_name("E");
    cmd->add_option_function<int>(
           "--subdivide", [&a](const int& v) { a.subdivide = v; },
           "Whole-solution sweep: K >= 1, the first reference mesh (elements per patch); default 16.")
        ->type_name("K");
    cmd->add_option_function<long>(
           "--max-elements", [&a](const long& v) { a.max_elements = v; },
           fmt::format("Whole-solution sweep: largest exact mesh tried (patches x K), >= 1; default {}; the exact "
                       "solver's memory limit applies too.",
                       default_reference_max_elements))
        ->type_name("N");
    cmd->add_option_function<int>(
           "--threads", [&a](const int& v) { a.threads = v; },
           "Whole-solution sweep: threads of both solvers; 0 (default): all cores.")
        ->type_name("N");
    cmd->add_option("-o,--output", a.output,
                    "CSV file to write (atomically: a temporary file renamed). Without -o the table goes to stdout.")
        ->type_name("OUT.csv");
    cmd->add_option("--svg", a.svg,
                    "Also draw plots: PREFIX-time.svg, PREFIX-F.svg and PREFIX-error.svg (form-factor sweep); "
                    "PREFIX-error.svg and PREFIX-eps.svg (whole-solution sweep).")
        ->type_name("PREFIX");
    cmd->add_flag("-q,--quiet", a.quiet, "No summary on stderr (and no progress line).");
    return cmd;
}

int run_sweep(const SweepArgs& args, std::ostream& out, std::ostream& err) {
    // The mode: --from and --to together, or neither (whole solutions).
    if (args.from.has_value() != args.to.has_value())
        throw UsageError(fmt::format("{}: --from and --to go together (a form-factor sweep); give both, or neither "
                                     "to sweep whole solutions",
                                     args.from ? "--from without --to" : "--to without --from"));
    if (!args.from) {
        if (args.gamma) throw UsageError("--gamma: only for a form-factor sweep (--from A --to B)");
        return run_solution_sweep_command(args, out, err);
    }
    for (const auto& [given, flag] : {std::pair{args.vis_eps.has_value(), "--vis-eps"},
                                      std::pair{args.subdivide.has_value(), "--subdivide"},
                                      std::pair{args.max_elements.has_value(), "--max-elements"},
                                      std::pair{args.threads.has_value(), "--threads"}})
        if (given)
            throw UsageError(fmt::format("{}: only for a whole-solution sweep (without --from and --to)", flag));
    const std::string& from_names = *args.from;
    const std::string& to_names = *args.to;

    const auto t0 = std::chrono::steady_clock::now();
    // Arguments first: a typo must not cost a sweep.
    const GammaRule rule = parse_gamma(args.gamma.value_or("bound"));
    if (args.repeat < 1) throw UsageError(fmt::format("--repeat: expected an integer >= 1, got {}", args.repeat));
    const std::vector<double> eps = parse_eps_range(args.eps.empty() ? default_form_factor_sweep_eps : args.eps);
    if (!args.output.empty()) check_output_path(args.output, "-o");
    const std::vector<std::pair<std::string, std::string>> plots = {
        {"time", args.svg + "-time.svg"}, {"F", args.svg + "-F.svg"}, {"error", args.svg + "-error.svg"}};
    if (!args.svg.empty())
        for (const auto& [kind, path] : plots) check_output_path(path, "--svg");

    const Scene scene = load_scene_reporting(args.scene, err);
    const std::vector<int> from = surface_group(scene, from_names, "--from");
    const std::vector<int> to = surface_group(scene, to_names, "--to");

    if (!args.quiet)
        err << fmt::format("sweep: \"{}\", {} -> {}, gamma {}, {} eps in [{:.6g}, {:.6g}], median of {} run{}\n",
                           one_line(scene.name), from_names, to_names, gamma_rule_name(rule), eps.size(), eps.front(),
                           eps.back(), args.repeat, args.repeat == 1 ? "" : "s")
            << std::flush;
    const FormFactorContext context(scene);
    const Sweep sweep = run_form_factor_sweep(context, from, to, eps, rule, args.repeat, args.quiet ? nullptr : &err);

    // Outputs: the table, then the plots, each written whole or not at all.
    std::vector<std::string> written;
    const std::string csv = sweep_csv(sweep, fmt::format("\"{}\" ({})", scene.name, scene.file), from_names, to_names);
    if (args.output.empty()) {
        out << csv << std::flush;
    } else {
        write_file_atomically(args.output, csv);
        written.push_back(args.output);
    }
    if (!args.svg.empty()) {
        const PlotContext c{one_line(scene.name), from_names, to_names, &sweep,
                            *std::min_element(eps.begin(), eps.end()), *std::max_element(eps.begin(), eps.end())};
        for (const auto& [kind, path] : plots) {
            const SvgPlot p = kind == "time" ? time_plot(c) : kind == "F" ? value_plot(c) : error_plot(c);
            write_file_atomically(path, render_svg_plot(p));
            written.push_back(path);
        }
    }
    if (!args.quiet)
        print_summary_tail(err, sweep, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                           written);
    return 0;
}

}  // namespace flatrad
