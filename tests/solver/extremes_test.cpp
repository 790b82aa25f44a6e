// The extreme-case matrix (hardening issue) on the exact path: exact
// occluded form factors (visibility/exact_visibility.h), group form factors
// (solver/group_form_factor.h) and the exact solver (solver/exact_solver.h)
// on scenes at the edge of what doubles hold. Each case states what must
// happen: a value with a justified tolerance, or a clear refusal.
//
// Hand values for occluded pairs come from Hottel's strings stretched
// through a window: when every line from patch i to patch j crosses a line
// W (here always parallel to both), and it is visible exactly when it
// crosses W inside a window [u, v], then
//     L_i F_ij = 1/2 (T(a, c) + T(b, d) - T(a, d) - T(b, c)),
// T(p, q) the taut string from p to q through the window: the straight
// segment when it crosses W inside [u, v], else the path bent at the
// nearest window end (i = [a, b], j = [c, d], both lit toward each other;
// the same crossed-minus-uncrossed pairing as engine/formfactor.h). This
// shares nothing with the line-space integration it checks.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "engine/compensated_sum.h"
#include "engine/error.h"
#include "engine/formfactor.h"
#include "engine/hierarchy.h"
#include "engine/scene.h"
#include "fuzz/fuzz_checks.h"
#include "solver/exact_solver.h"
#include "solver/group_form_factor.h"
#include "visibility/exact_visibility.h"

using namespace flatrad;

namespace {

// An exact form factor is a compensated sum over arcs of a few roundings
// each (~1e-15 relative, tests/visibility/exact_visibility_test.cpp); the
// hand values are a dozen square roots. 1e-12 is the bar the exact engine
// issue set for reciprocity and closure, and it is used here as well.
constexpr double exact_tol = 1e-12;
// Scaled copies of one scene: every coordinate is rounded once when scaled
// by 10^k (not exact in binary), moving F by a few ulps: 1e-12 again.
constexpr double scale_tol = 1e-12;
// A direct solve of a well-conditioned system (condition ~ 1 / (1 - rho F)
// with rho F <= 0.42 here): B to ~1e-15; 1e-13 leaves a 100x margin.
constexpr double solve_tol = 1e-13;

double rel_err(double x, double ref) { return std::abs(x - ref) / std::abs(ref); }

std::string num(double x) { return fmt::format("{}", x); }

/// Taut string from (ax, 0) to (cx, h) through the window [u, v] on the
/// line y = w_y (0 < w_y < h).
double taut(double ax, double cx, double h, double w_y, double u, double v) {
    const double x = ax + (cx - ax) * (w_y / h);  // where the straight string crosses W
    if (x >= u && x <= v) return std::hypot(cx - ax, h);
    const double e = x < u ? u : v;
    return std::hypot(e - ax, w_y) + std::hypot(cx - e, h - w_y);
}

/// L_i F_ij for i = [a_x0, a_x1] on y = 0 lit up and j = [c_x1 .. c_x0]
/// on y = h lit down, through the window [u, v] at height w_y.
double exchange_through_window(double a0, double a1, double c0, double c1, double h, double w_y, double u,
                               double v) {
    // i = [a, b] = [(a0, 0), (a1, 0)]; j = [c, d] = [(c1, h), (c0, h)].
    const double crossed = taut(a0, c1, h, w_y, u, v) + taut(a1, c0, h, w_y, u, v);
    const double uncrossed = taut(a0, c0, h, w_y, u, v) + taut(a1, c1, h, w_y, u, v);
    return 0.5 * (crossed - uncrossed);
}

/// group_form_factor between surfaces named `from` and `to`.
GroupFormFactor group(const Scene& scene, const char* from, const char* to,
                      FormFactorMethod method = FormFactorMethod::Exact) {
    const int a = scene.find_surface(from), b = scene.find_surface(to);
    REQUIRE(a >= 0);
    REQUIRE(b >= 0);
    return group_form_factor(scene, {a}, {b}, method);
}

/// Facing unit plates at distance 1 (bottom lit up, top lit down) plus
/// `extra` surfaces, every coordinate scaled by s and shifted by (3 s, -2 s).
std::string plates_scene(double s, const std::string& extra_points_x_y = "") {
    const auto p = [s](double x, double y) { return fmt::format("[{}, {}]", num(x * s + 3 * s), num(y * s - 2 * s)); };
    std::string text = fmt::format(
        R"({{"flatrad": 1, "materials": {{"lamp": {{"emission": 1}}, "grey": {{"reflectance": 0.5}}}},
            "surfaces": [{{"name": "bottom", "material": "lamp", "points": [{}, {}]}},
                         {{"name": "top", "material": "grey", "points": [{}, {}]}})",
        p(0, 0), p(1, 0), p(1, 1), p(0, 1));
    if (!extra_points_x_y.empty()) {
        // "x0 y0 x1 y1": one two-sided blocker.
        double x0, y0, x1, y1;
        REQUIRE(std::sscanf(extra_points_x_y.c_str(), "%lf %lf %lf %lf", &x0, &y0, &x1, &y1) == 4);
        text += fmt::format(R"(, {{"name": "blocker", "material": "grey", "points": [{}, {}], "side": "both"}})",
                            p(x0, y0), p(x1, y1));
    }
    return text + "]}";
}

}  // namespace

