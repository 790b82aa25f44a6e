// Tests apps/cli/compare_command.h: `flatrad compare`, driven through run_cli.
#include "cli/compare_command.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "support/cli_run.h"
#include "solver/exact_solver.h"

namespace fs = std::filesystem;
using nlohmann::json;

using flatrad::test::is_one_error_line;
using flatrad::test::read_text;
using flatrad::test::Run;
using flatrad::test::run;
using flatrad::test::TempDir;

namespace {


// A closed unit box lit by its floor, a pillar casting shadows: small (8
// patches), so the exact reference converges within a few doublings, and
// with real discretisation error (shadow edges, corners).
const char* const pillar_box = R"({"flatrad": 1, "name": "box with a pillar",
 "materials": {"white": {"reflectance": 0.6}, "lamp": {"reflectance": 0.0, "emission": 1.0}},
 "surfaces": [
  {"name": "floor", "material": "lamp", "points": [[0,0],[1,0]], "side": "left"},
  {"name": "walls", "material": "white", "points": [[1,0],[1,1],[0,1],[0,0]], "side": "left"},
  {"name": "pillar", "material": "white", "points": [[0.4,0.3],[0.6,0.3],[0.6,0.5],[0.4,0.5]],
   "closed": true, "side": "out"}]})";

std::string write_scene(const std::string& text) {
    const fs::path p = fs::temp_directory_path() / ("flatrad_compare_test_" + std::to_string(::getpid()) + ".json");
    std::ofstream(p) << text;
    return p.string();
}

bool finite_number(const json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

}  // namespace

TEST_CASE("compare: JSON fields, finite errors, hierarchical error falls with eps") {
    const std::string scene = write_scene(pillar_box);
    double previous = 0, previous_balance = -1;
    for (const char* eps : {"1e-1", "1e-3"}) {
        CAPTURE(eps);
        const Run r = run({"compare", scene, "--eps", eps, "--max-elements", "2100"});
        REQUIRE(r.status == 0);
        CHECK(r.err.find("hierarchical") != std::string::npos);  // the table
        const json j = json::parse(r.out);
        CHECK(j["scene"] == "box with a pillar");
        for (const char* side : {"hierarchical", "exact"}) {
            CAPTURE(side);
            const json& s = j[side];
            CHECK(finite_number(s["error"]["relative_l2"]));
            CHECK(finite_number(s["error"]["max_relative"]));
            CHECK(finite_number(s["time_s"]));
            CHECK(s["elements"].get<long>() > 0);
            CHECK(s["links"].get<long>() > 0);
            REQUIRE(s["balance"].size() == 1);
            CHECK(finite_number(s["balance"][0]));
        }
        // The exact solver's balance is its linear solve's; the hierarchical
        // one's, in this closed box, is its transport error: it must fall.
        CHECK(j["exact"]["balance"][0].get<double>() <= 1e-9);
        const double balance = j["hierarchical"]["balance"][0].get<double>();
        if (previous_balance >= 0) CHECK(balance < previous_balance);
        previous_balance = balance;
        CHECK(j["hierarchical"]["eps"].get<double>() == std::stod(eps));
        const json& ref = j["reference"];
        CHECK(ref["subdivide"].get<long>() >= 32);
        CHECK(finite_number(ref["error_estimate"]));
        CHECK(ref["reached"].is_boolean());
        CHECK(ref["steps"].size() >= 1);
        // On this scene the target is reached well within 2100 elements.
        CHECK(ref["reached"].get<bool>());
        CHECK(ref["error_estimate"].get<double>() <=
              j["hierarchical"]["error"]["relative_l2"].get<double>() / 10);

        const double err = j["hierarchical"]["error"]["relative_l2"].get<double>();
        CHECK(err > 0);
        if (previous > 0) CHECK(err < previous);
        previous = err;
    }
    fs::remove(scene);
}

