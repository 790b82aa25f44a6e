#include "cli/compare_command.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <cmath>
#include <limits>
#include <ostream>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/atomic_write.h"
#include "cli/progress.h"
#include "cli/result_json.h"
#include "cli/scene_warnings.h"
#include "cli/tolerance_flag.h"
#include "cli/usage_error.h"
#include "engine/error.h"
#include "solver/hierarchical_solver.h"

namespace flatrad {

namespace {

double max_of(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::isfinite(x) ? x : std::numeric_limits<double>::infinity());
    return m;
}

// A JSON number, or null when not finite (JSON has no inf or NaN).
nlohmann::ordered_json number(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); }

nlohmann::ordered_json patch_relative_json(const PatchRelative& q) {
    return {{"median", number(q.median)}, {"p90", number(q.p90)}, {"max", number(q.max)}};
}

// The error's figures, and where it lies: the patches with the largest
// shares of the squared error, each with both radiosities.
nlohmann::ordered_json error_json(const CompareError& e, const Scene& scene, const Solution& solution,
                                  const Solution& reference) {
    nlohmann::ordered_json j = {{"relative_l2", number(e.relative_l2)}, {"max_relative", number(e.max_relative)},
                                {"worst_patch", e.worst_patch}};
    nlohmann::ordered_json largest = nlohmann::ordered_json::array();
    for (const PatchErrorShare& s : e.largest) {
        const Patch& patch = scene.patches[static_cast<size_t>(s.patch)];
        nlohmann::ordered_json b = nlohmann::ordered_json::array(), r = nlohmann::ordered_json::array();
        for (double v : solution.patches[static_cast<size_t>(s.patch)].radiosity) b.push_back(number(v));
        for (double v : reference.patches[static_cast<size_t>(s.patch)].radiosity) r.push_back(number(v));
        largest.push_back({{"patch", s.patch},
                           {"surface", scene.surfaces[static_cast<size_t>(patch.surface)].name},
                           {"segment", patch.segment - scene.surfaces[static_cast<size_t>(patch.surface)].first_segment},
                           {"side", side_name(patch.side)},
                           {"share", number(s.share)},
                           {"radiosity", b},
                           {"reference", r}});
    }
    j["largest"] = largest;
    j["patch_relative"] = patch_relative_json(e.patch_relative);
    return j;
}

nlohmann::ordered_json run_json(const Solution& s) {
    nlohmann::ordered_json j;
    j["time_s"] = s.stats.time_s;
    j["elements"] = s.stats.elements;
    j["links"] = s.stats.links;
    j["balance"] = nlohmann::ordered_json::array();
    for (double b : s.totals.balance) j["balance"].push_back(number(b));
    j["escaped"] = nlohmann::ordered_json::array();
    for (double b : s.totals.escaped) j["escaped"].push_back(number(b));
    return j;
}

std::string sci(double v) { return std::isfinite(v) ? fmt::format("{:.3e}", v) : "inf"; }

}  // namespace

CLI::App* add_compare_command(CLI::App& app, CompareArgs& a) {
    CLI::App* cmd = app.add_subcommand("compare", "Hierarchical against exact: error and run time, side by side.");
    cmd->footer(
        "Solves the scene hierarchically, then exactly on a mesh and on its halves (every element cut in two): "
        "first K and 2K elements per patch (K from --subdivide, halved until the pair fits in half of "
        "--max-elements), doubling K while the pair fits in half of it, then graded meshes, each element cut "
        "where it and its halves disagree most, until the exact solution's own error (estimated as the "
        "relative L2 distance between the mesh and its halves) is at most 1/10 of the hierarchical error "
        "against the finer solution, or until the next step would pass --max-elements or the exact solver's "
        "memory limit (then \"reached\": false). Errors are "
        "over patch radiosities, length-weighted, all channels: relative_l2, and max_relative (largest "
        "|difference| over the reference's length-weighted RMS), both at the scale of the scene's light; "
        "and patch_relative: each patch's |difference| over its own reference value, its length-weighted "
        "median, 90th percentile and max (how well dim surfaces are known). Prints a table on stderr and JSON "
        "{scene, hierarchical, exact, reference} on stdout (or -o).\n"
        "Exit status: 0 done; 2 bad input or bad arguments (one line on stderr); 1 anything else.");
    cmd->add_option("SCENE", a.scene, "Scene file (JSON).")->required()->type_name("FILE");
    cmd->add_option("-o,--output", a.output, "JSON file to write (atomically); stdout without it.")
        ->type_name("OUT.json");
    cmd->add_option("--eps", a.eps, "Refinement tolerance of the hierarchical solver, > 0.")
        ->type_name("E")
        ->capture_default_str();
    cmd->add_option("--vis-eps", a.vis_eps,
                    "Visibility tolerance of the hierarchical solver, >= 0; default: eps / 10. 0: exact "
                    "visibility on every occluded link (none carries the density's estimate).")
        ->type_name("E");
    cmd->add_option("--subdivide", a.subdivide, "K >= 1: the first reference mesh, elements per patch.")
        ->type_name("K")
        ->capture_default_str();
    cmd->add_option("--reference-output", a.reference_output,
                    "Also write the exact reference's result file (SPEC.md \"Result file\"; settings.subdivide 0 "
                    "for a graded mesh), atomically.")
        ->type_name("REF.json");
    cmd->add_option("--max-elements", a.max_elements,
                    "Largest exact mesh tried (elements), >= 1; the exact solver's memory limit applies too.")
        ->type_name("N")
        ->capture_default_str();
    cmd->add_option("--threads", a.threads, "Threads; 0: all cores.")->type_name("N")->capture_default_str();
    cmd->add_flag("-q,--quiet", a.quiet, "No table on stderr (and no progress line).");
    return cmd;
}