// ---- the hand values themselves ----------------------------------------------

TEST_CASE("extremes: the window strings reproduce crossed strings and the centred blocker") {
    // A window covering the whole shaft changes nothing: sqrt(2) - 1.
    CHECK(rel_err(exchange_through_window(0, 1, 0, 1, 1, 0.5, -10, 10), std::sqrt(2.0) - 1) <= 1e-15);
    // The existing line-space check (tests/visibility/exact_visibility_test.cpp,
    // "a centred blocker"): blocker [0.25, 0.75] at y = 0.5; the two gaps sum
    // to sqrt(5)/2 - 1.
    const double X = exchange_through_window(0, 1, 0, 1, 1, 0.5, -10, 0.25) +
                     exchange_through_window(0, 1, 0, 1, 1, 0.5, 0.75, 10);
    CHECK(rel_err(X, std::sqrt(5.0) / 2 - 1) <= 1e-15);
}

// ---- coordinates from 1e-9 to 1e9, on the exact path --------------------------

TEST_CASE("extremes: exact F with a blocker is the same from 1e-9 to 1e9") {
    // Facing unit plates, a two-sided blocker [0.25, 0.75] at mid-height:
    // F = sqrt(5)/2 - 1 at every scale (form factors are scale-free), read
    // from scene text, every coordinate shifted too.
    const double ref = std::sqrt(5.0) / 2 - 1;
    for (int k = -9; k <= 9; ++k) {
        const double s = std::pow(10.0, k);
        CAPTURE(s);
        const Scene scene = parse_scene(plates_scene(s, "0.25 0.5 0.75 0.5"), "scaled.json");
        const GroupFormFactor g = group(scene, "bottom", "top");
        CHECK(rel_err(g.F, ref) <= scale_tol);
        CHECK(rel_err(g.F_reverse, ref) <= scale_tol);
        CHECK(g.stats.queries >= 1);  // the blocker really was in the shaft
        // Unoccluded: sqrt(2) - 1 at every scale.
        CHECK(rel_err(group(scene, "bottom", "top", FormFactorMethod::Unoccluded).F, std::sqrt(2.0) - 1) <= scale_tol);
    }
}

TEST_CASE("extremes: the exact solver's answer does not depend on the scale") {
    // bottom: E = 1, rho = 0; top: rho = 0.5; F = sqrt(2) - 1 both ways
    // (no blocker): B_top = 0.5 F, B_bottom = 1, at every scale.
    const double F = std::sqrt(2.0) - 1;
    for (int k : {-9, -3, 0, 3, 9}) {
        const double s = std::pow(10.0, k);
        CAPTURE(s);
        const Solution sol = solve_exact(parse_scene(plates_scene(s), "scaled.json"), {2, 1});
        REQUIRE(sol.patches.size() == 2);
        CHECK(sol.patches[0].radiosity[0] == 1);  // rho = 0: nothing added to E
        CHECK(rel_err(sol.patches[1].radiosity[0], 0.5 * F) <= scale_tol);
        CHECK(sol.totals.balance[0] <= 1e-13);
    }
}

// ---- segments from 1e-8 to 1e8 long in one scene ------------------------------