TEST_CASE("compare: -o writes the file, bad flags give status 2") {
    const std::string scene = write_scene(pillar_box);
    const fs::path out = fs::temp_directory_path() / ("flatrad_compare_out_" + std::to_string(::getpid()) + ".json");
    const Run r = run({"compare", scene, "-q", "--eps", "0.05", "--subdivide", "8", "--max-elements", "600", "-o",
                       out.string()});
    CHECK(r.status == 0);
    CHECK(r.out.empty());
    CHECK(r.err.empty());
    REQUIRE(fs::exists(out));
    std::ifstream in(out);
    const json j = json::parse(in);
    CHECK(j.contains("reference"));
    fs::remove(out);

    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"compare", scene, "--eps", "0"},
          std::vector<std::string>{"compare", scene, "--subdivide", "0"},
          std::vector<std::string>{"compare", scene, "--max-elements", "7"},  // 8 patches: not one element each
          std::vector<std::string>{"compare", scene, "--max-elements", "0"}}) {
        const Run b = run(bad);
        CHECK(b.status == 2);
        CHECK(b.err.rfind("error: ", 0) == 0);
    }
    // A first K beyond the cap is halved until its pair fits in half the
    // cap, not refused (8 patches, K = 1000 against a cap of 100: halved to
    // 3, its pair of 48 elements within 50); the refusal is for a cap below
    // one element per patch, which no halving helps.
    const Run big = run({"compare", scene, "-q", "--eps", "0.05", "--subdivide", "1000", "--max-elements", "100"});
    REQUIRE(big.status == 0);
    const json jb = json::parse(big.out);
    REQUIRE(jb["reference"]["steps"].size() >= 1);
    CHECK(jb["reference"]["steps"][0]["subdivide"].get<long>() == 3);
    const Run cap = run({"compare", scene, "--max-elements", "7"});
    CHECK(cap.err.find("--max-elements 7") != std::string::npos);
    CHECK(cap.err.find("raise --max-elements") != std::string::npos);
    fs::remove(scene);
}

TEST_CASE("compare: --reference-output writes the reference's result file, the one the errors are against") {
    const std::string scene = write_scene(pillar_box);
    const std::string stem = (fs::temp_directory_path() / ("flatrad_compare_ref_" + std::to_string(::getpid()))).string();
    const std::string ref_path = stem + "_ref.json", out_path = stem + "_out.json";
    const Run r = run({"compare", scene, "-q", "--eps", "0.05", "--subdivide", "4", "--max-elements", "200",
                       "--reference-output", ref_path, "-o", out_path});
    REQUIRE(r.status == 0);
    std::ifstream ref_in(ref_path), out_in(out_path);
    const json ref = json::parse(ref_in), cmp = json::parse(out_in);
    CHECK(ref["method"] == "exact");
    CHECK(ref["settings"]["subdivide"].get<long>() == cmp["reference"]["subdivide"].get<long>());
    REQUIRE(ref["patches"].size() == 8);
    long elements = 0;
    for (const auto& p : ref["patches"]) elements += static_cast<long>(p["elements"].size());
    CHECK(elements == cmp["exact"]["elements"].get<long>());
    // The patches the comparison names carry the file's radiosities.
    REQUIRE(cmp["hierarchical"]["error"]["largest"].size() >= 1);
    for (const auto& l : cmp["hierarchical"]["error"]["largest"]) {
        const auto& file_b = ref["patches"][l["patch"].get<size_t>()]["radiosity"];
        CHECK(file_b[0].get<double>() == l["reference"][0].get<double>());
    }
    fs::remove(ref_path);
    fs::remove(out_path);

    // One file for both, or a directory that does not exist: status 2, nothing written.
    const Run same = run({"compare", scene, "-q", "--reference-output", out_path, "-o",
                          (fs::path(out_path).parent_path() / "." / fs::path(out_path).filename()).string()});
    CHECK(same.status == 2);
    CHECK(same.err.find("same file") != std::string::npos);
    const Run missing = run({"compare", scene, "-q", "--reference-output", stem + "_no/dir/ref.json"});
    CHECK(missing.status == 2);
    CHECK(missing.err.find("--reference-output") != std::string::npos);
    CHECK_FALSE(fs::exists(out_path));
    fs::remove(scene);
}

TEST_CASE("compare: the mesh limit stops the doubling and says so") {
    const std::string scene = write_scene(pillar_box);
    // 8 patches: K = 4 (32 elements) fits alone, but a first pair must fit
    // in half the cap (20), so K is halved to 1 (8 elements, its pair 16),
    // then graded meshes of at most 20 elements (their halved pairs within
    // 40): not enough for eps 1e-3.
    const Run r = run({"compare", scene, "-q", "--eps", "1e-3", "--subdivide", "4", "--max-elements", "40"});
    REQUIRE(r.status == 0);
    const json j = json::parse(r.out);
    CHECK_FALSE(j["reference"]["reached"].get<bool>());
    CHECK(j["reference"]["stopped"].get<std::string>().find("--max-elements") != std::string::npos);
    CHECK(j["exact"]["elements"].get<long>() <= 40);
    REQUIRE(j["reference"]["steps"].size() >= 1);
    CHECK(j["reference"]["steps"][0]["subdivide"].get<long>() == 1);
    CHECK(finite_number(j["reference"]["error_estimate"]));
    CHECK(finite_number(j["hierarchical"]["error"]["relative_l2"]));
    fs::remove(scene);
}

