#include "cli/cli.h"

#include <algorithm>
#include <exception>
#include <new>
#include <ostream>

#include <CLI/CLI.hpp>

#include "cli/compare_command.h"
#include "cli/formfactor_command.h"
#include "cli/solve_command.h"
#include "cli/sweep_command.h"
#include "cli/usage_error.h"
#include "engine/error.h"

#ifndef FLATRAD_VERSION
#define FLATRAD_VERSION "unknown"
#endif

namespace flatrad {

namespace {

constexpr int exit_ok = 0;
constexpr int exit_failure = 1;  // anything but bad input
constexpr int exit_bad_input = 2;

// Errors are one line (SPEC.md, "Exit status"); a stray newline in a
// message would break that, so it is folded into a space.
void print_error(std::ostream& err, const std::string& message) {
    std::string line = message;
    for (char& c : line)
        if (c == '\n' || c == '\r') c = ' ';
    while (!line.empty() && line.back() == ' ') line.pop_back();
    err << "error: " << line << '\n' << std::flush;
}

bool is_command(CLI::App& app, const std::string& word) {
    const auto all = app.get_subcommands([](const CLI::App*) { return true; });
    return std::any_of(all.begin(), all.end(), [&](const CLI::App* sub) { return sub->check_name(word); });
}

// What each command's parser fills in.
struct Commands {
    SolveArgs solve;
    CLI::Option* solve_eps = nullptr;
    CLI::Option* solve_vis_eps = nullptr;
    FormFactorArgs formfactor;
    CLI::Option* formfactor_eps = nullptr;
    double eps_value = 0, vis_eps_value = 0, ff_eps_value = 0;

    CLI::App* solve_cmd = nullptr;
    CLI::App* formfactor_cmd = nullptr;
    CLI::App* compare_cmd = nullptr;
    CLI::App* sweep_cmd = nullptr;
    SweepArgs sweep;
    CompareArgs compare;
};

void add_solve(CLI::App& app, Commands& c) {
    CLI::App* cmd = app.add_subcommand("solve", "Solve a scene; write the result file (stdout without -o).");
    cmd->footer(
        "The result file is JSON (SPEC.md \"Result file\"): per patch its radiosity and elements, "
        "energy totals and stats. A summary goes to stderr unless --quiet.\n"
        "Exit status: 0 done; 2 bad input or bad arguments (one line on stderr); 1 anything else.");
    c.solve_cmd = cmd;
    SolveArgs& a = c.solve;
    cmd->add_option("SCENE", a.scene, "Scene file (JSON, SPEC.md \"Scene file\").")
        ->required()
        ->type_name("FILE");
    cmd->add_option("-o,--output", a.output,
                    "Result file to write (JSON). Written through a temporary file and renamed, "
                    "so it is never half-written; nothing is written if the solve fails. "
                    "Without -o the result goes to stdout and the summary to stderr.")
        ->type_name("RESULT.json");
    cmd->add_option("--method", a.method,
                    "hierarchical (the default): clusters and element trees joined by links refined "
                    "until each one's estimated error is within --eps, multi-scale visibility "
                    "(--vis-eps), GMRES. exact: every patch cut into K equal elements, every pair's "
                    "exact form factor, one dense linear system (the reference).")
        ->type_name("METHOD")
        ->check(CLI::IsMember({"exact", "hierarchical"}))
        ->capture_default_str();
    c.solve_eps = cmd->add_option("--eps", c.eps_value,
                                  "Refinement tolerance of the hierarchical solver, > 0, RELATIVE: a link "
                                  "may misplace at most E times the scene's mean exitant power per patch, "
                                  "so one value means about the same accuracy on any scene. Default 3e-3: "
                                  "0.06-0.2% relative L2 error on the data scenes (README, 'Hierarchical'), "
                                  "well inside 1%; 0.1 gives 0.4-1.2%, 1e-4 about 1e-4. Ignored by --method exact.")
                      ->type_name("E");
    c.solve_vis_eps = cmd->add_option("--vis-eps", c.vis_eps_value,
                                      "Visibility tolerance of the hierarchical solver (the "
                                      "paper's epsilon for Gamma), >= 0; default eps / 10. 0: exact "
                                      "visibility on every occluded link (none carries the density's "
                                      "estimate). Ignored by --method exact.")
                          ->type_name("E");
    cmd->add_option("--subdivide", a.subdivide,
                    "K >= 1: elements per patch for --method exact. Its three dense matrices need "
                    "3 x (patches x K)^2 x 8 bytes; more than 8 GiB is refused up front.")
        ->type_name("K")
        ->capture_default_str();
    cmd->add_option("--svg", a.svg,
                    "Draw the solution as an SVG picture (cli/scene_svg.h): each element colored by "
                    "its radiosity on its lit side, unlit sides grey; written atomically.")
        ->type_name("OUT.svg");
    cmd->add_option("--threads", a.threads, "Threads for the form factors; 0: all cores.")
        ->type_name("N")
        ->capture_default_str();
    cmd->add_flag("-q,--quiet", a.quiet,
                  "No summary on stderr, and no progress line (drawn only when stderr is a terminal).");
}

void add_formfactor(CLI::App& app, Commands& c) {
    CLI::App* cmd = app.add_subcommand(
        "formfactor", "Form factor between two groups of surfaces; prints one JSON object.");
    cmd->footer(
        "Prints {from, to, method, eps, F, F_reverse, time_s, clusters_visited, stats} on one line. "
        "Every segment of the scene is an occluder. F is the length-weighted form factor from A's "
        "lit patches to B's (a both-sided segment counts twice); F_reverse the same from B to A. "
        "A and B may name the same surface.\n"
        "Exit status: 0 done; 2 bad input or bad arguments (one line on stderr); 1 anything else.");
    c.formfactor_cmd = cmd;
    FormFactorArgs& a = c.formfactor;
    cmd->add_option("SCENE", a.scene, "Scene file (JSON).")->required()->type_name("FILE");
    cmd->add_option("--from", a.from,
                    "Sending surface name(s); several, separated by commas, form one group.")
        ->required()
        ->type_name("A");
    cmd->add_option("--to", a.to, "Receiving surface name(s), comma-separated as for --from.")
        ->required()
        ->type_name("B");
    cmd->add_option("--method", a.method,
                    "exact: exact visibility (the default). unoccluded: crossed strings, "
                    "ignoring every blocker. multiscale: clusters of blockers replaced by their "
                    "mean directional transmittance where the criterion allows (--eps, --gamma); "
                    "adds clusters_approximated and error_bound.")
        ->type_name("METHOD")
        ->check(CLI::IsMember({"exact", "unoccluded", "multiscale"}))
        ->capture_default_str();
    c.formfactor_eps = cmd->add_option(
        "--eps", c.ff_eps_value,
        "Tolerance of --method multiscale: each cluster is approximated only when its criterion "
        "(a bound on the error it adds to F, absolute) is below E; 0 approximates nothing and "
        "gives the exact value. Default 1e-3. Ignored by exact and unoccluded (reported as 0).")
                              ->type_name("E");
    cmd->add_option("--gamma", a.gamma,
                    "Criterion of --method multiscale: bound (line-space L1 bound charging only the "
                    "directions where the cluster interacts, the default), bound-uniform (the same "
                    "charging every direction), paper (Soler 1995's Gamma as written) or line-space "
                    "(DESIGN's L2 variant).")
        ->type_name("RULE")
        ->check(CLI::IsMember({"bound", "bound-uniform", "paper", "line-space"}))
        ->capture_default_str();
}

void add_not_yet(CLI::App& app, Commands& c) {
    c.compare_cmd = add_compare_command(app, c.compare);  // cli/compare_command.h
    c.sweep_cmd = add_sweep_command(app, c.sweep);  // cli/sweep_command.h
}

int dispatch(Commands& c, std::ostream& out, std::ostream& err) {
    if (c.solve_cmd->parsed()) {
        if (c.solve_eps->count() > 0) c.solve.eps = c.eps_value;
        if (c.solve_vis_eps->count() > 0) c.solve.vis_eps = c.vis_eps_value;
        return run_solve(c.solve, out, err);
    }
    if (c.formfactor_cmd->parsed()) {
        if (c.formfactor_eps->count() > 0) c.formfactor.eps = c.ff_eps_value;
        return run_formfactor(c.formfactor, out, err);
    }
    if (c.compare_cmd->parsed()) return run_compare(c.compare, out, err);
    if (c.sweep_cmd->parsed()) return run_sweep(c.sweep, out, err);
    throw UsageError("a command is required: solve, formfactor, compare or sweep (see flatrad --help)");
}

}  // namespace

int run_cli(int argc, char** argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"flatrad: 2D (flatland) radiosity with an exact-visibility reference solver.",
                 "flatrad"};
    app.set_version_flag("--version", std::string("flatrad ") + FLATRAD_VERSION);
    app.require_subcommand(0, 1);
    app.footer(
        "Exit status: 0 done; 2 bad input or bad arguments (one line on stderr); 1 anything else.\n"
        "Run 'flatrad COMMAND --help' for a command's flags.");
    Commands commands;
    add_solve(app, commands);
    add_formfactor(app, commands);
    add_not_yet(app, commands);