TEST_CASE("extremes: a 1e-8 segment under a 1e8 one, a unit blocker between") {
    // i = [-e/2, e/2] on y = 0 lit up, j = 2H long on y = 1 lit down
    // (e = 1e-8, H = 5e7), blocker [-0.5, 0.5] at y = 0.5: lines pass
    // through the windows (-inf, -0.5] and [0.5, inf). Seen from the tiny
    // segment the blocker hides sin(45 deg) of the (practically whole)
    // half-plane: F_ij ~ 1 - sqrt(2)/2. Each window's strings are evaluated
    // with their differences written out (the plain strings cancel all
    // but 8 digits at e / H = 1e-16):
    //   X = 2 H e / (s1 + s2) + 2 v e / (t1 + t2),  v = -0.5,
    //   s = sqrt((H +- e/2)^2 + 1), t = sqrt((v +- e/2)^2 + 1/4).
    const double e = 1e-8, H = 5e7, v = -0.5;
    const double s1 = std::sqrt((H + e / 2) * (H + e / 2) + 1), s2 = std::sqrt((H - e / 2) * (H - e / 2) + 1);
    const double t1 = std::sqrt((v + e / 2) * (v + e / 2) + 0.25), t2 = std::sqrt((v - e / 2) * (v - e / 2) + 0.25);
    const double X = 2 * H * e / (s1 + s2) + 2 * v * e / (t1 + t2);
    const std::string text = fmt::format(
        R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}},
            "surfaces": [{{"name": "short", "material": "m", "points": [[{}, 0], [{}, 0]]}},
                         {{"name": "long", "material": "m", "points": [[{}, 1], [{}, 1]]}},
                         {{"name": "blocker", "material": "m", "points": [[-0.5, 0.5], [0.5, 0.5]], "side": "both"}}]}})",
        num(-e / 2), num(e / 2), num(H), num(-H));
    const Scene scene = parse_scene(text, "lengths.json");
    const GroupFormFactor g = group(scene, "short", "long");
    CHECK(rel_err(g.F, X / e) <= exact_tol);
    CHECK(rel_err(g.F_reverse, X / (2 * H)) <= exact_tol);
    CHECK(std::abs(g.F - (1 - std::sqrt(0.5))) <= 1e-7);  // sanity of the hand value itself
}

// ---- nearly collinear and overlapping segments --------------------------------

TEST_CASE("extremes: a collinear segment touching a lamp end to end blocks nothing") {
    // Lamp [0, 2] on y = 0, a two-sided segment [2, 3] continuing it on the
    // same line, top [0, 2] at y = 1: lines from the lamp never cross the
    // continuation, so F = crossed strings = (sqrt(5) - 1) / 2 exactly as
    // without it. (An overlapping one is refused by the reader:
    // engine/extremes_test.cpp.)
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5}}, "surfaces": [
            {"name": "lamp", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "next", "material": "m", "points": [[2, 0], [3, 0]], "side": "both"},
            {"name": "top", "material": "m", "points": [[2, 1], [0, 1]]}]})",
        "touching.json");
    CHECK(rel_err(group(scene, "lamp", "top").F, (std::sqrt(5.0) - 1) / 2) <= exact_tol);
    // Pieces of one line see nothing of each other.
    CHECK(group(scene, "lamp", "next").F == 0);
}

TEST_CASE("extremes: a blocker 1e-3 .. 1e-12 above a patch, nearly collinear with it") {
    // Lamp [0, 2] on y = 0, top [0, 2] on y = 1, a blocker over the lamp's
    // left half at height d. Visible lines cross y = d in the window (1, 2]:
    // the strings give X = (sqrt(5) - 1) / 2 for every d (the d terms of
    // the two bent strings cancel), so F_lamp = (sqrt(5) - 1) / 4.
    const double ref = (std::sqrt(5.0) - 1) / 4;
    for (double d : {1e-3, 1e-6, 1e-9, 1e-12}) {
        CAPTURE(d);
        REQUIRE(rel_err(exchange_through_window(0, 2, 0, 2, 1, d, 1, 10) / 2, ref) <= 1e-14);
        const Scene scene = parse_scene(
            fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}}, "surfaces": [
                {{"name": "lamp", "material": "m", "points": [[0, 0], [2, 0]]}},
                {{"name": "lid", "material": "m", "points": [[0, {0}], [1, {0}]], "side": "both"}},
                {{"name": "top", "material": "m", "points": [[2, 1], [0, 1]]}}]}})",
                        num(d)),
            "lid.json");
        CHECK(rel_err(group(scene, "lamp", "top").F, ref) <= exact_tol);
    }
    // The same lid over the whole lamp closes the shaft: exactly 0.
    const Scene closed = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5}}, "surfaces": [
            {"name": "lamp", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "lid", "material": "m", "points": [[0, 1e-9], [2, 1e-9]], "side": "both"},
            {"name": "top", "material": "m", "points": [[2, 1], [0, 1]]}]})",
        "closed_lid.json");
    CHECK(group(closed, "lamp", "top").F == 0);
}

// ---- T-junctions and shared endpoints ------------------------------------------