TEST_CASE("compare_solutions: zero for equal solutions, scale-free") {
    const std::string path = write_scene(pillar_box);
    const flatrad::Scene scene = flatrad::load_scene(path);
    const flatrad::Solution a = flatrad::solve_exact(scene, {2, 0});
    CHECK(flatrad::compare_solutions(scene, a, a).relative_l2 == 0);
    CHECK(flatrad::compare_solutions(scene, a, a).worst_patch == -1);
    flatrad::Solution b = a;
    for (auto& p : b.patches) p.radiosity[0] *= 1.01;
    CHECK(flatrad::compare_solutions(scene, b, a).relative_l2 == doctest::Approx(0.01).epsilon(1e-9));
    fs::remove(path);
}

TEST_CASE("compare_solutions: where the error lies, largest shares first") {
    const std::string path = write_scene(pillar_box);
    const flatrad::Scene scene = flatrad::load_scene(path);
    const flatrad::Solution a = flatrad::solve_exact(scene, {2, 0});
    CHECK(flatrad::compare_solutions(scene, a, a).largest.empty());  // nothing to place
    // Two patches off by known amounts: shares L_p d_p^2 / sum.
    flatrad::Solution b = a;
    b.patches[2].radiosity[0] += 0.1;
    b.patches[5].radiosity[0] -= 0.3;
    const double w2 = scene.patches[2].length * 0.1 * 0.1, w5 = scene.patches[5].length * 0.3 * 0.3;
    const flatrad::CompareError e = flatrad::compare_solutions(scene, b, a);
    REQUIRE(e.largest.size() == 2);
    const bool five_first = w5 > w2;
    CHECK(e.largest[0].patch == (five_first ? 5 : 2));
    CHECK(e.largest[1].patch == (five_first ? 2 : 5));
    // (Rounding: the sums are taken in long double, the differences in
    // double, so a share is exact to ~1e-15 relative; 1e-12 is room.)
    constexpr double share_rounding = 1e-12;
    CHECK(e.largest[0].share == doctest::Approx(std::max(w2, w5) / (w2 + w5)).epsilon(share_rounding));
    CHECK(e.largest[1].share == doctest::Approx(std::min(w2, w5) / (w2 + w5)).epsilon(share_rounding));
    // Every patch off: at most largest_error_patches listed, in order.
    flatrad::Solution c = a;
    for (size_t p = 0; p < c.patches.size(); ++p) c.patches[p].radiosity[0] += 0.01 * static_cast<double>(p + 1);
    const flatrad::CompareError all = flatrad::compare_solutions(scene, c, a);
    REQUIRE(static_cast<int>(all.largest.size()) == std::min<int>(flatrad::largest_error_patches, static_cast<int>(scene.patches.size())));
    double sum = 0;
    for (size_t q = 0; q < all.largest.size(); ++q) {
        CAPTURE(q);
        CHECK(all.largest[q].share > 0);
        if (q > 0) CHECK(all.largest[q].share <= all.largest[q - 1].share);
        sum += all.largest[q].share;
    }
    CHECK(sum <= 1 + share_rounding);
    fs::remove(path);
}