    // CLI11 would call an unknown command an unexpected argument; say what it is.
    if (argc > 1 && argv[1][0] != '-' && !is_command(app, argv[1])) {
        print_error(err, std::string("unknown command \"") + argv[1] +
                             "\": expected solve, formfactor, compare or sweep (see flatrad --help)");
        return exit_bad_input;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        // The top-level help shows every command's flags too.
        out << (app.get_subcommands().empty() ? app.help("", CLI::AppFormatMode::All) : app.help());
        return exit_ok;
    } catch (const CLI::CallForAllHelp&) {
        out << app.help("", CLI::AppFormatMode::All);
        return exit_ok;
    } catch (const CLI::CallForVersion&) {
        out << app.version() << '\n';
        return exit_ok;
    } catch (const CLI::ParseError& e) {
        // CLI11's own report spans several lines; ours is one.
        std::string where = "flatrad";
        for (const CLI::App* sub : app.get_subcommands()) where += " " + sub->get_name();
        print_error(err, std::string(e.what()) + " (see " + where + " --help)");
        return exit_bad_input;
    }

    try {
        return dispatch(commands, out, err);
    } catch (const UsageError& e) {
        print_error(err, e.what());
        return exit_bad_input;
    } catch (const InputError& e) {
        print_error(err, e.what());  // already "FILE: PATH: MESSAGE"
        return exit_bad_input;
    } catch (const std::bad_alloc&) {
        print_error(err, "out of memory");
        return exit_failure;
    } catch (const std::exception& e) {
        print_error(err, e.what());
        return exit_failure;
    }
}

int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
    std::vector<std::string> storage;
    storage.reserve(args.size() + 1);
    storage.emplace_back("flatrad");
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : storage) argv.push_back(s.data());
    argv.push_back(nullptr);
    return run_cli(static_cast<int>(storage.size()), argv.data(), out, err);
}

}  // namespace flatrad