TEST_CASE("extremes: a stem standing on the lamp (T-junction) between lamp and top") {
    // Lamp [0, 2] on y = 0, two-sided stem (1, 0) -> (1, 1), top [0, 2] on
    // y = 2. A line from the lamp's left half is visible iff it crosses
    // y = 1 left of the stem's tip (window (-inf, 1]); the right half
    // mirrors it. X = 2 X_left = sqrt(2) + sqrt(5) - 3, F = X / 2.
    const double X_left = exchange_through_window(0, 1, 0, 2, 2, 1, -10, 1);
    REQUIRE(rel_err(2 * X_left, std::sqrt(2.0) + std::sqrt(5.0) - 3) <= 1e-15);
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5}}, "surfaces": [
            {"name": "lamp", "material": "m", "points": [[0, 0], [2, 0]]},
            {"name": "stem", "material": "m", "points": [[1, 0], [1, 1]], "side": "both"},
            {"name": "top", "material": "m", "points": [[2, 2], [0, 2]]}]})",
        "t.json");
    const GroupFormFactor g = group(scene, "lamp", "top");
    CHECK(rel_err(g.F, (std::sqrt(2.0) + std::sqrt(5.0) - 3) / 2) <= exact_tol);
    CHECK(rel_err(g.F_reverse, g.F) <= exact_tol);  // equal lengths: reciprocity
    // Each stem side sees the lamp half in front of it as perpendicular
    // plates sharing an edge (the top cannot hide any of it): 1 - sqrt(2)/2.
    CHECK(rel_err(group(scene, "stem", "lamp").F, 1 - std::sqrt(2.0) / 2) <= exact_tol);
}

TEST_CASE("extremes: a closed triangle made of three surfaces sharing endpoints") {
    // 3-4-5 triangle lit inside, each side its own surface: for a pair of
    // sides the third lies along their shaft's boundary (an occluder
    // candidate touching both at the shared corners) and must hide nothing:
    // F_ab = (a + b - c) / 2a, and each side's row sums to 1 (closure).
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5, "emission": 1}}, "surfaces": [
            {"name": "a", "material": "m", "points": [[0, 0], [3, 0]]},
            {"name": "b", "material": "m", "points": [[3, 0], [3, 4]]},
            {"name": "c", "material": "m", "points": [[3, 4], [0, 0]]}]})",
        "triangle.json");
    const char* names[3] = {"a", "b", "c"};
    const double L[3] = {3, 4, 5};
    for (int p = 0; p < 3; ++p) {
        double row = 0;
        for (int q = 0; q < 3; ++q) {
            if (p == q) continue;
            const GroupFormFactor g = group(scene, names[p], names[q]);
            CAPTURE(p);
            CAPTURE(q);
            CHECK(rel_err(g.F, (L[p] + L[q] - L[3 - p - q]) / (2 * L[p])) <= exact_tol);
            row += g.F;
        }
        CHECK(std::abs(row - 1) <= exact_tol);
    }
    // Closed, lit inside, E = 1 and rho = 0.5 everywhere: B = E / (1 - rho) = 2.
    const Solution sol = solve_exact(scene, {3, 1});
    for (const PatchResult& p : sol.patches) CHECK(rel_err(p.radiosity[0], 2) <= solve_tol);
    CHECK(sol.totals.escaped[0] == 0);
}

// ---- a blocker touching a patch ---------------------------------------------------

TEST_CASE("extremes: a blocker leaning from the lamp's end over the lamp") {
    // Lamp [0, 1] on y = 0, top [0, 1] on y = 1, a wall from the lamp's end
    // (1, 0) to (0.5, 0.5): a line is visible iff it crosses y = 0.5 left
    // of the wall's tip, window (-inf, 0.5]: by the mirror symmetry of the
    // plates exactly half the lines: F = (sqrt(2) - 1) / 2.
    REQUIRE(rel_err(exchange_through_window(0, 1, 0, 1, 1, 0.5, -10, 0.5), (std::sqrt(2.0) - 1) / 2) <= 1e-15);
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5}}, "surfaces": [
            {"name": "lamp", "material": "m", "points": [[0, 0], [1, 0]]},
            {"name": "wall", "material": "m", "points": [[1, 0], [0.5, 0.5]], "side": "both"},
            {"name": "top", "material": "m", "points": [[1, 1], [0, 1]]}]})",
        "lean.json");
    CHECK(rel_err(group(scene, "lamp", "top").F, (std::sqrt(2.0) - 1) / 2) <= exact_tol);
}

// ---- many blockers in one shaft --------------------------------------------------

