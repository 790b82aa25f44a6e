#include "cli/solution_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>

#include <fmt/format.h>

#include "cli/atomic_write.h"
#include "cli/median.h"
#include "cli/parse_whole.h"
#include "cli/progress.h"
#include "cli/scene_warnings.h"
#include "cli/tolerance_flag.h"
#include "cli/usage_error.h"
#include "solver/hierarchical_solver.h"

namespace flatrad {

namespace {

const char* const blue = "#1f77b4";
const char* const orange = "#ff7f0e";
const char* const green = "#2ca02c";
const char* const red = "#d62728";
const char* const grey = "#7f7f7f";

// The first reference mesh when --subdivide is absent: as `flatrad compare`.
constexpr int default_reference_subdivide = 16;

std::string one_line(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

std::string sci(double v) { return std::isfinite(v) ? fmt::format("{:.3e}", v) : (std::isnan(v) ? "?" : "inf"); }

double max_of(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::isfinite(x) ? x : std::numeric_limits<double>::infinity());
    return m;
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    size_t k = 0;
    while (true) {
        const size_t next = s.find(sep, k);
        out.push_back(s.substr(k, next == std::string::npos ? std::string::npos : next - k));
        if (next == std::string::npos) return out;
        k = next + 1;
    }
}

// "K=64" or "graded 3977": a plot's point label.
std::string short_mesh(long K, const Solution& s) {
    return K > 0 ? fmt::format("K={}", K) : fmt::format("graded {}", s.stats.elements);
}

std::string scene_label(const Scene& scene) {
    return fmt::format("{} ({} patches, {} channel{})", one_line(scene.name), scene.patches.size(), scene.channels,
                       scene.channels == 1 ? "" : "s");
}

}  // namespace

std::vector<double> parse_eps_list(const std::string& spec) {
    auto bad = [&](const std::string& why) {
        return UsageError(fmt::format("--eps \"{}\": expected a list E1,E2,... or A:B:N or A:B:Nlog, every value a "
                                      "finite number > 0 and N an integer in [1, {}]: {}",
                                      one_line(spec), max_solution_sweep_points, why));
    };
    auto positive = [&](const std::string& field, const char* what) {
        double v = 0;
        if (!parse_whole(field, v) || !std::isfinite(v))
            throw bad(fmt::format("{} \"{}\" is not a finite number", what, field));
        if (!(v > 0)) throw bad(fmt::format("{} = {} is not > 0", what, field));
        return v;
    };
    std::vector<double> eps;
    if (spec.find(':') == std::string::npos) {
        // A list.
        for (const std::string& field : split(spec, ',')) eps.push_back(positive(field, "value"));
        if (static_cast<long>(eps.size()) > max_solution_sweep_points)
            throw bad(fmt::format("{} values is too many", eps.size()));
        return eps;
    }
    // A range, linear or log-spaced.
    const std::vector<std::string> fields = split(spec, ':');
    if (fields.size() != 3) throw bad("a range has three fields separated by ':'");
    const double a = positive(fields[0], "A"), b = positive(fields[1], "B");
    std::string n_field = fields[2];
    const bool log_spaced = n_field.size() >= 3 && n_field.compare(n_field.size() - 3, 3, "log") == 0;
    if (log_spaced) n_field.resize(n_field.size() - 3);
    long n = 0;
    if (!parse_whole(n_field, n)) throw bad(fmt::format("N \"{}\" is not an integer", n_field));
    if (n < 1 || n > max_solution_sweep_points) throw bad(fmt::format("N = {} is out of range", n));
    eps.resize(static_cast<size_t>(n));
    for (long k = 0; k < n; ++k) {
        const double t = n == 1 ? 0.0 : static_cast<double>(k) / static_cast<double>(n - 1);
        // Geometric: 10^(log10 a + t (log10 b - log10 a)), every step the
        // same ratio; decimal logs so that whole decades come out exact.
        const double v = log_spaced ? std::pow(10.0, std::log10(a) + t * (std::log10(b) - std::log10(a)))
                                    : a + t * (b - a);
        // Snapped to the nearest 15-digit decimal (what a double holds
        // faithfully): the ends are decimals the user wrote, and 0.01 should
        // not come out as 0.010000000000000004 in the table.
        double snapped = v;
        parse_whole(fmt::format("{:.15g}", v), snapped);  // from_chars: no locale
        eps[static_cast<size_t>(k)] = snapped;
    }
    eps.front() = a;  // exactly as written, whatever the rounding
    if (n > 1) eps.back() = b;
    return eps;
}

SolutionSweep run_solution_sweep(const Scene& scene, const SolutionSweepOptions& options, std::ostream* log,
                                 ProgressLine* progress) {
    SolutionSweep sweep;
    sweep.repeat = std::max(1, options.repeat);
    auto say = [&](const std::string& line) {
        if (progress) progress->clear();
        if (log) *log << line << '\n' << std::flush;
    };

    // 1. Hierarchical, each eps `repeat` times.
    std::vector<Solution> solutions;
    solutions.reserve(options.eps.size());
    for (size_t i = 0; i < options.eps.size(); ++i) {
        const double eps = options.eps[i];
        HierarchicalOptions h;
        h.eps = eps;
        h.vis_eps = options.vis_eps;
        h.threads = options.threads;
        std::vector<double> times;
        Solution solution;
        for (int r = 0; r < sweep.repeat; ++r) {
            if (progress && progress->enabled())
                h.progress = progress->callback(fmt::format("sweep: eps {:g} ({}/{}), run {}/{}: ", eps, i + 1,
                                                            options.eps.size(), r + 1, sweep.repeat));
            solution = solve_hierarchical(scene, h);
            times.push_back(solution.stats.time_s);
            if (i == 0 && r == 0 && !options.header.empty()) say(options.header);
        }
        SolutionSweepRow row;
        row.eps = solution.eps;
        row.vis_eps = solution.vis_eps;
        row.time_s = median(times);
        row.balance = max_of(solution.totals.balance);
        row.elements = solution.stats.elements;
        row.links = solution.stats.links;
        row.iterations = solution.stats.iterations;
        sweep.rows.push_back(row);
        say(fmt::format("sweep: eps {:g} (vis_eps {:g}): {:.3g} s, {} elements, {} links", row.eps, row.vis_eps,
                        row.time_s, row.elements, row.links));
        solutions.push_back(std::move(solution));
    }

    // 2. One reference, good enough for the best row of the sweep.
    ReferenceOptions reference = options.reference;
    if (log || progress)
        reference.on_solve = [&](long K, long elements) {
            say(fmt::format("sweep: exact solve, {}", reference_mesh_name(K, elements)));
            if (options.reference.on_solve) options.reference.on_solve(K, elements);
        };
    sweep.reference = solve_reference(scene, reference, [&](const Solution& candidate) {
        double smallest = std::numeric_limits<double>::infinity();
        for (const Solution& s : solutions)
            smallest = std::min(smallest, compare_solutions(scene, s, candidate).relative_l2);
        return smallest;
    });

    // 3. Errors against it.
    const Solution& ref = sweep.reference.solution();
    sweep.smallest_error = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < solutions.size(); ++i) {
        sweep.rows[i].error = compare_solutions(scene, solutions[i], ref);
        sweep.smallest_error = std::min(sweep.smallest_error, sweep.rows[i].error.relative_l2);
    }
    for (const Solution& s : sweep.reference.ladder) sweep.ladder_error.push_back(compare_solutions(scene, s, ref));
    return sweep;
}

