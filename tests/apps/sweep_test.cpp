// Tests apps/cli/sweep_command.h (`flatrad sweep`, driven in-process through
// run_cli), both its modes: the form-factor sweep and the sweep over whole
// solutions (apps/cli/solution_sweep.h); and the plot writer they use,
// apps/cli/svg_plot.h.
#include "cli/sweep_command.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <doctest/doctest.h>

#include "cli/cli.h"
#include "support/cli_run.h"
#include "cli/svg_plot.h"
#include "cli/solution_sweep.h"
#include "cli/usage_error.h"

namespace fs = std::filesystem;

using flatrad::test::is_one_error_line;
using flatrad::test::read_text;
using flatrad::test::Run;
using flatrad::test::run;
using flatrad::test::TempDir;

namespace {



std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string field;
    std::istringstream in(s);
    while (std::getline(in, field, sep)) out.push_back(field);
    return out;
}

struct Csv {
    std::vector<std::string> comments, header;
    std::vector<std::vector<double>> rows;
};

Csv parse_csv(const std::string& text) {
    Csv csv;
    for (const std::string& line : split(text, '\n')) {
        if (line.empty()) continue;
        if (line[0] == '#') {
            csv.comments.push_back(line);
        } else if (csv.header.empty()) {
            csv.header = split(line, ',');
        } else {
            std::vector<double> row;
            for (const std::string& f : split(line, ',')) row.push_back(std::stod(f));
            csv.rows.push_back(row);
        }
    }
    return csv;
}

const std::string fig5 = std::string(FLATRAD_DATA_DIR) + "/soler95-fig5.json";

const std::vector<std::string> expected_header = {
    "eps", "F", "F_exact", "error", "relative_error", "error_bound", "time_s", "clusters_visited",
    "clusters_approximated"};

// With nothing approximated the multiscale path is the exact one; only the
// order of a few compensated sums may differ: 1e-12 relative is far above
// that rounding and far below any approximation's effect.
constexpr double same_value_tol = 1e-12;

}  // namespace

TEST_CASE("parse_eps_range: N values from LO to HI, both ends included") {
    const std::vector<double> e = flatrad::parse_eps_range("0:0.04:5");
    REQUIRE(e.size() == 5);
    CHECK(e.front() == 0.0);
    CHECK(e.back() == 0.04);
    CHECK(e[2] == doctest::Approx(0.02).epsilon(1e-15));
    CHECK(flatrad::parse_eps_range("0:0.04:800").size() == 800);
    CHECK(flatrad::parse_eps_range("0.5:0.5:3") == std::vector<double>{0.5, 0.5, 0.5});
    CHECK(flatrad::parse_eps_range("0.25:1:1") == std::vector<double>{0.25});  // N = 1: LO alone
    CHECK(flatrad::parse_eps_range("1e-3:2e-3:2") == std::vector<double>{1e-3, 2e-3});
    CHECK(flatrad::parse_eps_range("0:1:100000").size() == 100000);

    for (const char* bad : {"", "0:1", "0:1:2:3", "1:0:3", "-1:1:3", "0:1:0", "0:1:-2", "0:1:2.5", "0:1:100001",
                            "a:1:2", "0:b:2", "0:1:x", "0:inf:3", "nan:1:3", " 0:1:3", "0:1:3 ", "0::3", "::"}) {
        CAPTURE(bad);
        CHECK_THROWS_AS(flatrad::parse_eps_range(bad), flatrad::UsageError);
    }
}