namespace {

// Facing unit plates, and n dashes on y = 0.5, dash k covering
// [(k + 1/4) / n, (k + 3/4) / n]: half of every pitch. Lines cross y = 0.5
// once, so the blocked measure is the sum over dashes of the lines through
// each dash: with G(w) the measure of lines crossing y = 0.5 at x <= w,
//   G(w) = sqrt(w^2 + 1/4) - 1/2             (w <= 1/2),
//   G(w) = sqrt(2) - 1 - G(1 - w)              (w >= 1/2),
// and X = sqrt(2) - 1 - sum_k (G(v_k) - G(u_k)), each difference written
// without cancellation: (v - u)(v + u) / (sqrt(v^2 + 1/4) + sqrt(u^2 + 1/4)).
double dashes_hand_value(int n) {
    const auto dG = [](double u, double v) {  // G(v) - G(u), u <= v <= 1/2
        return (v - u) * (v + u) / (std::sqrt(v * v + 0.25) + std::sqrt(u * u + 0.25));
    };
    CompensatedSum blocked;
    for (int k = 0; k < n; ++k) {
        const double u = (k + 0.25) / n, v = (k + 0.75) / n;
        if (v <= 0.5) blocked.add(dG(u, v));
        else if (u >= 0.5) blocked.add(dG(1 - v, 1 - u));  // mirror
        else {
            blocked.add(dG(u, 0.5));
            blocked.add(dG(1 - v, 0.5));
        }
    }
    return std::sqrt(2.0) - 1 - blocked.value();
}

std::vector<Segment> dashes(int n) {
    std::vector<Segment> out;
    out.reserve(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) out.push_back({{(k + 0.25) / n, 0.5}, {(k + 0.75) / n, 0.5}});
    return out;
}

void check_dashes(int n) {
    const Segment i{{0, 0}, {1, 0}}, j{{1, 1}, {0, 1}};
    const std::vector<Segment> blockers = dashes(n);
    const double ref = dashes_hand_value(n);
    ExactWorkspace ws;
    VisibilityStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    const double X = ExactVisibility::exchange_with_blockers(i, j, blockers, ws, stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    MESSAGE(fmt::format("{} dashes: X = {:.17g} (hand {:.17g}), {:.2f} s, {} events, {} sub-shafts", n, X, ref,
                        seconds, stats.events, stats.subshafts));
    CAPTURE(n);
    // The half-covered fence lets through about half of sqrt(2) - 1.
    CHECK(std::abs(ref - (std::sqrt(2.0) - 1) / 2) <= 1.0 / n);
    CHECK(rel_err(X, ref) <= exact_tol);
    // Through the scene path too (hierarchy culling, the patch's own
    // segments skipped): the same value.
    std::vector<Segment> all = blockers;
    all.push_back(i);
    all.push_back(j);
    const Hierarchy hierarchy(all);
    const ExactVisibility visibility(hierarchy);
    VisibilityStats stats2;
    CHECK(rel_err(visibility.exchange(i, j, n, n + 1, ws, stats2), ref) <= exact_tol);
}

}  // namespace

TEST_CASE("extremes: 2000 dashes inside one shaft against the hand value") {
    // The issue asks for 10^5 blockers in one shaft. The exact algorithm's
    // cost grows faster than linearly with the blockers in a shaft (critical
    // directions are pairs of endpoints; sub-shaft splitting stops at 4096
    // pieces): measured in Release on this project's 2-core machine,
    // 1000 dashes 0.13 s, 3000 0.8 s, 10^4 7.6 s, 10^5 see the skipped
    // case below. This case keeps the expectation (hand value to 1e-12) at
    // a size that the sanitizer suite runs in seconds.
    check_dashes(2000);
}

TEST_CASE("extremes: 10^5 dashes inside one shaft (slow: run with --no-skip)" * doctest::skip()) {
    // Same expectation at the issue's size; minutes in Release (see above),
    // so skipped by default: test_solver_extremes_test --no-skip -tc='*10^5*'.
    check_dashes(100000);
}

// ---- reflectance 0 and 0.999999 ---------------------------------------------------

TEST_CASE("extremes: reflectance 0 adds nothing, reflectance 0.999999 in an open scene") {
    // Facing unit plates, F = sqrt(2) - 1 both ways, lamp E = 1.
    const double F = std::sqrt(2.0) - 1;
    const auto solve_plates = [](double rho_lamp, double rho_top) {
        const std::string text = fmt::format(
            R"({{"flatrad": 1, "materials": {{"lamp": {{"reflectance": {}, "emission": 1}}, "top": {{"reflectance": {}}}}},
                "surfaces": [{{"name": "lamp", "material": "lamp", "points": [[0, 0], [1, 0]]}},
                             {{"name": "top", "material": "top", "points": [[1, 1], [0, 1]]}}]}})",
            num(rho_lamp), num(rho_top));
        return solve_exact(parse_scene(text, "plates.json"), {1, 1});
    };
    {
        // rho = 0 everywhere: B = E exactly, nothing comes back; the top
        // absorbs F, the rest (2 - sqrt(2)) escapes.
        const Solution sol = solve_plates(0, 0);
        CHECK(sol.patches[0].radiosity[0] == 1);
        CHECK(sol.patches[1].radiosity[0] == 0);
        CHECK(rel_err(sol.totals.absorbed[0], F) <= solve_tol);
        CHECK(rel_err(sol.totals.escaped[0], 2 - std::sqrt(2.0)) <= solve_tol);
        CHECK(sol.totals.balance[0] <= 1e-15);
    }
    {
        // rho = 0.999999 on both: B1 = 1 / (1 - r^2 F^2), B2 = r F B1 (the
        // 2x2 system in closed form; F < 0.42 keeps it well conditioned).
        const double r = 0.999999;
        const Solution sol = solve_plates(r, r);
        const double B1 = 1 / (1 - r * r * F * F);
        CHECK(rel_err(sol.patches[0].radiosity[0], B1) <= solve_tol);
        CHECK(rel_err(sol.patches[1].radiosity[0], r * F * B1) <= solve_tol);
        CHECK(sol.totals.balance[0] <= 1e-13);
    }
}