std::string solution_sweep_csv(const SolutionSweep& s, const Scene& scene) {
    const Reference& r = s.reference;
    const Solution& ref = r.solution();
    std::string csv = one_line(fmt::format(
        "# flatrad sweep (whole solutions): scene \"{}\" ({}), patches {}, channels {}, repeat {}; errors over patch "
        "radiosities against the exact reference: subdivide {}, elements {}, time_s {}, time_total_s {}, "
        "error_estimate {} ({}), target {} (1/{} of the smallest relative_l2 {}), reached {}{}",
        scene.name, scene.file, scene.patches.size(), scene.channels, s.repeat, r.subdivide(), ref.stats.elements,
        ref.stats.time_s, r.time_total_s, r.error_estimate,
        !r.estimate_from.empty() ? r.estimate_from : "no pair of a mesh and its halves was solved",
        s.smallest_error / reference_margin, reference_margin, s.smallest_error, r.reached ? "true" : "false",
        r.stopped.empty() ? "" : ", stopped: " + r.stopped));
    csv += '\n';
    for (size_t k = 0; k < r.ladder.size(); ++k) {
        const bool last = k + 1 == r.ladder.size();
        csv += fmt::format("# exact subdivide {} elements {} time_s {} relative_l2 {} max_relative {}{}\n",
                           r.ladder_subdivide[k], r.ladder[k].stats.elements, r.ladder[k].stats.time_s,
                           s.ladder_error[k].relative_l2, s.ladder_error[k].max_relative,
                           last ? " (the reference itself)" : "");
    }
    csv += "eps,vis_eps,time_s,relative_l2,max_relative,balance,elements,links,iterations,reference_subdivide,"
           "reference_time_s,patch_relative_median,patch_relative_p90\n";
    for (const SolutionSweepRow& row : s.rows)
        csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{}\n", row.eps, row.vis_eps, row.time_s,
                           row.error.relative_l2, row.error.max_relative, row.balance, row.elements, row.links,
                           row.iterations, r.subdivide(), ref.stats.time_s, row.error.patch_relative.median,
                           row.error.patch_relative.p90);
    return csv;
}