int run_compare(const CompareArgs& args, std::ostream& out, std::ostream& err) {
    check_tolerance(args.eps, "--eps", true);
    check_tolerance(args.vis_eps, "--vis-eps");
    if (args.subdivide < 1)
        throw UsageError(fmt::format("--subdivide: expected an integer >= 1, got {}", args.subdivide));
    if (args.max_elements < 1)
        throw UsageError(fmt::format("--max-elements: expected an integer >= 1, got {}", args.max_elements));
    if (args.threads < 0)
        throw UsageError(fmt::format("--threads: expected an integer >= 0, got {}", args.threads));
    if (!args.output.empty()) check_output_path(args.output, "-o");
    if (!args.reference_output.empty()) check_output_path(args.reference_output, "--reference-output");
    if (!args.output.empty() && !args.reference_output.empty() &&
        std::filesystem::absolute(args.output).lexically_normal() ==
            std::filesystem::absolute(args.reference_output).lexically_normal())
        throw UsageError(fmt::format("-o and --reference-output name the same file: {}", args.output));

    const Scene scene = load_scene_reporting(args.scene, err);
    const long patches = static_cast<long>(scene.patches.size());
    check_reference_cap(scene, args.max_elements);

    // 1. Hierarchical, its progress drawn on a terminal (cli/progress.h).
    HierarchicalOptions h_options;
    h_options.eps = args.eps;
    h_options.vis_eps = args.vis_eps.value_or(-1);
    h_options.threads = args.threads;
    ProgressLine progress(err, !args.quiet && is_terminal_stderr(err));
    if (progress.enabled()) h_options.progress = progress.callback("compare: hierarchical: ");
    const Solution hier = solve_hierarchical(scene, h_options);
    progress.clear();

    // 2. The exact reference, refined until its own error is a tenth of the
    // hierarchical one (cli/reference_solution.h).
    ReferenceOptions r_options;
    r_options.subdivide = args.subdivide;
    r_options.max_elements = args.max_elements;
    r_options.threads = args.threads;
    if (!args.quiet)
        r_options.on_solve = [&err](long K, long elements) {
            err << fmt::format("compare: exact solve, {}\n", reference_mesh_name(K, elements)) << std::flush;
        };
    const Reference ref = solve_reference(scene, r_options, [&](const Solution& candidate) {
        return compare_solutions(scene, hier, candidate).relative_l2;
    });
    const Solution& reference = ref.solution();
    const long reference_K = ref.subdivide();
    const CompareError h_err = compare_solutions(scene, hier, reference);
    const double estimate = ref.error_estimate;
    const bool reached = ref.reached;
    nlohmann::ordered_json steps = nlohmann::ordered_json::array();
    for (const ReferenceStep& s : ref.steps)
        steps.push_back({{"subdivide", s.subdivide}, {"elements", s.elements}, {"error_estimate", number(s.error_estimate)},
                         {"hierarchical_relative_l2", number(s.compared_error)}});

    // 3. Report.
    nlohmann::ordered_json j;
    j["flatrad"] = 1;
    j["scene"] = scene.name;
    j["command"] = "compare";
    nlohmann::ordered_json h = {{"eps", hier.eps}, {"vis_eps", hier.vis_eps}};
    h["error"] = error_json(h_err, scene, hier, reference);
    h.update(run_json(hier));
    j["hierarchical"] = h;
    nlohmann::ordered_json x = {{"subdivide", reference_K}};
    x["error"] = {{"relative_l2", number(estimate)},
                  {"max_relative", number(ref.estimate_max_relative)},
                  {"patch_relative", patch_relative_json(ref.estimate_patch_relative)},
                  {"estimated", true}};
    x.update(run_json(reference));
    x["time_total_s"] = ref.time_total_s;
    j["exact"] = x;
    j["reference"] = {{"subdivide", reference_K},
                      {"mesh", ref.mesh_name()},
                      {"error_estimate", number(estimate)},
                      {"estimate_from_subdivide", ref.estimate_from_subdivide},
                      {"estimate_from", ref.estimate_from},
                      {"target", number(h_err.relative_l2 / reference_margin)},
                      {"reached", reached},
                      {"stopped", ref.stopped},
                      {"steps", steps}};
    const std::string text = j.dump(2) + "\n";
    // The reference's own result file first: if it cannot be written, no
    // comparison claims to have one.
    if (!args.reference_output.empty()) write_file_atomically(args.reference_output, result_text(scene, reference));
    if (args.output.empty())
        out << text << std::flush;
    else
        write_file_atomically(args.output, text);

    if (!args.quiet) {
        err << fmt::format("compare: {} ({} patches, {} channel{})\n", scene.name, patches, scene.channels,
                           scene.channels == 1 ? "" : "s");
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "", fmt::format("hierarchical"),
                           reference_K > 0 ? fmt::format("exact K={}", reference_K) : std::string("exact, graded"));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "settings",
                           fmt::format("eps {:g}", hier.eps), fmt::format("vis_eps {:g}", hier.vis_eps));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "relative L2 error", sci(h_err.relative_l2),
                           std::isfinite(estimate) ? "<= " + sci(estimate) + " (est.)" : "unknown");
        // An estimate of the reference's own error ("?" when there is none).
        auto estimated = [](double v) { return std::isnan(v) ? std::string("?") : "<= " + sci(v) + " (est.)"; };
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "max relative error", sci(h_err.max_relative),
                           estimated(ref.estimate_max_relative));
        // Each patch at its own scale (the dim ones too).
        const PatchRelative &hq = h_err.patch_relative, &rq = ref.estimate_patch_relative;
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "per patch: median", sci(hq.median), estimated(rq.median));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "           90%", sci(hq.p90), estimated(rq.p90));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "           max", sci(hq.max), estimated(rq.max));
        // Where the error lies: the patches with the largest shares of it.
        for (size_t q = 0; q < h_err.largest.size() && q < 3; ++q) {
            const PatchErrorShare& s = h_err.largest[q];
            const Patch& patch = scene.patches[static_cast<size_t>(s.patch)];
            const Surface& surface = scene.surfaces[static_cast<size_t>(patch.surface)];
            const std::string where =
                surface.segment_count > 1
                    ? fmt::format("{} segment {} {}", surface.name, patch.segment - surface.first_segment, side_name(patch.side))
                    : fmt::format("{} {}", surface.name, side_name(patch.side));
            // Its radiosity in the channel where it errs most.
            const auto& b = hier.patches[static_cast<size_t>(s.patch)].radiosity;
            const auto& r = reference.patches[static_cast<size_t>(s.patch)].radiosity;
            size_t c = 0;
            for (size_t k = 1; k < b.size(); ++k)
                if (std::abs(b[k] - r[k]) > std::abs(b[c] - r[c])) c = k;
            err << fmt::format("  {:<22}{:>18}   {}: {:.4g} against {:.4g}{}\n", q == 0 ? "largest errors" : "",
                               fmt::format("{:.1f}% of L2^2", 100 * s.share), where, b[c], r[c],
                               b.size() > 1 ? fmt::format(" (channel {})", c) : "");
        }
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "energy balance", sci(max_of(hier.totals.balance)),
                           sci(max_of(reference.totals.balance)));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "time", fmt::format("{:.3g} s", hier.stats.time_s),
                           fmt::format("{:.3g} s", reference.stats.time_s));
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "elements", hier.stats.elements, reference.stats.elements);
        err << fmt::format("  {:<22}{:>18}{:>22}\n", "links", hier.stats.links, reference.stats.links);
        if (reached)
            err << fmt::format("  reference: {}, its own error estimate {} <= 1/10 of the hierarchical error\n",
                               ref.mesh_name(), sci(estimate));
        else
            err << fmt::format("  reference NOT good enough: estimate {} > 1/10 of the hierarchical error {}; "
                               "stopped: {}\n",
                               sci(estimate), sci(h_err.relative_l2), ref.stopped);
        if (!args.output.empty()) err << "  written to " << args.output << '\n';
        if (!args.reference_output.empty()) err << "  the reference written to " << args.reference_output << '\n';
        err << std::flush;
    }
    return 0;
}

}  // namespace flatrad