TEST_CASE("extremes: reflectance 0.999999 in a closed triangle gives E / (1 - rho) = 1e6") {
    // Closed: rows of F sum to 1 to ~1e-15, the system's condition is
    // 1 / (1 - rho) = 1e6, so B = 1e6 to ~1e-9 relative. Checked at 1e-8.
    constexpr double stiff_tol = 1e-8;
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.999999, "emission": 1}}, "surfaces": [
            {"name": "t", "material": "m", "points": [[0, 0], [3, 0], [3, 4]], "closed": true, "side": "in"}]})",
        "stiff.json");
    const Solution sol = solve_exact(scene, {4, 1});
    for (const PatchResult& p : sol.patches) {
        CHECK(rel_err(p.radiosity[0], 1e6) <= stiff_tol);
        for (const ElementValue& e : p.elements) CHECK(rel_err(e.B[0], 1e6) <= stiff_tol);
    }
    CHECK(sol.totals.balance[0] <= stiff_tol);  // absorbed = E up to B's error
}

// ---- no light at all ----------------------------------------------------------------

namespace {

void check_all_zero(const Solution& sol) {
    for (const PatchResult& p : sol.patches) {
        for (double b : p.radiosity) CHECK(b == 0);  // 0, not NaN
        for (const ElementValue& e : p.elements)
            for (double b : e.B) CHECK(b == 0);
    }
    for (const auto* v : {&sol.totals.emitted, &sol.totals.absorbed, &sol.totals.escaped, &sol.totals.balance})
        for (double x : *v) CHECK(x == 0);  // balance is 0 when nothing is emitted (SPEC)
    CHECK(sol.stats.residual == 0);
}

}  // namespace

TEST_CASE("extremes: emission 0 everywhere gives radiosity 0, not NaN") {
    // Closed room with an occluding pillar, three channels, "emission": 0
    // written out; reflectance < 1 so the system is regular: B = 0 exactly.
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": [0.5, 0, 0.999999], "emission": 0}}, "surfaces": [
            {"name": "room", "material": "m", "points": [[0, 0], [2, 0], [2, 1], [0, 1]], "closed": true, "side": "in"},
            {"name": "pillar", "material": "m", "circle": {"center": [1, 0.5], "radius": 0.2, "segments": 8}, "side": "out"}]})",
        "dark.json");
    check_all_zero(solve_exact(scene, {2, 1}));
}

TEST_CASE("extremes: a scene with no emitter (open, emission absent) is solved to 0") {
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.7}}, "surfaces": [
            {"name": "a", "material": "m", "points": [[0, 0], [1, 0]]},
            {"name": "b", "material": "m", "points": [[1, 1], [0, 1]], "side": "both"}]})",
        "unlit.json");
    check_all_zero(solve_exact(scene, {3, 1}));
    // Form factors do not depend on emission.
    CHECK(rel_err(group(scene, "a", "b").F, std::sqrt(2.0) - 1) <= exact_tol);
}

// ---- a single segment -------------------------------------------------------------