SvgPlot solution_error_time_plot(const SolutionSweep& s, const Scene& scene) {
    const Reference& r = s.reference;
    SvgPlot p;
    p.title = fmt::format("{}: error against run time, hierarchical and exact", one_line(scene.name));
    long zero = 0;
    for (const SolutionSweepRow& row : s.rows)
        if (!(row.error.relative_l2 > 0)) ++zero;
    p.subtitle = fmt::format(
        "errors against exact {} (its own error {} estimated, {}); hierarchical time: median of {} run{}{}",
        r.mesh_name(), sci(r.error_estimate), r.reached ? "10x below every row" : "NOT 10x below every row",
        s.repeat, s.repeat == 1 ? "" : "s",
        zero ? fmt::format("; {} row{} with error 0 not shown (log axis)", zero, zero == 1 ? "" : "s") : "");
    p.x.label = "run time (s, log)";
    p.x.scale = AxisScale::Log;
    p.y.label = "relative L2 error over patches (log)";
    p.y.scale = AxisScale::Log;

    PlotSeries hier{"hierarchical, one point per eps", {}, {}, PlotMark::LineAndPoints, blue};
    for (const SolutionSweepRow& row : s.rows) {
        hier.x.push_back(row.time_s);
        hier.y.push_back(row.error.relative_l2);
        hier.point_labels.push_back(fmt::format("{:g}", row.eps));
    }
    // The exact solver's own curve: each coarser solve of the doubling
    // against the reference, and the reference at its estimated error.
    PlotSeries ladder{"exact at K, against the reference", {}, {}, PlotMark::LineAndPoints, orange};
    for (size_t k = 0; k + 1 < r.ladder.size(); ++k) {
        ladder.x.push_back(r.ladder[k].stats.time_s);
        ladder.y.push_back(s.ladder_error[k].relative_l2);
        ladder.point_labels.push_back(short_mesh(r.ladder_subdivide[k], r.ladder[k]));
    }
    PlotSeries reference{"reference, its estimated error", {}, {}, PlotMark::Points, red};
    reference.x.push_back(r.solution().stats.time_s);
    reference.y.push_back(r.error_estimate);
    reference.point_labels.push_back(short_mesh(r.subdivide(), r.solution()));
    p.series = {hier};
    if (!ladder.x.empty()) p.series.push_back(ladder);
    p.series.push_back(reference);
    PlotRefLine time;
    time.label = fmt::format("exact reference time ({:.3g} s)", r.solution().stats.time_s);
    time.value = r.solution().stats.time_s;
    time.vertical = true;
    time.color = red;
    p.lines.push_back(time);
    return p;
}