TEST_CASE("sweep: soler95 fig. 5, five eps, CSV and three SVG plots") {
    TempDir tmp;
    const std::string csv_path = tmp.path("fig5.csv"), prefix = tmp.path("fig5");
    const Run r = run({"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:0.04:5", "--repeat", "1", "-o",
                       csv_path, "--svg", prefix, "--quiet"});
    REQUIRE(r.status == 0);
    CHECK(r.err.empty());  // --quiet
    CHECK(r.out.empty());  // the table went to -o

    const Csv csv = parse_csv(read_text(csv_path));
    REQUIRE(csv.comments.size() == 1);
    CHECK(csv.comments[0].find("soler95") != std::string::npos);
    CHECK(csv.comments[0].find("gamma bound") != std::string::npos);
    CHECK(csv.header == expected_header);
    REQUIRE(csv.rows.size() == 5);
    const double F_exact = csv.rows[0][2];
    CHECK(F_exact > 0);
    for (const auto& row : csv.rows) {
        REQUIRE(row.size() == 9);
        CAPTURE(row[0]);
        CHECK(row[2] == F_exact);                              // one exact value
        CHECK(row[3] == std::abs(row[1] - F_exact));           // round-trip doubles: exactly
        CHECK(row[3] <= row[5] + 1e-12);                       // the claimed bound holds
        CHECK(row[6] > 0);                                     // a time
        CHECK(row[7] >= row[8]);                               // approximated clusters were visited
    }
    CHECK(csv.rows[0][0] == 0.0);
    CHECK(csv.rows[0][3] <= same_value_tol * F_exact);  // eps = 0 is exact
    CHECK(csv.rows[0][8] == 0.0);                        // and approximates nothing
    CHECK(csv.rows[4][0] == 0.04);

    for (const char* kind : {"-time.svg", "-F.svg", "-error.svg"}) {
        CAPTURE(kind);
        const std::string svg = read_text(prefix + kind);
        CHECK(svg.rfind("<svg", 0) == 0);
        CHECK(svg.find("</svg>") != std::string::npos);
        CHECK(svg.find("soler95") != std::string::npos);  // title names the scene
        CHECK(svg.find("gamma bound") != std::string::npos);
    }
    // Nothing but the four outputs: no temporary file left behind.
    int files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(tmp.dir())) ++files;
    CHECK(files == 4);
}

TEST_CASE("sweep: table on stdout without -o, summary on stderr, any gamma") {
    for (const char* gamma : {"bound", "paper", "line-space"}) {
        CAPTURE(gamma);
        const Run r = run({"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:0.01:2", "--repeat", "1",
                           "--gamma", gamma});
        REQUIRE(r.status == 0);
        const Csv csv = parse_csv(r.out);
        CHECK(csv.header == expected_header);
        CHECK(csv.rows.size() == 2);
        CHECK(csv.comments.at(0).find(std::string("gamma ") + gamma) != std::string::npos);
        CHECK(r.err.find("exact: F = ") != std::string::npos);
        CHECK(r.err.find("largest eps with relative error <= 1%") != std::string::npos);
        CHECK(r.err.find("error > error_bound at") != std::string::npos);
    }
}

TEST_CASE("sweep: bad arguments give status 2, one line, and write nothing") {
    TempDir tmp;
    const std::string csv = tmp.path("x.csv");
    const std::vector<std::vector<std::string>> bad = {
        {"sweep"},                                                            // usage
        {"sweep", fig5, "--from", "S1"},                                      // missing --to
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:0.04"},     // two fields
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0.04:0:5"},   // HI < LO
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:1:0"},      // N = 0
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:1:1e9"},    // N not an integer
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "0:1:200000"}, // N too large
        {"sweep", fig5, "--from", "S1", "--to", "nope"},                      // unknown surface
        {"sweep", fig5, "--from", "S1,", "--to", "S2"},                       // empty name
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--gamma", "magic"},
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--repeat", "0"},
        {"sweep", fig5, "--from", "S1", "--to", "S2", "-o", tmp.path("no/such/dir.csv")},
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--svg", tmp.path("no/such/prefix")},
        {"sweep", tmp.path("missing.json"), "--from", "S1", "--to", "S2"},
    };
    for (const auto& args : bad) {
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        CAPTURE(joined);
        const Run r = run(args);
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.out.empty());
    }
    const Run eps = run({"sweep", fig5, "--from", "S1", "--to", "S2", "--eps", "1:0:3", "-o", csv});
    CHECK(eps.err.find("--eps") != std::string::npos);
    CHECK_FALSE(fs::exists(csv));
}

TEST_CASE("svg_plot: linear ticks are round and inside the range") {
    const std::vector<double> t = flatrad::linear_ticks(0, 0.04);
    REQUIRE(t.size() == 5);
    CHECK(t.front() == 0.0);
    CHECK(t.back() == doctest::Approx(0.04));
    CHECK(flatrad::linear_ticks(1, 1).empty());
    for (double v : flatrad::linear_ticks(0.0391, 0.0417)) {
        CHECK(v >= 0.0391 - 1e-12);
        CHECK(v <= 0.0417 + 1e-12);
    }
}