TEST_CASE("extremes: a single segment emits and everything escapes") {
    for (const char* side : {"left", "both"}) {
        CAPTURE(side);
        const Scene scene = parse_scene(
            fmt::format(R"({{"flatrad": 1, "materials": {{"lamp": {{"reflectance": 0.5, "emission": 2}}}}, "surfaces": [
                {{"name": "lamp", "material": "lamp", "points": [[0, 0], [3, 0]], "side": "{}"}}]}})",
                        side),
            "single.json");
        const Solution sol = solve_exact(scene, {4, 1});
        const double patches = std::string(side) == "both" ? 2 : 1;
        REQUIRE(sol.patches.size() == static_cast<size_t>(patches));
        for (const PatchResult& p : sol.patches) CHECK(p.radiosity[0] == 2);  // sees nothing, B = E
        CHECK(sol.totals.emitted[0] == 6 * patches);
        CHECK(sol.totals.absorbed[0] == 0);
        CHECK(sol.totals.escaped[0] == 6 * patches);
        CHECK(sol.totals.balance[0] == 0);
        CHECK(group(scene, "lamp", "lamp").F == 0);  // a flat segment cannot see itself
    }
}

// ---- memory limit --------------------------------------------------------------------

TEST_CASE("extremes: a run beyond the exact solver's memory limit is refused up front") {
    const Scene plates = parse_scene(plates_scene(1), "plates.json");  // 2 patches
    // 3 n^2 doubles dominate: n = 2 K.
    for (int K : {1, 10, 1000}) {
        const double n = 2.0 * K;
        CHECK(exact_solver_memory_bytes(plates, K) >= 3 * n * n * 8);
        CHECK(exact_solver_memory_bytes(plates, K) <= 3 * n * n * 8 + 200 * n);
    }
    // 8 GiB / 24 bytes per n^2 allows n up to about 18900: K = 9000 fits.
    CHECK_NOTHROW(check_exact_solver_memory(plates, 9000));
    try {
        solve_exact(plates, {100000, 1});  // 2e5 elements: 894 GiB
        FAIL("a 894 GiB run was not refused");
    } catch (const InputError& err) {
        CHECK(err.path() == "--subdivide");
        CHECK(err.message().find("would need 894.1 GiB") != std::string::npos);
        CHECK(err.message().find("limit is 8 GiB") != std::string::npos);
    }
    // A big scene at K = 1 is refused too, naming no flag, before any form
    // factor is computed (this would take hours otherwise): a two-sided
    // circle of 10^4 segments is 2 10^4 patches, 8.9 GiB.
    const Scene big = parse_scene(
        R"({"flatrad": 1, "materials": {"m": {"reflectance": 0.5, "emission": 1}}, "surfaces": [
            {"name": "ring", "material": "m", "circle": {"center": [0, 0], "radius": 1, "segments": 10000}, "side": "both"}]})",
        "ring.json");
    const auto t0 = std::chrono::steady_clock::now();
    try {
        solve_exact(big, {1, 1});
        FAIL("an 8.9 GiB run was not refused");
    } catch (const InputError& err) {
        CHECK(err.path() == "");
        CHECK(err.message().find("20000 elements") != std::string::npos);
        CHECK(err.message().find("would need 8.9 GiB") != std::string::npos);
    }
    CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < 1.0);
}

// ---- the fuzzer's corpus and its regressions -----------------------------------------

TEST_CASE("extremes: every input of the fuzz corpus passes the fuzz target's checks") {
    // fuzz/corpus holds the seeds (data/ scenes, bad inputs, these extremes)
    // and every input the fuzzer broke (regress_*.json): each must be refused
    // cleanly or pass fuzz/fuzz_checks.h, here without clang or libFuzzer.
    const std::filesystem::path corpus = std::filesystem::path(FLATRAD_DATA_DIR) / ".." / "fuzz" / "corpus";
    REQUIRE(std::filesystem::is_directory(corpus));
    int inputs = 0, regressions = 0;
    for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
        std::ifstream in(entry.path(), std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        const std::string name = entry.path().filename().string();
        CAPTURE(name);
        const auto finding = fuzz::check_input(text.str());
        CHECK_MESSAGE(!finding, finding.value_or(""));
        ++inputs;
        regressions += name.rfind("regress_", 0) == 0;
    }
    CHECK(inputs >= 40);
    CHECK(regressions >= 1);
}