SvgPlot solution_error_eps_plot(const SolutionSweep& s, const Scene& scene) {
    const Reference& r = s.reference;
    SvgPlot p;
    p.title = fmt::format("{}: hierarchical error against eps", one_line(scene.name));
    p.subtitle = fmt::format("against exact {}; values of 0 (an exact balance) are not shown (log axis)",
                             r.mesh_name());
    p.x.label = "eps (relative refinement tolerance, log)";
    p.x.scale = AxisScale::Log;
    p.y.label = "error (log)";
    p.y.scale = AxisScale::Log;
    PlotSeries l2{"relative L2", {}, {}, PlotMark::LineAndPoints, blue};
    PlotSeries max{"max relative", {}, {}, PlotMark::LineAndPoints, orange};
    max.dashed = true;
    PlotSeries balance{"energy balance", {}, {}, PlotMark::LineAndPoints, green};
    // Each patch at its own scale (cli/solution_error.h): where the scene
    // has dim surfaces, far above the relative L2.
    PlotSeries per_patch{"per patch |B - R| / R, median", {}, {}, PlotMark::LineAndPoints, red};
    per_patch.dashed = true;
    for (const SolutionSweepRow& row : s.rows) {
        l2.x.push_back(row.eps), l2.y.push_back(row.error.relative_l2);
        max.x.push_back(row.eps), max.y.push_back(row.error.max_relative);
        balance.x.push_back(row.eps), balance.y.push_back(row.balance);
        per_patch.x.push_back(row.eps), per_patch.y.push_back(row.error.patch_relative.median);
    }
    // Lines join the points in eps order, whatever order they were run in.
    for (PlotSeries* series : {&l2, &max, &balance, &per_patch}) {
        std::vector<size_t> order(series->x.size());
        for (size_t k = 0; k < order.size(); ++k) order[k] = k;
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return series->x[a] < series->x[b]; });
        PlotSeries sorted = *series;
        for (size_t k = 0; k < order.size(); ++k) sorted.x[k] = series->x[order[k]], sorted.y[k] = series->y[order[k]];
        *series = sorted;
    }
    p.series = {l2, max, balance, per_patch};
    if (std::isfinite(r.error_estimate) && r.error_estimate > 0) {
        PlotRefLine floor;
        floor.label = fmt::format("reference's own error (est. {})", sci(r.error_estimate));
        floor.value = r.error_estimate;
        floor.color = grey;
        p.lines.push_back(floor);
    }
    return p;
}