TEST_CASE("svg_plot: a standalone document, and log axes skip what they cannot draw") {
    flatrad::SvgPlot p;
    p.title = "a <title> & \"quotes\"";
    p.x.scale = flatrad::AxisScale::Log;
    p.y.scale = flatrad::AxisScale::Log;
    flatrad::PlotSeries s;
    s.label = "points";
    s.mark = flatrad::PlotMark::Points;
    s.x = {1e-3, 1e-2, 0.0, 1.0};
    s.y = {1.0, 0.0, 5.0, NAN};  // only the first point is drawable
    p.series = {s};
    flatrad::PlotRefLine v;
    v.vertical = true;
    v.value = 0.05;
    p.lines = {v};
    const std::string svg = flatrad::render_svg_plot(p);
    CHECK(svg.rfind("<svg", 0) == 0);
    CHECK(svg.size() >= 7);
    CHECK(svg.substr(svg.size() - 7) == "</svg>\n");
    CHECK(svg.find("a &lt;title&gt; &amp; &quot;quotes&quot;") != std::string::npos);
    CHECK(svg.find("<title>") == std::string::npos);
    CHECK(svg.find("nan") == std::string::npos);
    CHECK(svg.find("inf") == std::string::npos);
    size_t circles = 0;
    for (size_t k = svg.find("<circle"); k != std::string::npos; k = svg.find("<circle", k + 1)) ++circles;
    CHECK(circles == 2);  // the one drawable point and its legend swatch

    flatrad::SvgPlot bad;
    flatrad::PlotSeries ragged;
    ragged.x = {1, 2};
    ragged.y = {1};
    bad.series = {ragged};
    CHECK_THROWS_AS(flatrad::render_svg_plot(bad), std::invalid_argument);
    flatrad::SvgPlot no_y2;
    flatrad::PlotSeries right;
    right.right_axis = true;
    no_y2.series = {right};
    CHECK_THROWS_AS(flatrad::render_svg_plot(no_y2), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// `flatrad sweep SCENE` without --from/--to: whole solutions (cli/solution_sweep.h).

namespace {

// Closed unit box lit by one wall (4 patches): real discretisation error at
// the corners, and small enough that the exact reference is reached at
// K = 32 (128 elements) in a fraction of a second.
const std::string closed_box = std::string(FLATRAD_DATA_DIR) + "/closed_box.json";

const std::vector<std::string> solution_header = {
    "eps",   "vis_eps", "time_s",     "relative_l2", "max_relative",        "balance",
    "elements", "links", "iterations", "reference_subdivide", "reference_time_s", "patch_relative_median",
    "patch_relative_p90"};

// Refinement is greedy, so a smaller eps is not always better on every
// patch: a finer row may be up to this factor worse than the coarser row
// before it (on closed_box each is better, by 1.1x to 10x).
constexpr double monotone_slack = 1.5;
// Over two decades of eps the error must fall by at least this much
// (measured: 15x on closed_box). Loose on purpose: it is a property any
// hierarchical solver must have (error -> 0 as eps -> 0), not a figure of
// this one, and it still catches a sweep whose rows all solve alike.
constexpr double min_fall_over_two_decades = 4;

}  // namespace

TEST_CASE("parse_eps_list: lists, linear and log ranges, in the order written") {
    using flatrad::parse_eps_list;
    CHECK(parse_eps_list("0.1,0.03,0.01") == std::vector<double>{0.1, 0.03, 0.01});
    CHECK(parse_eps_list("1e-3") == std::vector<double>{1e-3});
    CHECK(parse_eps_list("0.1:0.3:3") == std::vector<double>{0.1, 0.2, 0.3});
    CHECK(parse_eps_list("0.3:0.1:3") == std::vector<double>{0.3, 0.2, 0.1});  // downwards
    // Log-spaced: whole decades exactly, the rest snapped to 15 digits.
    CHECK(parse_eps_list("1e-1:1e-4:4log") == std::vector<double>{0.1, 0.01, 0.001, 0.0001});
    const std::vector<double> d = parse_eps_list(flatrad::default_solution_sweep_eps);
    REQUIRE(d.size() == 9);
    CHECK(d.front() == 0.1);
    CHECK(d[2] == 0.01);
    CHECK(d.back() == 1e-5);
    CHECK(d[1] == doctest::Approx(std::sqrt(0.1 * 0.01)).epsilon(1e-14));  // geometric middle
    CHECK(parse_eps_list("0.5:0.5:1log") == std::vector<double>{0.5});
    CHECK(parse_eps_list("1:2:1000").size() == 1000);

    for (const char* bad : {"", ",", "0.1,", ",0.1", "0.1,,0.01", "0", "0.1,0", "-0.1", "nan", "inf", "1e-3x",
                            " 0.1", "a", "0.1:0.01", "0.1:0.01:3:4", "0:0.1:3", "0.1:0:3", "0.1:0.01:0",
                            "0.1:0.01:0log", "0.1:0.01:log", "0.1:0.01:3lin", "0.1:0.01:2.5", "1:2:1001",
                            "0.1:0.01:-3log"}) {
        CAPTURE(bad);
        CHECK_THROWS_AS(parse_eps_list(bad), flatrad::UsageError);
    }
    std::string many = "0.1";
    for (int k = 0; k < 1000; ++k) many += ",0.1";  // 1001 values
    CHECK_THROWS_AS(parse_eps_list(many), flatrad::UsageError);
}

TEST_CASE("sweep (whole solutions): CSV rows per eps, errors fall with eps, two plots") {
    TempDir tmp;
    const std::string csv_path = tmp.path("box.csv"), prefix = tmp.path("box");
    const Run r = run({"sweep", closed_box, "--eps", "0.1,0.01,0.001", "--repeat", "1", "-o", csv_path, "--svg",
                       prefix, "--quiet"});
    REQUIRE(r.status == 0);
    CHECK(r.err.empty());  // --quiet
    CHECK(r.out.empty());  // the table went to -o

    const Csv csv = parse_csv(read_text(csv_path));
    REQUIRE(csv.comments.size() >= 3);  // the reference, then one line per exact solve (at least K and 2K)
    CHECK(csv.comments[0].rfind("# flatrad sweep (whole solutions)", 0) == 0);
    CHECK(csv.comments[0].find("closed unit box") != std::string::npos);
    CHECK(csv.comments[0].find("reached true") != std::string::npos);
    CHECK(csv.comments.back().find("(the reference itself)") != std::string::npos);
    CHECK(csv.header == solution_header);
    REQUIRE(csv.rows.size() == 3);
    const double reference_K = csv.rows[0][9], reference_time = csv.rows[0][10];
    CHECK(reference_K >= 32);  // doubled at least once from the default 16
    CHECK(reference_time > 0);
    const std::vector<double> eps = {0.1, 0.01, 0.001};
    for (size_t k = 0; k < csv.rows.size(); ++k) {
        const std::vector<double>& row = csv.rows[k];
        CAPTURE(row[0]);
        REQUIRE(row.size() == solution_header.size());
        CHECK(row[0] == eps[k]);                        // in the order given
        CHECK(row[1] == doctest::Approx(eps[k] / 10));  // vis_eps defaults to eps / 10
        CHECK(row[2] > 0);                              // a time
        CHECK(row[3] > 0);                              // relative L2: not exact
        CHECK(std::isfinite(row[3]));
        CHECK(row[4] >= row[3] / 10);                   // max relative is of the same order or larger
        CHECK(row[5] >= 0);  // balance: the closed box's transport error (solver/hierarchical_solver.h)
        CHECK(row[6] > 0);                              // elements
        CHECK(row[7] > 0);                              // links
        CHECK(row[9] == reference_K);                   // one reference for the whole sweep
        CHECK(row[10] == reference_time);
        CHECK(row[11] >= 0);       // each patch at its own scale: the median,
        CHECK(row[12] >= row[11]);  // and the 90th percentile above it
        if (k > 0) CHECK(row[3] <= monotone_slack * csv.rows[k - 1][3]);
    }
    CHECK(csv.rows.back()[3] * min_fall_over_two_decades <= csv.rows.front()[3]);
    CHECK(csv.rows.back()[5] < csv.rows.front()[5]);  // the energy error falls too
    CHECK(csv.rows.back()[6] >= csv.rows.front()[6]);  // a finer eps refines more

    for (const char* kind : {"-error.svg", "-eps.svg"}) {
        CAPTURE(kind);
        const std::string svg = read_text(prefix + kind);
        CHECK(svg.rfind("<svg", 0) == 0);
        CHECK(svg.find("</svg>") != std::string::npos);
        CHECK(svg.find("closed unit box") != std::string::npos);  // the title names the scene
    }
    // The error plot labels each hierarchical point with its eps and shows
    // the exact reference's time.
    const std::string error_svg = read_text(prefix + "-error.svg");
    CHECK(error_svg.find(">0.001</text>") != std::string::npos);
    CHECK(error_svg.find("exact reference time") != std::string::npos);
    // The eps plot has the per-patch median beside the relative L2.
    CHECK(read_text(prefix + "-eps.svg").find("per patch |B - R| / R, median") != std::string::npos);
    // Nothing but the three outputs: no temporary file left behind.
    int files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(tmp.dir())) ++files;
    CHECK(files == 3);
}

TEST_CASE("sweep (whole solutions): table on stdout, summary on stderr, a fixed --vis-eps") {
    // At eps 1e-3 the error (3.1e-4) asks for a reference error below
    // 3.1e-5: K = 8 against 16 would pass half the cap (16 x 4 patches >
    // 32), so K = 4 against 8, then graded meshes of up to 32 elements
    // (4.7e-5), and the next graded step would pass the cap.
    const Run r = run({"sweep", closed_box, "--eps", "0.01:0.001:2log", "--vis-eps", "0.002", "--repeat", "2",
                       "--threads", "1", "--subdivide", "8", "--max-elements", "64"});
    REQUIRE(r.status == 0);
    const Csv csv = parse_csv(r.out);
    CHECK(csv.header == solution_header);
    REQUIRE(csv.rows.size() == 2);
    for (const auto& row : csv.rows) CHECK(row[1] == 0.002);
    CHECK(csv.rows[0][9] == 0);  // a graded reference
    CHECK(csv.comments.at(0).find("reached false") != std::string::npos);
    CHECK(csv.comments.at(0).find("--max-elements") != std::string::npos);
    CHECK(r.err.find("sweep: eps 0.01 (vis_eps 0.002)") != std::string::npos);
    CHECK(r.err.find("exact solve, K = 4 (16 elements)") != std::string::npos);
    CHECK(r.err.find("exact solve, graded (") != std::string::npos);
    CHECK(r.err.find("reference NOT good enough") != std::string::npos);
    CHECK(r.err.find("\033[K") == std::string::npos);  // a string stream gets no progress line
}

TEST_CASE("sweep (whole solutions): bad arguments give status 2, one line, and write nothing") {
    TempDir tmp;
    const std::string csv = tmp.path("x.csv");
    const std::vector<std::vector<std::string>> bad = {
        {"sweep", closed_box, "--eps", "0"},                    // eps must be > 0
        {"sweep", closed_box, "--eps", "0.1,,0.01"},            // empty field
        {"sweep", closed_box, "--eps", "0.1:0.01:0log"},        // N = 0
        {"sweep", closed_box, "--eps", "0.1;0.01"},             // not a number
        {"sweep", closed_box, "--to", "floor"},                 // --to without --from
        {"sweep", closed_box, "--gamma", "paper"},              // form-factor only
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--vis-eps", "0.1"},      // whole-solution only
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--subdivide", "4"},
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--max-elements", "100"},
        {"sweep", fig5, "--from", "S1", "--to", "S2", "--threads", "1"},
        {"sweep", closed_box, "--vis-eps", "-1"},
        {"sweep", closed_box, "--repeat", "0"},
        {"sweep", closed_box, "--subdivide", "0"},
        {"sweep", closed_box, "--max-elements", "0"},
        {"sweep", closed_box, "--threads", "-1"},
        {"sweep", closed_box, "--max-elements", "3"},  // 4 patches: not one element each within the cap
        {"sweep", closed_box, "-o", tmp.path("no/such/dir.csv")},
        {"sweep", closed_box, "--svg", tmp.path("no/such/prefix")},
        {"sweep", tmp.path("missing.json")},
    };
    for (const auto& args : bad) {
        std::string joined;
        for (const auto& a : args) joined += a + " ";
        CAPTURE(joined);
        const Run r = run(args);
        CHECK(r.status == 2);
        CHECK(is_one_error_line(r.err));
        CHECK(r.out.empty());
    }
    const Run eps = run({"sweep", closed_box, "--eps", "0.1,0", "-o", csv});
    CHECK(eps.err.find("--eps") != std::string::npos);
    CHECK_FALSE(fs::exists(csv));
    const Run gamma = run({"sweep", closed_box, "--gamma", "paper"});
    CHECK(gamma.err.find("--from") != std::string::npos);  // says what it needs
}

TEST_CASE("svg_plot: point labels beside drawable points, escaped, and checked for length") {
    flatrad::SvgPlot p;
    p.x.scale = flatrad::AxisScale::Log;
    flatrad::PlotSeries s;
    s.mark = flatrad::PlotMark::LineAndPoints;
    s.x = {0.1, 1.0, -1.0};  // the last cannot be drawn on a log axis
    s.y = {1.0, 2.0, 3.0};
    s.point_labels = {"a<b", "", "hidden"};
    p.series = {s};
    const std::string svg = flatrad::render_svg_plot(p);
    CHECK(svg.find(">a&lt;b</text>") != std::string::npos);
    CHECK(svg.find("hidden") == std::string::npos);

    s.point_labels = {"one"};
    p.series = {s};
    CHECK_THROWS_AS(flatrad::render_svg_plot(p), std::invalid_argument);
}