TEST_CASE("compare_solutions: each patch at its own scale, by length-weighted quantiles") {
    const std::string path = write_scene(pillar_box);
    const flatrad::Scene scene = flatrad::load_scene(path);
    const flatrad::Solution a = flatrad::solve_exact(scene, {2, 0});
    for (const auto& p : a.patches) REQUIRE(p.radiosity[0] > 0);  // (every patch lit: q is finite)
    const flatrad::CompareError same = flatrad::compare_solutions(scene, a, a);
    CHECK(same.patch_relative.median == 0);
    CHECK(same.patch_relative.p90 == 0);
    CHECK(same.patch_relative.max == 0);
    // Every patch 10% high but one, k, 3x high: the median is 0.1 whatever
    // the brightness (the relative L2 is not), the max 2; the 90th
    // percentile is 2 exactly when k holds more than a tenth of the length.
    // (Rounding: B (1 + f) - B over B is f to a few ulps; 1e-12 is room.)
    constexpr double rounding = 1e-12;
    double total = 0;
    for (const auto& p : scene.patches) total += p.length;
    int over_tenth = 0, under_tenth = 0;  // both cases of the 90th percentile are checked
    for (size_t k : {size_t{0}, scene.patches.size() - 1}) {
        CAPTURE(k);
        ++(scene.patches[k].length > 0.1 * total ? over_tenth : under_tenth);
        flatrad::Solution b = a;
        for (size_t p = 0; p < b.patches.size(); ++p) b.patches[p].radiosity[0] *= p == k ? 3.0 : 1.1;
        const flatrad::CompareError e = flatrad::compare_solutions(scene, b, a);
        REQUIRE(scene.patches[k].length < 0.5 * total);
        CHECK(e.patch_relative.median == doctest::Approx(0.1).epsilon(rounding));
        CHECK(e.patch_relative.max == doctest::Approx(2.0).epsilon(rounding));
        CHECK(e.patch_relative.p90 == doctest::Approx(scene.patches[k].length > 0.1 * total ? 2.0 : 0.1).epsilon(rounding));
        // Scale-free: both solutions times 1000, the same quantiles.
        flatrad::Solution a2 = a, b2 = b;
        for (auto& p : a2.patches) p.radiosity[0] *= 1000;
        for (auto& p : b2.patches) p.radiosity[0] *= 1000;
        const flatrad::CompareError e2 = flatrad::compare_solutions(scene, b2, a2);
        CHECK(e2.patch_relative.median == doctest::Approx(e.patch_relative.median).epsilon(rounding));
        CHECK(e2.patch_relative.p90 == doctest::Approx(e.patch_relative.p90).epsilon(rounding));
    }
    CHECK(over_tenth == 1);   // the floor, 1 of 4.8
    CHECK(under_tenth == 1);  // a pillar side, 0.2 of 4.8
    // A patch dark in the reference: 0 where the solution is dark too, +inf
    // (the max) where it is not.
    flatrad::Solution dark = a;
    dark.patches[3].radiosity[0] = 0;
    CHECK(flatrad::compare_solutions(scene, dark, dark).patch_relative.max == 0);
    flatrad::Solution lit = dark;
    lit.patches[3].radiosity[0] = 0.5;
    CHECK(std::isinf(flatrad::compare_solutions(scene, lit, dark).patch_relative.max));
    fs::remove(path);
}

TEST_CASE("compare: the JSON and the table say where the error lies") {
    const std::string scene = write_scene(pillar_box);
    const Run r = run({"compare", scene, "--eps", "1e-1", "--max-elements", "2100"});
    REQUIRE(r.status == 0);
    const json j = json::parse(r.out);
    const json& largest = j["hierarchical"]["error"]["largest"];
    REQUIRE(largest.is_array());
    REQUIRE(!largest.empty());  // eps 0.1 leaves an error somewhere
    CHECK(largest.size() <= static_cast<size_t>(flatrad::largest_error_patches));
    const std::vector<std::string> surfaces{"floor", "walls", "pillar"};
    double previous = 2;
    for (const json& p : largest) {
        CHECK(std::find(surfaces.begin(), surfaces.end(), p["surface"].get<std::string>()) != surfaces.end());
        const double share = p["share"].get<double>();
        CHECK(share > 0);
        CHECK(share <= previous);
        previous = share;
        REQUIRE(p["radiosity"].size() == 1);
        REQUIRE(p["reference"].size() == 1);
        CHECK(p["radiosity"][0].get<double>() != p["reference"][0].get<double>());
    }
    CHECK(r.err.find("largest errors") != std::string::npos);
    // Each patch at its own scale, for the hierarchical solution and as the
    // reference's own estimate.
    const json& q = j["hierarchical"]["error"]["patch_relative"];
    REQUIRE(finite_number(q["median"]));
    REQUIRE(finite_number(q["p90"]));
    REQUIRE(finite_number(q["max"]));
    CHECK(q["median"].get<double>() > 0);  // eps 0.1 leaves every patch a little off
    CHECK(q["median"].get<double>() <= q["p90"].get<double>());
    CHECK(q["p90"].get<double>() <= q["max"].get<double>());
    CHECK(finite_number(j["exact"]["error"]["patch_relative"]["p90"]));
    CHECK(r.err.find("per patch: median") != std::string::npos);
    fs::remove(scene);
}