int run_solution_sweep_command(const SweepArgs& args, std::ostream& out, std::ostream& err) {
    const auto t0 = std::chrono::steady_clock::now();
    // Arguments first: a typo must not cost a sweep.
    SolutionSweepOptions o;
    o.eps = parse_eps_list(args.eps.empty() ? default_solution_sweep_eps : args.eps);
    if (args.repeat < 1) throw UsageError(fmt::format("--repeat: expected an integer >= 1, got {}", args.repeat));
    o.repeat = args.repeat;
    check_tolerance(args.vis_eps, "--vis-eps");
    if (args.vis_eps) o.vis_eps = *args.vis_eps;
    o.threads = args.threads.value_or(0);
    if (o.threads < 0) throw UsageError(fmt::format("--threads: expected an integer >= 0, got {}", o.threads));
    o.reference.subdivide = args.subdivide.value_or(default_reference_subdivide);
    if (o.reference.subdivide < 1)
        throw UsageError(fmt::format("--subdivide: expected an integer >= 1, got {}", o.reference.subdivide));
    o.reference.max_elements = args.max_elements.value_or(default_reference_max_elements);
    if (o.reference.max_elements < 1)
        throw UsageError(fmt::format("--max-elements: expected an integer >= 1, got {}", o.reference.max_elements));
    o.reference.threads = o.threads;
    if (!args.output.empty()) check_output_path(args.output, "-o");
    const std::vector<std::pair<std::string, std::string>> plots = {{"error", args.svg + "-error.svg"},
                                                                     {"eps", args.svg + "-eps.svg"}};
    if (!args.svg.empty())
        for (const auto& [kind, path] : plots) check_output_path(path, "--svg");

    const Scene scene = load_scene_reporting(args.scene, err);
    check_reference_cap(scene, o.reference.max_elements);

    if (!args.quiet)
        o.header = fmt::format("sweep: {}, {} eps from {:g} to {:g}, median of {} run{}", scene_label(scene),
                               o.eps.size(), o.eps.front(), o.eps.back(), o.repeat, o.repeat == 1 ? "" : "s");
    ProgressLine progress(err, !args.quiet && is_terminal_stderr(err));
    const SolutionSweep sweep = run_solution_sweep(scene, o, args.quiet ? nullptr : &err, &progress);
    progress.clear();

    // Outputs: the table, then the plots, each written whole or not at all.
    std::vector<std::string> written;
    const std::string csv = solution_sweep_csv(sweep, scene);
    if (args.output.empty()) {
        out << csv << std::flush;
    } else {
        write_file_atomically(args.output, csv);
        written.push_back(args.output);
    }
    if (!args.svg.empty())
        for (const auto& [kind, path] : plots) {
            const SvgPlot p = kind == "error" ? solution_error_time_plot(sweep, scene)
                                              : solution_error_eps_plot(sweep, scene);
            write_file_atomically(path, render_svg_plot(p));
            written.push_back(path);
        }

    if (!args.quiet) {
        const Reference& r = sweep.reference;
        err << fmt::format("  {:>10} {:>10} {:>10} {:>11} {:>11} {:>11} {:>10} {:>9} {:>9} {:>6}\n", "eps", "vis_eps",
                           "time_s", "rel. L2", "max rel.", "patch med.", "balance", "elements", "links", "iter");
        for (const SolutionSweepRow& row : sweep.rows)
            err << fmt::format("  {:>10.3g} {:>10.3g} {:>10.3g} {:>11} {:>11} {:>11} {:>10} {:>9} {:>9} {:>6}\n",
                               row.eps, row.vis_eps, row.time_s, sci(row.error.relative_l2),
                               sci(row.error.max_relative), sci(row.error.patch_relative.median), sci(row.balance),
                               row.elements, row.links, row.iterations);
        for (size_t k = 0; k < r.ladder.size(); ++k)
            err << fmt::format("  exact {}: {:.3g} s, relative L2 {}{}\n", reference_mesh_name(r.ladder_subdivide[k], r.ladder[k].stats.elements),
                               r.ladder[k].stats.time_s,
                               k + 1 < r.ladder.size() ? sci(sweep.ladder_error[k].relative_l2)
                                                       : "<= " + sci(r.error_estimate) + " (est.)",
                               k + 1 < r.ladder.size() ? "" : ": the reference");
        if (r.reached)
            err << fmt::format("  reference: {}, its own error estimate {} <= 1/10 of the smallest hierarchical "
                               "error {}\n",
                               r.mesh_name(), sci(r.error_estimate), sci(sweep.smallest_error));
        else
            err << fmt::format("  reference NOT good enough for every row: estimate {} > 1/10 of the smallest "
                               "hierarchical error {}; stopped: {}\n",
                               sci(r.error_estimate), sci(sweep.smallest_error), r.stopped);
        std::string files;
        for (const std::string& w : written) files += (files.empty() ? "" : ", ") + w;
        err << fmt::format("  sweep took {:.3g} s{}{}\n",
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                           files.empty() ? "" : "; wrote ", files)
            << std::flush;
    }
    return 0;
}

}  // namespace flatrad