TEST_CASE("extremes: a lamp in a box with a corner 1e15 away: exact F and a sane solve") {
    // fuzz/corpus/regress_huge_wall_snap.json and regress_sliver_box_1e33.json
    // put the box corner 4e57 and 4e33 away: the clipping snap moved the
    // far wall's end onto the lamp (F = 1.2), blockers beside the long walls
    // were dropped as "on the patch line" (tolerance relative to the shaft's
    // size), and crossed strings lost X to noise of 1e17; the solve then
    // gave negative radiosity and a balance of 0.08. All three are fixed
    // (engine/formfactor.cpp, visibility/shaft.h); scenes past the 2e16
    // range of lengths are now refused (next case). At 1e15 the lamp, inside
    // the closed box, sends all its light to it (F = 1 to 1e-12), every row
    // closes, and the stiff solve (rho = 0.999999) stays >= 0 and balanced.
    const Scene scene = parse_scene(
        R"({"flatrad": 1, "materials": {"white": {"reflectance": 0.999999}, "lamp": {"reflectance": 0, "emission": 1}},
            "surfaces": [{"name": "lamp", "material": "lamp", "points": [[0,0],[1,0]]},
                         {"name": "box", "material": "white", "closed": true, "side": "in",
                          "points": [[0,-1],[2,-1],[2,1e15],[-2,2]]}]})",
        "far_corner.json");
    CHECK(rel_err(group(scene, "lamp", "box").F, 1) <= exact_tol);
    const Solution sol = solve_exact(scene, {2, 1});
    double largest = 0;
    for (const PatchResult& p : sol.patches) largest = std::max(largest, p.radiosity[0]);
    for (const PatchResult& p : sol.patches) CHECK(p.radiosity[0] >= -1e-12 * largest);
    // Closure to ~1e-15 per row, amplified by 1 / (1 - rho) = 1e6.
    CHECK(sol.totals.balance[0] <= 1e-8);
}

TEST_CASE("extremes: a scene whose lengths span more than 2e16 is refused") {
    // The same box with its corner 4.4e33 and 4.4e57 away (the fuzzer's
    // inputs): a clear refusal naming the short segment, not a wrong answer.
    for (const char* far : {"4444440000000001990216897952597785",
                            "4444444444444444444444444444444444444444444444444444444442"}) {
        CAPTURE(far);
        try {
            parse_scene(fmt::format(R"({{"flatrad": 1, "materials": {{"m": {{"reflectance": 0.5}}}},
                "surfaces": [{{"name": "lamp", "material": "m", "points": [[0,0],[1,0]]}},
                             {{"name": "box", "material": "m", "closed": true, "side": "in",
                               "points": [[0,-1],[2,-1],[2,{}],[-2,2]]}}]}})",
                                    far),
                        "far.json");
            FAIL("accepted");
        } catch (const InputError& err) {
            CHECK(err.path() == "surfaces[0].points[1]");
            CHECK(err.message().find("range of lengths") != std::string::npos);
        }
    }
}

TEST_CASE("extremes: cuts of a 5e14-long wall near a small pillar stay where they are") {
    // fuzz/corpus/regress_long_wall_cut.json: exact group F came out 1.66.
    // Clipping cut the long wall at 8 from its end by lerp from its far end
    // (error ~0.1, of the wall's length), and the snap tolerance, also of
    // the wall's length (~8), moved a 0.19 pillar patch's end onto that cut:
    // exchanges of 4 with a patch 0.19 long. Cuts are now measured from the
    // nearer end and snapped only within their own rounding. Each exact
    // exchange is at most the shorter length (a measure of lines meeting
    // it), and the group values are fractions.
    std::ifstream in(std::filesystem::path(FLATRAD_DATA_DIR) / ".." / "fuzz" / "corpus" / "regress_long_wall_cut.json");
    std::stringstream text;
    text << in.rdbuf();
    const Scene scene = parse_scene(text.str(), "regress_long_wall_cut.json");
    const GroupFormFactor g = group_form_factor(scene, {0}, {static_cast<int>(scene.surfaces.size()) - 1},
                                                FormFactorMethod::Exact);
    CHECK(g.F >= 0);
    CHECK(g.F <= 1);
    CHECK(g.F_reverse >= 0);
    CHECK(g.F_reverse <= 1);
    const Hierarchy hierarchy(scene.segment_geometry());
    const ExactVisibility visibility(hierarchy);
    ExactWorkspace ws;
    VisibilityStats stats;
    for (size_t a = 0; a < scene.patches.size(); ++a)
        for (size_t b = 0; b < scene.patches.size(); ++b) {
            const Patch& pa = scene.patches[a];
            const Patch& pb = scene.patches[b];
            if (pa.segment == pb.segment) continue;
            const double X = visibility.exchange(scene.patch_segment(static_cast<int>(a)),
                                                 scene.patch_segment(static_cast<int>(b)), pa.segment, pb.segment, ws,
                                                 stats);
            CAPTURE(a);
            CAPTURE(b);
            CHECK(X <= std::min(pa.length, pb.length) * (1 + 1e-12));
        }
    CHECK_FALSE(fuzz::check_input(text.str()));
}
