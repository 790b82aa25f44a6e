#include "visibility/multiscale.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "engine/error.h"
#include "engine/formfactor.h"
#include "visibility/direction_bounds.h"
#include "visibility/opaque_band.h"
#include "visibility/shaft.h"

namespace flatrad {

using namespace shaft_detail;

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();
// The direction integral is computed to this share of eps (error in F), so
// that its own error stays well below the approximation it serves.
constexpr double quadrature_share = 1e-3;
// Direction bounds (1b in form_factor_skipping), where enabled
// (set_min_pieces_to_bound), get a budget of bounds_budget_per_piece bins a
// piece (at least bounds_min_budget). A cost choice: an attempt that does
// not converge is wasted, one that does replaces an integral of ~n^2
// events. With the hierarchical solver's settings (from 32 pieces):
// measured on the 1000-segment forest of `scripts/bench versus` (eps 2 /
// 1 / 0.5 / 0.1; time in s, relative L2 against exact K = 2; bounds
// from N pieces with B bins a piece, "from N, B", starting from 8 bins,
// direction_bounds.cpp):
//   none            5.35 / 6.51 / 7.94 / 10.7 s   8.5e-3 / 5.4e-3 / 3.7e-3 / 1.8e-3
//   from 32, 0.5    0.42 / 0.68 / 1.03 / 2.34 s   1.8e-2 / 9.9e-3 / 6.3e-3 / 2.2e-3
//   from 32, 2      0.38 / 0.58 / 0.85 / 1.98 s   1.8e-2 / 1.0e-2 / 6.3e-3 / 2.2e-3
//   from 16, 2      0.32 / 0.50 / 0.76 / 1.83 s   2.3e-2 / 1.3e-2 / 8.1e-3 / 2.8e-3
// (the bounds spend the visibility tolerance the exact integral left
// unused, hence the larger errors at one eps). With 16 starting bins (the
// default) "from 32, 2" gives 0.43 / 0.63 / 0.91 / 2.04 s at 9.5e-3 /
// 6.0e-3 / 4.0e-3 / 1.8e-3: at 1% error, 12x faster than none.
constexpr long bounds_min_budget = 16;
constexpr double bounds_budget_per_piece = 2;
// A loose query: a tolerance of at least this share of the pair's
// unoccluded exchange (the hierarchical solver's links at eps 5 and more,
// vis_eps = eps / 10, ask for their transmittance to +-0.5 or worse). It
// needs to tell open from closed and how much passes roughly, not digits:
// bounds from 8 bins with their midpoint rule (DirectionBounds::estimate)
// give that from fewer pieces than the exact integral costs (set_min_pieces_
// to_bound's `loose`), and the estimate, unlike the bounds' midpoint, is not
// biased open through a deep forest (the solver takes it within the bounds
// instead of the density's prior: solver/hierarchical_solver.cpp, within_bound).
// The 1000-segment forest of `scripts/bench versus` (in-process, 2 threads,
// medians of 7 runs, 3 rounds alternating), before / with: eps 8 63.0 / 50.2
// ms at relative L2 8.15e-3 / 8.07e-3, eps 10 58.0 / 48.0 ms at 8.98e-3 /
// 8.74e-3, eps 16 50.8 / 41.5 ms at 1.04e-2 / 9.89e-3: 1% at eps 16 in
// 41.5 ms against eps 12 in 54.9 ms before (in another, slower hour, eps
// 16: from 8 pieces 45.0 ms at 9.89e-3, from 16 46.1 ms at 1.02e-2, from
// 32 53.5 ms at 1.02e-2; 16 initial bins instead of 8, eps 14: 48.4
// against 43.7 ms at 9.95e-3 against 9.78e-3). data/forest.json
// (3000 sticks) at eps 0.1 / 1 / 10: 1.82 / 0.53 / 0.20 s before, 1.53 /
// 0.46 / 0.18 s with, the same errors; data/tube_bank.json at eps 10 11.5
// / 5.9 ms at 5.2e-2 / 3.9e-2, at eps 0.1 (tight) 45 / 41 ms, the same
// error. Tight queries keep the exact integral below 32 pieces: with every
// query treated as loose, the tube bank at eps 0.1 took 24% longer for
// the same error (more links, split on the bounds' gaps).
constexpr double loose_tolerance = 0.5;
constexpr int loose_initial_bins = 8;
// A long shaft (0 in form_factor_skipping): at least long_shaft_layers
// layers of shadow between the patches by the scene's density, where the
// slabs around the three bands' depths, band_slab_layers each (a band
// takes opaque_band_layers), are walked first. On the forests of
// `scripts/make-scene N --density 30` (2 cores): at 10^5 segments and eps
// 10, 102 s before, 65 s with them (the same links, 1.04 million; 225 000
// queries settled by the slabs alone); at 10^4 and 10^3 the same times
// and links (few shafts that long); from 28 layers on, no different.
constexpr double long_shaft_layers = 36;
constexpr double band_slab_layers = 8;
// A closure screen's proof (shown_closed) may stand nearer than a long
// shaft: its three slabs then share the depth between the patches, each
// at most band_slab_layers and at least screen_min_slab_layers thick (a
// band takes opaque_band_layers, but a thinner slab still holds a band
// that may close: the proof is exact whatever the slab gives it). On the
// 10^4 forest (`scripts/make-scene 10000 --seed 1 --density 30`, one
// thread, callgrind) with screens at 1.05, 0.7, 0.47 and 0.37 long-shaft
// depths (solver/hierarchical_solver.cpp): 11.36 G instructions at eps 10
// with 4 layers, 11.43 G with 5 (and only the first three depths usable),
// 11.30 G with 3 and a fifth screen at 0.29.
constexpr double screen_min_slab_layers = 4;
// Depth cap of the adaptive Gauss-Kronrod bisection on one arc.
constexpr int max_quadrature_depth = 30;

// Gauss-Kronrod 3-7 nodes and weights on [-1, 1] (standard constants):
// arcs between critical directions are short and smooth, so the low order
// pair is the cheaper way to the tolerance.
constexpr double xgk[4] = {0.960491268708020283423507092629080, 0.774596669241483377035853079956480,
                           0.434243749346802558002071502844628, 0.0};
constexpr double wgk[4] = {0.104656226026467265193823857192073, 0.268488089868333440728569280666710,
                           0.401397414775962222905051818618432, 0.450916538658474142345110087045571};
constexpr double wg[2] = {0.555555555555555555555555555555556, 0.888888888888888888888888888888889};

// What a pair looks like from the criteria's point of view (DESIGN §2).
struct PairGeometry {
    bool visible = false;
    Segment ci, cj;        // mutually clipped
    double L_i = 0;        // unclipped length of i (F is per unit length of i)
    Vec2 origin, u;        // frame (PairFrame in shaft.h): origin and axis bisecting the directions
    double theta_u = 0;    // absolute direction of u
    double delta_theta = 0;  // half spread of directions of lines meeting both
    double r_min = 0;      // distance between the clipped patches
    double T = 0;          // |sin(alpha - theta12) sin(beta - theta12)|
};

double point_segment_distance(Vec2 p, const Segment& s) {
    const Vec2 d = s.b - s.a;
    const double l2 = norm_squared(d);
    const double t = l2 > 0 ? std::clamp(dot(p - s.a, d) / l2, 0.0, 1.0) : 0.0;
    return distance(p, lerp(s.a, s.b, t));
}

PairGeometry pair_geometry(const Segment& i, const Segment& j) {
    PairGeometry g;
    const auto clipped = clip_to_lit_halfplanes(i, j);
    if (!clipped) return g;
    g.visible = true;
    g.ci = clipped->first;
    g.cj = clipped->second;
    g.L_i = i.length();
    const PairFrame frame(g.ci, g.cj);
    g.origin = frame.origin;
    g.u = frame.u;
    g.theta_u = frame.theta_u;
    g.delta_theta = frame.delta_theta;
    // Segments that face each other after clipping do not cross; their
    // distance is the least endpoint-to-segment distance.
    g.r_min = std::min({point_segment_distance(g.ci.a, g.cj), point_segment_distance(g.ci.b, g.cj),
                        point_segment_distance(g.cj.a, g.ci), point_segment_distance(g.cj.b, g.ci)});
    const double alpha = std::atan2(i.b.y - i.a.y, i.b.x - i.a.x);
    const double beta = std::atan2(j.b.y - j.a.y, j.b.x - j.a.x);
    g.T = std::abs(std::sin(alpha - g.theta_u) * std::sin(beta - g.theta_u));
    return g;
}

ClusterCriteria criteria_for(const ClusterTables& tables, int node, const PairGeometry& g) {
    ClusterCriteria c;
    if (!g.visible) return {infinity, infinity, infinity};
    const ClusterTables::Sample s = tables.at(node, g.theta_u);
    const double R = s.R1 + s.R2f;
    // Soler 1995 §2.2: Gamma = (2 dtheta sqrt(dp) / r_min) T (R1 + R2);
    // beyond Delta_theta, R1 says nothing: +infinity.
    const bool wide = g.delta_theta > ClusterTables::max_delta_theta;
    c.paper = wide || g.r_min <= 0 ? infinity : 2 * g.delta_theta * std::sqrt(s.delta_p) / g.r_min * g.T * R;
    c.line_space = wide ? infinity : g.delta_theta * std::sqrt(s.delta_p) * R / g.L_i;
    // Error of tau_bar in the integral: Int (tau - tau_bar) w dp with w in
    // [0, 1] (the overlap window times everything else's transmittance).
    // Since Int (tau - tau_bar) dp = 0 over the box's lines, w may be
    // replaced by w - 1/2, so |error| <= ||tau - tau_bar||_L1 / 2 per
    // direction; over 2 delta_theta of directions, halved again for
    // L_i F = 1/2 Integral: delta_theta max L1 / (2 L_i).
    c.bound = g.delta_theta *
              tables.max_l1_over(node, g.theta_u - g.delta_theta, g.theta_u + g.delta_theta) / (2 * g.L_i);
    return c;
}

// An approximated cluster during integration: its box corners in the frame.
struct Approx {
    int node;
    Vec2 corner[4];
    const ClusterTable* table = nullptr;
};

struct Integrand {
    const PairGeometry& g;
    const std::vector<Vec2>& pts;  // A0 A1 C0 C1, then exact blocker endpoints
    const std::vector<Approx>& approx;
    mutable std::vector<double> ev_p;
    mutable std::vector<int> ev_kind;
    mutable std::vector<int32_t> ev_order;

    // Free measure at direction phi (frame angle): the integral over the
    // overlap of [no exact blocker] x prod tau_bar of the crossed clusters.
    double operator()(double phi) const {
        const double nx = -std::sin(phi), ny = std::cos(phi);
        double p[4];
        for (size_t k = 0; k < 4; ++k) p[k] = nx * pts[k].x + ny * pts[k].y;
        const double lo = std::max(std::min(p[0], p[1]), std::min(p[2], p[3]));
        const double hi = std::min(std::max(p[0], p[1]), std::max(p[2], p[3]));
        if (!(hi > lo)) return 0;
        // Events: exact blockers as (p, exact_open / exact_close), clusters
        // as (p, +-(index + 1)). Their order changes little from one
        // direction to the next (the integrator moves in small steps), so
        // the previous order is kept and repaired by insertion sort.
        constexpr int exact_open = 1 << 30, exact_close = -(1 << 30);
        const size_t n_exact = (pts.size() - 4) / 2, n_ev = 2 * (n_exact + approx.size());
        if (ev_order.size() != n_ev) {
            ev_order.resize(n_ev);
            for (size_t k = 0; k < n_ev; ++k) ev_order[k] = static_cast<int32_t>(k);
            ev_kind.resize(n_ev);
            for (size_t q = 0; q < n_exact; ++q) {
                ev_kind[2 * q] = exact_open;
                ev_kind[2 * q + 1] = exact_close;
            }
            for (size_t c = 0; c < approx.size(); ++c) {
                ev_kind[2 * (n_exact + c)] = static_cast<int>(c) + 1;
                ev_kind[2 * (n_exact + c) + 1] = -(static_cast<int>(c) + 1);
            }
        }
        ev_p.resize(n_ev);
        for (size_t q = 0; q < n_exact; ++q) {
            const Vec2 A = pts[4 + 2 * q], B = pts[5 + 2 * q];
            const double a = nx * A.x + ny * A.y, b = nx * B.x + ny * B.y;
            ev_p[2 * q] = std::clamp(std::min(a, b), lo, hi);
            ev_p[2 * q + 1] = std::clamp(std::max(a, b), lo, hi);
        }
        for (size_t c = 0; c < approx.size(); ++c) {
            double mn = infinity, mx = -infinity;
            for (const Vec2& q : approx[c].corner) {
                const double v = nx * q.x + ny * q.y;
                mn = std::min(mn, v);
                mx = std::max(mx, v);
            }
            ev_p[2 * (n_exact + c)] = std::clamp(mn, lo, hi);
            ev_p[2 * (n_exact + c) + 1] = std::clamp(mx, lo, hi);
        }
        for (size_t k = 1; k < n_ev; ++k) {
            const int32_t key = ev_order[k];
            const double v = ev_p[static_cast<size_t>(key)];
            size_t r = k;
            while (r > 0 && ev_p[static_cast<size_t>(ev_order[r - 1])] > v) {
                ev_order[r] = ev_order[r - 1];
                --r;
            }
            ev_order[r] = key;
        }
        // Sweep: exact depth, and the product of the open clusters' tau_bar
        // (kept as a count of zeros and a running product: multiplied in
        // on entry, divided out on exit; a handful of roundings per piece,
        // far below the quadrature tolerance). tau_bar is linear in theta
        // on an arc (arcs end at the table's samples): alpha + beta theta.
        const double theta = g.theta_u + phi;
        std::vector<double>& weight = scratch_weight;
        weight.resize(approx.size());
        for (size_t c = 0; c < approx.size(); ++c)
            weight[c] = std::clamp(line_alpha[c] + line_beta[c] * theta, 0.0, 1.0);
        int depth = 0, zeros = 0;
        double prod = 1, at = lo, total = 0;
        for (size_t k = 0; k < n_ev; ++k) {
            const double x = ev_p[static_cast<size_t>(ev_order[k])];
            const int kind = ev_kind[static_cast<size_t>(ev_order[k])];
            if (x > at && depth == 0 && zeros == 0) total += (x - at) * prod;
            at = std::max(at, x);
            if (kind == exact_open) {
                ++depth;
            } else if (kind == exact_close) {
                --depth;
            } else {
                const double w = weight[static_cast<size_t>(std::abs(kind) - 1)];
                if (w <= 0)
                    zeros += kind > 0 ? 1 : -1;
                else if (kind > 0)
                    prod *= w;
                else
                    prod /= w;
            }
        }
        if (hi > at && depth == 0 && zeros == 0) total += (hi - at) * prod;
        return total;
    }
    // tau_bar = alpha + beta theta of each cluster on the current arc.
    mutable std::vector<double> line_alpha, line_beta;
    void set_arc(double theta_mid) const {
        line_alpha.resize(approx.size());
        line_beta.resize(approx.size());
        constexpr double pi = 3.14159265358979323846;
        const double step = pi / ClusterTables::directions;
        const double x = theta_mid / step - 0.5;
        const double k0 = std::floor(x);
        const long k0l = static_cast<long>(k0);
        const size_t q0 = static_cast<size_t>(((k0l % ClusterTables::directions) + ClusterTables::directions) %
                                              ClusterTables::directions);
        const size_t q1 = (q0 + 1) % ClusterTables::directions;
        const double theta0 = (k0 + 0.5) * step;
        for (size_t c = 0; c < approx.size(); ++c) {
            const double t0 = approx[c].table->tau_bar[q0], t1 = approx[c].table->tau_bar[q1];
            line_beta[c] = (t1 - t0) / step;
            line_alpha[c] = t0 - line_beta[c] * theta0;
        }
    }
    mutable std::vector<double> scratch_weight;
};

// Adaptive Gauss-Kronrod (3-7) on [a, b] to absolute tolerance tol; adds
// the error estimate |K7 - G3| of every accepted piece to err.
template <class F>
double adaptive_gk(const F& f, double a, double b, double tol, int depth, double& err, long& evals) {
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    const double fc = f(c);
    double k7 = wgk[3] * fc, g3 = wg[1] * fc;
    evals += 7;
    for (int q = 0; q < 3; ++q) {
        const double fx = f(c - h * xgk[q]) + f(c + h * xgk[q]);
        k7 += wgk[q] * fx;
        if (q == 1) g3 += wg[0] * fx;
    }
    k7 *= h;
    g3 *= h;
    const double e = std::abs(k7 - g3);
    // Accept at the tolerance, at the depth cap, or when the difference is
    // rounding noise (a tolerance below it can never be met by halving).
    const double noise = 64 * std::numeric_limits<double>::epsilon() * (std::abs(k7) + h * std::abs(fc));
    if (e <= tol || e <= noise || depth >= max_quadrature_depth || h <= 1e-15 * (std::abs(a) + std::abs(b))) {
        err += e;
        return k7;
    }
    return adaptive_gk(f, a, c, tol / 2, depth + 1, err, evals) + adaptive_gk(f, c, b, tol / 2, depth + 1, err, evals);
}

// Simpson on [a, b] given f(a); returns f(b) in fb. Error estimate
// |S - T| with T the trapezoid on the same points, halving until it is under
// tol (or the depth cap); the estimates of accepted pieces add to err.
template <class F>
double adaptive_simpson(const F& f, double a, double b, double fa, double tol, int depth, double& err, long& evals,
                        double& fb) {
    const double m = 0.5 * (a + b);
    const double fm = f(m);
    fb = f(b);
    evals += 2;
    const double h = b - a;
    const double S = h / 6 * (fa + 4 * fm + fb);
    const double T = h / 4 * (fa + 2 * fm + fb);
    const double e = std::abs(S - T);
    const double noise = 64 * std::numeric_limits<double>::epsilon() * std::abs(S);
    if (e <= tol || e <= noise || depth >= max_quadrature_depth) {
        err += e;
        return S;
    }
    double fmid = 0;
    const double left = adaptive_simpson(f, a, m, fa, tol / 2, depth + 1, err, evals, fmid);
    return left + adaptive_simpson(f, m, b, fm, tol / 2, depth + 1, err, evals, fb);
}

// Same splitting rule as the exact integral: shafts crowded with pieces
// (exact blockers and approximated clusters: both bring critical
// directions, O(pieces^2) of them) are halved, so that critical directions
// stay few; each half keeps only the clusters whose box meets it.
constexpr size_t mixed_split_threshold = 16;
constexpr int mixed_max_depth = 12;

// The direction integral of [no exact blocker] x prod tau_bar over a facing
// pair's shaft: 2 L_i F, by adaptive Gauss-Kronrod between the critical
// directions of the exact blockers; crowded shafts are split first.
struct MixedIntegral {
    const Hierarchy& hierarchy;
    ExactWorkspace& ws;
    VisibilityStats& stats;
    long arcs, evals;
    double err;

    double solve(const Segment& ci, const Segment& cj, const Segment* candidates, size_t count,
                 const std::vector<Approx>& approx_in, double tol, int depth) {
        if (ws.levels.size() <= static_cast<size_t>(depth)) ws.levels.resize(static_cast<size_t>(depth) + 1);
        std::vector<Segment>& mine = ws.levels[static_cast<size_t>(depth)];
        const Shaft shaft(ci, cj);
        if (clip_candidates(shaft, candidates, count, mine)) {
            ++stats.separated;
            return 0;
        }
        std::vector<Approx> approx;
        approx.reserve(approx_in.size());
        for (const Approx& a : approx_in)
            if (shaft.overlaps(hierarchy.node(a.node).box)) approx.push_back(a);
        const size_t pieces_here = mine.size() + approx.size(), pieces_above = count + approx_in.size();
        const bool no_progress = depth > 0 && static_cast<double>(pieces_here) > 0.8 * static_cast<double>(pieces_above);
        if (pieces_here > mixed_split_threshold && depth < mixed_max_depth && !no_progress) {
            ++stats.subshafts;
            const std::vector<Segment> pieces = mine;  // deeper levels reuse ws.levels
            if (ci.length() >= cj.length()) {
                const Vec2 m = ci.midpoint();
                return solve({ci.a, m}, cj, pieces.data(), pieces.size(), approx, tol / 2, depth + 1) +
                       solve({m, ci.b}, cj, pieces.data(), pieces.size(), approx, tol / 2, depth + 1);
            }
            const Vec2 m = cj.midpoint();
            return solve(ci, {cj.a, m}, pieces.data(), pieces.size(), approx, tol / 2, depth + 1) +
                   solve(ci, {m, cj.b}, pieces.data(), pieces.size(), approx, tol / 2, depth + 1);
        }
        return integrate(ci, cj, mine, approx, tol);
    }

    double integrate(const Segment& ci, const Segment& cj, const std::vector<Segment>& exact,
                     const std::vector<Approx>& approx_here, double tol) {
        // Frame (shaft.h): origin at the shorter patch, axis bisecting the directions.
        PairGeometry g;
        g.visible = true;
        g.ci = ci;
        g.cj = cj;
        const PairFrame frame(ci, cj);
        g.origin = frame.origin;
        g.u = frame.u;
        g.theta_u = frame.theta_u;
        auto local = [&](Vec2 P) { return frame.local(P); };
        std::vector<Vec2> pts;
        for (Vec2 P : {ci.a, ci.b, cj.a, cj.b}) pts.push_back(local(P));
        for (const Segment& b : exact) {
            pts.push_back(local(b.a));
            pts.push_back(local(b.b));
        }
        std::vector<Approx> approx = approx_here;
        for (Approx& a : approx) {
            const Box& b = hierarchy.node(a.node).box;
            const Vec2 c[4] = {b.lo, {b.hi.x, b.lo.y}, b.hi, {b.lo.x, b.hi.y}};
            for (int q = 0; q < 4; ++q) a.corner[q] = local(c[q]);
        }
        double s_lo = infinity, s_hi = -infinity;
        for (size_t a = 0; a < 2; ++a)
            for (size_t c = 2; c < 4; ++c) {
                const Vec2 w = pts[c] - pts[a];
                if (w == Vec2{}) continue;
                s_lo = std::min(s_lo, w.y / w.x);
                s_hi = std::max(s_hi, w.y / w.x);
            }
        if (!(s_hi > s_lo)) return 0;
        std::vector<double> slopes{s_lo, s_hi};
        const size_t n_exact = exact.size();
        // Only lines that meet both patches matter (elsewhere nothing in the
        // overlap changes): the line through P of slope s must cross [lo, hi].
        auto consider = [&](Vec2 P, Vec2 Q) {
            const Vec2 w = Q - P;
            if (w.x == 0) return;
            const double s = w.y / w.x;
            if (!(s > s_lo && s < s_hi)) return;
            double p4[4];
            for (size_t k = 0; k < 4; ++k) p4[k] = -s * pts[k].x + pts[k].y;
            const double lo = std::max(std::min(p4[0], p4[1]), std::min(p4[2], p4[3]));
            const double hi = std::min(std::max(p4[0], p4[1]), std::max(p4[2], p4[3]));
            const double p = -s * P.x + P.y;
            const double slack = event_slack * (std::abs(hi - lo) + std::abs(p));
            if (p < lo - slack || p > hi + slack) return;
            // Hidden strictly inside an exact blocker's shadow: the integrand
            // is 0 around (p, s) before and after, whatever the clusters weigh.
            for (size_t q = 0; q < n_exact; ++q) {
                const double da = -s * pts[4 + 2 * q].x + pts[4 + 2 * q].y - p;
                const double db = -s * pts[5 + 2 * q].x + pts[5 + 2 * q].y - p;
                if (da * db < 0 && std::min(std::abs(da), std::abs(db)) > slack) return;
            }
            slopes.push_back(s);
        };
        for (size_t a = 0; a < pts.size(); ++a)
            for (size_t b = std::max(a + 1, a < 2 ? size_t{2} : a + 1); b < pts.size(); ++b) consider(pts[a], pts[b]);
        // Box corners crossing the overlap's ends, exact blockers' ends or
        // other boxes' corners, and the table's sample directions (tau_bar is
        // linear between them), put kinks in the integrand. Splitting there
        // keeps every arc smooth, so that the Gauss-Kronrod error estimate
        // is trustworthy (across a kink it can miss the error by orders of
        // magnitude, which the bound study caught).
        for (size_t c = 0; c < approx.size(); ++c)
            for (const Vec2& corner : approx[c].corner) {
                for (size_t q = 0; q < pts.size(); ++q) consider(pts[q], corner);
                for (size_t d = c; d < approx.size(); ++d)
                    for (const Vec2& other : approx[d].corner)
                        if (!(other == corner)) consider(corner, other);
            }
        {
            constexpr double pi = 3.14159265358979323846;
            const double step = pi / ClusterTables::directions;
            const double phi_lo = std::atan(s_lo), phi_hi = std::atan(s_hi);
            // Sample k sits at absolute (k + 1/2) step; in the frame, phi = theta - theta_u (mod pi).
            const double first = std::ceil((g.theta_u + phi_lo) / step - 0.5);
            for (double k = first; (k + 0.5) * step - g.theta_u < phi_hi; k += 1) {
                const double phi = (k + 0.5) * step - g.theta_u;
                if (phi > phi_lo && phi < phi_hi) slopes.push_back(std::tan(phi));
            }
        }
        std::sort(slopes.begin(), slopes.end());
        slopes.erase(std::unique(slopes.begin(), slopes.end()), slopes.end());
        stats.events += static_cast<long>(slopes.size());
        arcs += static_cast<long>(slopes.size()) - 1;

        const Integrand f{g, pts, approx, {}, {}, {}, {}, {}, {}};
        const double phi_lo = std::atan(slopes.front()), phi_hi = std::atan(slopes.back());
        // Arcs are short and smooth: Simpson's rule on each, its error
        // bounded by |Simpson - trapezoid| (the trapezoid's error estimate,
        // far above Simpson's own on a smooth arc: a safe estimate), halving
        // an arc until that is under its share of the tolerance. The value at
        // an arc's end is the next arc's start (the integrand is continuous),
        // so an arc costs about two evaluations.
        double integral = 0;
        double a = std::atan(slopes.front());
        f.set_arc(g.theta_u + a);
        double fa = f(a);
        ++evals;
        for (size_t k = 0; k + 1 < slopes.size(); ++k) {
            const double b = std::atan(slopes[k + 1]);
            if (!(b > a)) continue;
            f.set_arc(g.theta_u + 0.5 * (a + b));
            double fb = 0;
            integral += adaptive_simpson(f, a, b, fa, tol * (b - a) / (phi_hi - phi_lo), 0, err, evals, fb);
            a = b;
            fa = fb;
        }
        return integral;
    }
};

// The window-aware L1 bound (GammaRule::Bound). Replacing cluster C's 0/1
// transmittance tau by tau_bar changes L_i F by
//   1/2 Integral_theta Integral_{P_C} (tau - tau_bar) w dp dtheta,
// w in [0, 1] the overlap window times everything else's transmittance.
// tau - tau_bar integrates to 0 over C's lines (P_C), so wherever w is
// constant over P_C (C's shadow inside the window, and no other piece's
// shadow meeting C's) the change is exactly 0; elsewhere w may be shifted by
// 1/2, giving at most ||tau - tau_bar||_L1 / 2. With several approximated
// clusters the telescoped difference of products has one such term per
// cluster. So
//   |error in F| <= 1/(4 L_i) Integral I_C(theta) L1(theta) dtheta
//                 + 1/(2 L_i) Integral delta_p |interpolation error| dtheta,
// I_C = 1 where C's shadow sticks out of the window or meets another
// piece's. I_C is sampled at the table's directions and widened by one
// sample on each side (it changes only at critical directions, between
// which it is constant).
struct Interactions {
    const PairGeometry& g;
    const std::vector<Segment>& pieces;
    const std::vector<int32_t>& piece_pos;
    long k_first = 0, k_last = -1;  // sample indices covering the range, widened
    std::vector<double> lo, hi;     // window per sample
    std::vector<std::vector<double>> starts, ends;  // sorted shadow ends per sample
    std::vector<double> start_val, end_val;         // scratch for the current sample
    std::vector<int32_t> start_order, end_order;

    static void insertion_sort(std::vector<int32_t>& order, const std::vector<double>& v) {
        for (size_t k = 1; k < order.size(); ++k) {
            const int32_t key = order[k];
            const double x = v[static_cast<size_t>(key)];
            size_t r = k;
            while (r > 0 && v[static_cast<size_t>(order[r - 1])] > x) {
                order[r] = order[r - 1];
                --r;
            }
            order[r] = key;
        }
    }

    static constexpr double pi = 3.14159265358979323846;
    static double step() { return pi / ClusterTables::directions; }
    static double theta_of(long k) { return (static_cast<double>(k) + 0.5) * step(); }

    Interactions(const PairGeometry& geo, const std::vector<Segment>& p, const std::vector<int32_t>& pos, bool needed)
        : g(geo), pieces(p), piece_pos(pos) {
        if (!needed) return;
        const double t_lo = g.theta_u - g.delta_theta, t_hi = g.theta_u + g.delta_theta;
        k_first = static_cast<long>(std::floor(t_lo / step() - 0.5)) - 1;
        k_last = static_cast<long>(std::floor(t_hi / step() - 0.5)) + 2;
        const size_t n = static_cast<size_t>(k_last - k_first + 1);
        lo.resize(n);
        hi.resize(n);
        starts.resize(n);
        ends.resize(n);
        for (size_t q = 0; q < n; ++q) {
            const double th = theta_of(k_first + static_cast<long>(q));
            const double nx = -std::sin(th), ny = std::cos(th);
            const double a0 = nx * g.ci.a.x + ny * g.ci.a.y, a1 = nx * g.ci.b.x + ny * g.ci.b.y;
            const double c0 = nx * g.cj.a.x + ny * g.cj.a.y, c1 = nx * g.cj.b.x + ny * g.cj.b.y;
            lo[q] = std::max(std::min(a0, a1), std::min(c0, c1));
            hi[q] = std::min(std::max(a0, a1), std::max(c0, c1));
            // Shadow ends, sorted. Neighbouring samples are a fraction of a
            // degree apart, so the previous sample's order is nearly right:
            // keep the index orders and repair them by insertion sort.
            const size_t m = pieces.size();
            start_val.resize(m);
            end_val.resize(m);
            for (size_t b = 0; b < m; ++b) {
                const double pa = nx * pieces[b].a.x + ny * pieces[b].a.y;
                const double pb = nx * pieces[b].b.x + ny * pieces[b].b.y;
                start_val[b] = std::min(pa, pb);
                end_val[b] = std::max(pa, pb);
            }
            if (q == 0) {  // first sample: a full sort
                start_order.resize(m);
                end_order.resize(m);
                for (size_t b = 0; b < m; ++b) start_order[b] = end_order[b] = static_cast<int32_t>(b);
                std::sort(start_order.begin(), start_order.end(),
                          [&](int32_t x, int32_t y) { return start_val[static_cast<size_t>(x)] < start_val[static_cast<size_t>(y)]; });
                std::sort(end_order.begin(), end_order.end(),
                          [&](int32_t x, int32_t y) { return end_val[static_cast<size_t>(x)] < end_val[static_cast<size_t>(y)]; });
            } else {
                insertion_sort(start_order, start_val);
                insertion_sort(end_order, end_val);
            }
            starts[q].resize(m);
            ends[q].resize(m);
            for (size_t b = 0; b < m; ++b) {
                starts[q][b] = start_val[static_cast<size_t>(start_order[b])];
                ends[q][b] = end_val[static_cast<size_t>(end_order[b])];
            }
        }
    }

    // Does C (box, own pieces [own_lo, own_hi) in `pieces`) interact at sample q?
    bool interacts(size_t q, const Box& box, size_t own_lo, size_t own_hi) const {
        if (!(hi[q] > lo[q])) return false;  // no line at this direction: w = 0, constant
        const double th = theta_of(k_first + static_cast<long>(q));
        const double nx = -std::sin(th), ny = std::cos(th);
        const double c[4] = {nx * box.lo.x + ny * box.lo.y, nx * box.hi.x + ny * box.lo.y,
                             nx * box.hi.x + ny * box.hi.y, nx * box.lo.x + ny * box.hi.y};
        const double a = std::min({c[0], c[1], c[2], c[3]}), b = std::max({c[0], c[1], c[2], c[3]});
        if (a < lo[q] || b > hi[q]) return true;  // the window cuts C's shadow
        // Pieces whose shadow meets [a, b] (closed: touching counts, which
        // only errs on the safe side): all minus those ending before a,
        // minus those starting after b. C's own pieces lie in its box, so
        // all of them meet it; any more is another piece.
        const auto& st = starts[q];
        const auto& en = ends[q];
        const long meeting = static_cast<long>(st.size()) -
                             static_cast<long>(std::lower_bound(en.begin(), en.end(), a) - en.begin()) -
                             static_cast<long>(st.end() - std::upper_bound(st.begin(), st.end(), b));
        return meeting > static_cast<long>(own_hi - own_lo);
    }

    double bound(const ClusterTables& tables, int node, const Box& box, size_t own_lo, size_t own_hi) const {
        const ClusterTable& t = tables.table(node);
        const size_t n = lo.size();
        std::vector<char> I(n);
        for (size_t q = 0; q < n; ++q) I[q] = interacts(q, box, own_lo, own_hi);
        const double t_lo = g.theta_u - g.delta_theta, t_hi = g.theta_u + g.delta_theta;
        auto sample = [&](long k) {
            return static_cast<size_t>(((k % ClusterTables::directions) + ClusterTables::directions) %
                                       ClusterTables::directions);
        };
        double l1_part = 0, interp_part = 0;
        for (size_t q = 1; q + 2 < n; ++q) {
            const long k = k_first + static_cast<long>(q);
            const double a = std::max(theta_of(k), t_lo), b = std::min(theta_of(k + 1), t_hi);
            if (!(b > a)) continue;
            const size_t s0 = sample(k), s1 = sample(k + 1);
            const double err = std::abs(t.tau_bar[s1] - t.tau_bar[s0]);
            const double dp = std::max(t.delta_p[s0], t.delta_p[s1]);
            if (I[q - 1] || I[q] || I[q + 1] || I[q + 2])
                l1_part += (b - a) * (std::max(t.L1[s0], t.L1[s1]) + 3 * dp * err);
            interp_part += (b - a) * dp * err;
        }
        return l1_part / (4 * g.L_i) + interp_part / (2 * g.L_i);
    }
};

}  // namespace

const char* gamma_rule_name(GammaRule r) {
    switch (r) {
        case GammaRule::Bound: return "bound";
        case GammaRule::BoundUniform: return "bound-uniform";
        case GammaRule::Paper: return "paper";
        case GammaRule::LineSpace: return "line-space";
    }
    return "?";
}

std::optional<GammaRule> gamma_rule_from_name(const std::string& name) {
    for (GammaRule r : {GammaRule::Bound, GammaRule::BoundUniform, GammaRule::Paper, GammaRule::LineSpace})
        if (name == gamma_rule_name(r)) return r;
    return std::nullopt;
}

MultiscaleVisibility::MultiscaleVisibility(const Hierarchy& hierarchy, const ClusterTables& tables)
    : m_hierarchy(&hierarchy), m_tables(&tables) {
    m_position.assign(hierarchy.segments().size(), -1);
    for (size_t k = 0; k < hierarchy.order().size(); ++k)
        m_position[static_cast<size_t>(hierarchy.order()[k])] = static_cast<int32_t>(k);
}

void MultiscaleVisibility::set_min_pieces_to_prove_closed(size_t n) {
    m_min_pieces_to_prove_closed = n;
    m_layers_per_depth = 0;
    const int root = m_hierarchy->root();
    if (root < 0) return;
    double length = 0;
    for (size_t k = 0; k < m_hierarchy->segments().size(); ++k)
        if (m_hierarchy->can_block(static_cast<int>(k))) length += m_hierarchy->segments()[k].length();
    const Vec2 e = m_hierarchy->node(root).box.extent();
    const double area = e.x * e.y;
    // A segment of length L, at a random angle, shadows 2 L / pi across a
    // line of sight on average.
    if (area > 0 && std::isfinite(length)) m_layers_per_depth = 2 / std::numbers::pi * length / area;
}

ClusterCriteria MultiscaleVisibility::criteria(int node, const Segment& i, const Segment& j) const {
    return criteria_for(*m_tables, node, pair_geometry(i, j));
}

MultiscaleResult MultiscaleVisibility::form_factor(const Segment& i, const Segment& j, int skip_i, int skip_j,
                                                   double eps, GammaRule rule, ExactWorkspace& ws,
                                                   VisibilityStats& stats) const {
    auto range_of = [&](int s) {
        return s < 0 ? SkipRange{} : SkipRange{m_position[static_cast<size_t>(s)], 1};
    };
    return form_factor_skipping(i, j, range_of(skip_i), range_of(skip_j), eps, rule, ws, stats);
}

// Stand-ins for the two nodes' contents, facing each other: a lone segment
// stands for itself; a cluster for its cross-section (through the box
// centre, perpendicular to the line joining the centres, as wide as the box
// seen along it). A box diagonal following the contents was tried instead:
// in data/tube_bank.json it gave tubes' arcs a tau near 0 towards the hot
// plate (relative L2 2.2e-2 against 6.7e-4), and it gained nothing on
// data/default.json once elements are their own stand-ins and convex
// objects do not block their own faces (solver/hierarchical_solver.cpp).
static Segment node_stand_in(const Hierarchy& h, const ClusterNode& n, Vec2 toward, bool cross_section = false) {
    const Vec2 centre = n.box.center();
    const double d = distance(centre, toward);
    const Vec2 u = d > 0 ? (toward - centre) / d : Vec2{1, 0}, v = rot90(u);
    const Vec2 e = n.box.extent();
    const double half = std::max(0.5 * (std::abs(e.x * v.x) + std::abs(e.y * v.y)), 1e-12 * d);
    Segment s{centre + v * half, centre - v * half};
    if (!cross_section && n.count == 1) s = h.segments()[static_cast<size_t>(h.order()[static_cast<size_t>(n.first)])];
    return orient(s.a, s.b, toward) >= 0 ? s : s.reversed();
}

TransmittanceResult MultiscaleVisibility::transmittance(int node_a, int node_b, double eps, GammaRule rule,
                                                        ExactWorkspace& ws, VisibilityStats& stats) const {
    return transmittance(node_a, node_b, node_a, node_b, eps, rule, ws, stats);
}

TransmittanceResult MultiscaleVisibility::transmittance(int node_a, int node_b, int skip_a, int skip_b, double eps,
                                                        GammaRule rule, ExactWorkspace& ws,
                                                        VisibilityStats& stats) const {
    const ClusterNode& A = m_hierarchy->node(node_a);
    const ClusterNode& B = m_hierarchy->node(node_b);
    const Vec2 ca = A.box.center(), cb = B.box.center();
    if (ca == cb) return {};
    if (auto t = transmittance_between(node_stand_in(*m_hierarchy, A, cb), node_stand_in(*m_hierarchy, B, ca), skip_a,
                                       skip_b, eps, rule, ws, stats))
        return *t;
    // Cross-sections through the centres face each other: never empty.
    return transmittance_between(node_stand_in(*m_hierarchy, A, cb, true), node_stand_in(*m_hierarchy, B, ca, true),
                                 skip_a, skip_b, eps, rule, ws, stats)
        .value_or(TransmittanceResult{});
}

TransmittanceResult MultiscaleVisibility::transmittance(const Segment& a, int skip_a, int node_b, int skip_b,
                                                        double eps, GammaRule rule, ExactWorkspace& ws,
                                                        VisibilityStats& stats) const {
    const ClusterNode& B = m_hierarchy->node(node_b);
    for (bool cross_section : {false, true})
        if (auto t = transmittance_between(a, node_stand_in(*m_hierarchy, B, a.midpoint(), cross_section), skip_a,
                                           skip_b, eps, rule, ws, stats))
            return *t;
    // The segment sees neither stand-in (node_b's centre lies behind it or
    // on its line): unknown, which makes the caller refine.
    TransmittanceResult unknown;
    unknown.tau = 1;
    unknown.error_bound = 1;
    return unknown;
}

// Empty when the two stand-ins cannot see each other (no line joins them
// from lit side to lit side).
std::optional<TransmittanceResult> MultiscaleVisibility::transmittance_between(const Segment& sa, const Segment& sb,
                                                                               int skip_a, int skip_b, double eps,
                                                                               GammaRule rule, ExactWorkspace& ws,
                                                                               VisibilityStats& stats) const {
    TransmittanceResult out;
    const double unoccluded = form_factor_unoccluded(sa, sb);
    if (!(unoccluded > 0)) return std::nullopt;
    const ClusterNode& SA = m_hierarchy->node(skip_a);
    const ClusterNode& SB = m_hierarchy->node(skip_b);
    const MultiscaleResult r = form_factor_skipping(sa, sb, SkipRange{SA.first, SA.count},
                                                    SkipRange{SB.first, SB.count}, eps * unoccluded, rule, ws, stats);
    out.tau = std::min(1.0, r.F / unoccluded);
    out.error_bound = r.error_bound / unoccluded;
    if (!std::isnan(r.estimate)) out.estimate = std::min(1.0, r.estimate / unoccluded);
    out.clusters_visited = r.clusters_visited;
    out.clusters_approximated = r.clusters_approximated;
    return out;
}

double MultiscaleVisibility::long_shaft_depth() const {
    if (!(m_layers_per_depth > 0) || m_min_pieces_to_prove_closed == std::numeric_limits<size_t>::max())
        return infinity;
    return long_shaft_layers / m_layers_per_depth;
}

bool MultiscaleVisibility::shown_closed(const Segment& a, int skip_a, const Segment& t, ExactWorkspace& ws,
                                        VisibilityStats& stats) const {
    const ClusterNode& SA = m_hierarchy->node(skip_a);
    const MultiscaleResult r =
        form_factor_skipping(a, t, SkipRange{SA.first, SA.count}, SkipRange{}, 0, GammaRule::Bound, ws, stats, true);
    const bool closed = r.F == 0 && r.error_bound == 0;
    if (closed) ++stats.screens;
    return closed;
}

MultiscaleResult MultiscaleVisibility::form_factor_skipping(const Segment& i, const Segment& j, SkipRange skip_a,
                                                            SkipRange skip_b, double eps, GammaRule rule,
                                                            ExactWorkspace& ws, VisibilityStats& stats,
                                                            bool slabs_only) const {
    MultiscaleResult out;
    const PairGeometry g = pair_geometry(i, j);
    if (!g.visible) {
        ++stats.culled;
        if (slabs_only) out.error_bound = infinity;  // not shown closed: nothing was asked
        return out;
    }
    const Shaft shaft(g.ci, g.cj);
    const double size = shaft.box.diagonal();

    // 1. Walk the hierarchy through the shaft: exact leaves, approximated
    //    clusters, opened clusters.
    // A node whose segments overlap a skipped range is never approximated.
    auto holds = [&](const ClusterNode& n, SkipRange r) {
        return r.count > 0 && r.first < n.first + n.count && n.first < r.first + r.count;
    };
    auto skipped = [&](int32_t pos) {
        return (pos >= skip_a.first && pos < skip_a.first + skip_a.count) ||
               (pos >= skip_b.first && pos < skip_b.first + skip_b.count);
    };
    // The walk through the shaft: hands every blocking segment (not
    // skipped) of each leaf whose box overlaps the shaft and passes box_ok
    // to take(position, segment), which says whether that closes the shaft
    // (the walk then stops: returns true).
    // A node whose box is surely inside the shaft goes on the stack as
    // -1 - node: its descendants are inside too, and are not tested again.
    auto walk = [&](auto&& box_ok, auto&& take) {
        bool closed = false;
        auto& stack = ws.stack;
        stack.clear();
        if (m_hierarchy->root() >= 0) stack.push_back(m_hierarchy->root());
        while (!stack.empty() && !closed) {
            const int top = stack.back();
            stack.pop_back();
            const bool known_inside = top < 0;
            const ClusterNode& n = m_hierarchy->node(known_inside ? -1 - top : top);
            if (n.blockers == 0) continue;  // nothing below can block (Hierarchy::set_blockers)
            ++out.clusters_visited;
            const Shaft::Where w = known_inside ? Shaft::Where::inside : shaft.where(n.box);
            if (w == Shaft::Where::outside || !box_ok(n.box)) continue;
            if (!n.leaf()) {
                const bool inside = w == Shaft::Where::inside;
                stack.push_back(inside ? -1 - n.child[1] : n.child[1]);
                stack.push_back(inside ? -1 - n.child[0] : n.child[0]);
                continue;
            }
            for (int q = n.first; q < n.first + n.count && !closed; ++q) {
                if (skipped(q)) continue;
                if (!m_hierarchy->can_block_at(q)) continue;
                closed = take(q, m_hierarchy->segment_at(q));
            }
        }
        return closed;
    };
    // Bands of whole segments across the shaft (opaque_band.h): shown
    // closed (exactly 0) or, with a tolerance, its exchange bounded within
    // it, for a few small sorts; the bound's midpoint is the answer, as for
    // the direction bounds below. True when that settles the query (`out`
    // holds the answer).
    auto settled_by_bands = [&](const std::vector<Segment>& whole, const double* depths) {
        BandOptions band;  // eps = 0: the proof of closure alone
        band.depths = depths;
        if (eps > 0) {
            band.limit = 2 * eps * g.L_i;
            // (A proof's slabs within a budget, box_closure.cpp, keep the
            // proof's narrow bins: the budget is a sliver of the shaft's
            // exchange, and wide bins' drift leaves gaps that use it up.
            // On the 10^5 forest at eps 10 the box proofs' failures cost
            // 0.24 thread-s with the bounds' drift, 0.11 with the proof's.)
            band.drift = slabs_only ? opaque_band_drift : band_bound_drift;
            band.max_checks = band_bound_max_checks;
        }
        const double upper = band_bound(g.ci, g.cj, whole.data(), whole.size(), band, ws.band);
        if (upper == 0) {
            ++stats.opaque;
            return true;
        }
        if (upper <= band.limit) {
            ++stats.banded;
            out.F = 0.5 * upper / g.L_i;
            out.error_bound = 0.5 * upper / g.L_i;
            return true;
        }
        return false;
    };

    // 0. A long shaft: bands need only the pieces near their depths. Where
    //    the scene's density puts long_shaft_layers layers of shadow between
    //    the patches, the slabs around the three bands' depths
    //    (band_slab_layers each) are walked first, alone; if their bands
    //    settle the query, the rest of the shaft is never walked. Otherwise
    //    the walk below starts over.
    //    The slabs lie side by side from the shaft's narrower end: a band
    //    needs fewest pieces where the section is narrowest, and the
    //    section grows linearly with depth, so at the far end of a link
    //    from an element to a cluster metres away it can be many times
    //    wider, and the pieces to walk and to sort with it. (On the 10^5
    //    forest at eps 10: 52.8 s with the slabs evenly spaced, 35.9 s with
    //    these, 566 and 359 million cluster visits. The same placement for
    //    the whole shaft's bands below, after the slabs: 37.4 s, and the
    //    balance 1.1% against 0.5%: not kept.)
    if (m_layers_per_depth > 0 && m_min_pieces_to_prove_closed != std::numeric_limits<size_t>::max()) {
        auto at_depth = [&](Vec2 p) { return dot(p - g.origin, g.u); };  // the pair's frame (PairFrame)
        const double xi = std::max(at_depth(g.ci.a), at_depth(g.ci.b));
        const double xj = std::min(at_depth(g.cj.a), at_depth(g.cj.b));
        const double depth = xj - xi;
        static_assert(long_shaft_layers >= opaque_band_count * band_slab_layers, "the slabs fit in a long shaft");
        // (A screen's proof, slabs_only, needs only room for the slabs, as
        // thin as screen_min_slab_layers: its depth is set by its maker, in
        // the pair's frame it may be less.)
        const double layers = depth * m_layers_per_depth;
        const double slab_layers = slabs_only ? std::min(band_slab_layers, layers / opaque_band_count) : band_slab_layers;
        const double long_from = slabs_only ? opaque_band_count * screen_min_slab_layers : long_shaft_layers;
        if (std::isfinite(depth) && layers >= long_from) {
            const double slab = slab_layers / m_layers_per_depth, half = 0.5 * slab;
            const bool from_i = narrower_at_i(g.ci, g.cj);
            double t0[opaque_band_count], slab_lo[opaque_band_count], slab_hi[opaque_band_count];
            auto place = [&](double lead) {
                for (int k = 0; k < opaque_band_count; ++k) {
                    t0[k] = from_i ? xi + lead + (k + 0.5) * slab : xj - lead - (k + 0.5) * slab;  // the bands' depths
                    slab_lo[k] = t0[k] - half;
                    slab_hi[k] = t0[k] + half;
                }
            };
            place(0);
            auto in_slabs = [&](double lo, double hi) {
                for (int k = 0; k < opaque_band_count; ++k)
                    if (hi >= slab_lo[k] && lo <= slab_hi[k]) return true;
                return false;
            };
            // A box's depths along the axis: its centre's, +- its half
            // extent seen along it.
            auto box_in_slabs = [&](const Box& b) {
                const double c = at_depth(b.center());
                const Vec2 e = b.extent();
                const double r = 0.5 * (std::abs(e.x * g.u.x) + std::abs(e.y * g.u.y));
                return in_slabs(c - r, c + r);
            };
            auto& found = ws.band.blockers;  // whole segments
            auto& clipped = ws.blockers;     // (scratch)
            // The slabs start where the blockers do: a shaft from a lamp
            // hung above a forest crosses units of empty room first, and
            // slabs laid there hold few pieces or none, their bands too
            // thin to close. So when the pieces the slabs found all lie
            // more than half a slab from the narrower end, the slabs move
            // to the nearest of them, and when they found none, past
            // themselves, as long as the three still fit in the shaft.
            // (Where they are laid is a choice of cost only: the bands'
            // proof holds wherever they are.) On the 10^6 forest at eps 10
            // (`scripts/make-scene 1000000 --seed 1 --density 30`, 2
            // threads) the lamp's links' queries took 29.9 thread-seconds
            // before, 3.5 after (528 000 against 228 000: more links from
            // it are closed whole); cluster visits 2.45 G -> 1.56 G.
            // nearest: the depth of the nearest piece the slabs found,
            // counted from the narrower end (as lead is).
            double nearest = infinity;
            auto walk_slabs = [&] {
                found.clear();
                nearest = infinity;
                return walk(box_in_slabs, [&](int, const Segment& b) {
                    const double da = at_depth(b.a), db = at_depth(b.b);
                    if (!in_slabs(std::min(da, db), std::max(da, db))) return false;
                    // The whole segment goes to the bands (they clip it in depth
                    // only): its shadow must reach past the shaft's sides, as the
                    // lines they check may, by their drift.
                    clipped.clear();
                    const bool alone = add_blocker(shaft, b, size, clipped);
                    if (!clipped.empty()) {
                        found.push_back(b);
                        nearest = std::min(nearest, from_i ? std::min(da, db) - xi : xj - std::max(da, db));
                    }
                    return alone;
                });
            };
            bool closed = walk_slabs();
            double lead = 0;
            while (!closed) {
                double next;
                if (std::isfinite(nearest)) {
                    if (nearest <= lead + half) break;
                    next = nearest;
                } else {
                    next = lead + opaque_band_count * slab;
                }
                if (next + opaque_band_count * slab > depth) break;
                lead = next;
                place(lead);
                closed = walk_slabs();
            }
            if (closed || (found.size() >= m_min_pieces_to_prove_closed && settled_by_bands(found, t0))) {
                stats.clusters_visited += out.clusters_visited;
                ++stats.queries;
                ++stats.slabs;
                if (closed) ++stats.separated;  // one piece from side to side: 0
                return out;
            }
        }
    }
    if (slabs_only) {
        stats.clusters_visited += out.clusters_visited;
        out.error_bound = infinity;  // not settled by the slabs
        return out;
    }

    // 1a. Every blocker piece in the shaft, with its position in the
    //     hierarchy's order (a left-first walk visits positions in order).
    std::vector<Segment> pieces;
    std::vector<int32_t> piece_pos;
    auto& whole = ws.band.blockers;  // the pieces' segments, unclipped (for the bands)
    whole.clear();
    const bool separated = walk([](const Box&) { return true; }, [&](int q, const Segment& b) {
        const size_t before = pieces.size();
        const bool alone = add_blocker(shaft, b, size, pieces);
        if (pieces.size() > before) {
            piece_pos.push_back(q);
            whole.push_back(b);
        }
        return alone;
    });
    stats.clusters_visited += out.clusters_visited;
    ++stats.queries;
    // 1b. A crowded shaft: bands first.
    if (!separated && pieces.size() >= m_min_pieces_to_prove_closed && settled_by_bands(whole, nullptr)) return out;
    //     A crowded shaft, a loose tolerance: bounds by direction bins
    //     (direction_bounds.h) may meet it for much less than the exact
    //     integral or the mixed one; they are tried with a budget. A loose
    //     query (see loose_tolerance) from fewer pieces and bins, with the
    //     bins' midpoint rule as its estimate.
    const bool loose = eps > 0 && pieces.size() >= m_min_pieces_to_bound_loose &&
                       eps * g.L_i >= loose_tolerance * exchange_crossed_strings(g.ci, g.cj);
    if (!separated && eps > 0 && pieces.size() >= (loose ? m_min_pieces_to_bound_loose : m_min_pieces_to_bound)) {
        const long budget = std::max(bounds_min_budget, static_cast<long>(pieces.size() * bounds_budget_per_piece));
        DirectionBoundsOptions how;
        if (loose) {
            how.initial_bins = loose_initial_bins;
            how.estimate = true;
        }
        const DirectionBounds b =
            direction_bounds(g.ci, g.cj, pieces.data(), pieces.size(), eps * g.L_i, budget, ws.bounds, how);
        if (b.converged) {
            ++stats.bounded;
            stats.events += b.evaluations;
            out.F = 0.5 * (b.lo + b.hi) / g.L_i;
            out.error_bound = 0.5 * (b.hi - b.lo) / g.L_i;
            out.estimate = b.estimate / g.L_i;
            return out;
        }
    }
    std::vector<Segment>& exact = ws.blockers;
    exact.clear();
    std::vector<Approx> approx;
    double bound = 0;
    if (!separated) {
        // 1b. Decide, top down: approximate a cluster wholly inside the shaft
        //     whose criterion is below eps; the pieces of the rest are exact.
        if (pieces.size() < m_min_pieces) eps = 0;  // cheaper exact (set_min_pieces_to_approximate)
        const Interactions inter(g, pieces, piece_pos, eps > 0 && rule == GammaRule::Bound && !pieces.empty());
        auto& stack = ws.stack;
        stack.clear();
        stack.push_back(m_hierarchy->root());
        while (!stack.empty()) {
            const int k = stack.back();
            stack.pop_back();
            const ClusterNode& n = m_hierarchy->node(k);
            const auto lo = std::lower_bound(piece_pos.begin(), piece_pos.end(), n.first);
            const auto hi = std::lower_bound(lo, piece_pos.end(), n.first + n.count);
            if (lo == hi) continue;  // no piece of this node in the shaft
            if (eps > 0 && !n.leaf() && !holds(n, skip_a) && !holds(n, skip_b) && shaft.contains(n.box)) {
                double gamma;
                if (rule == GammaRule::Bound)
                    gamma = inter.bound(*m_tables, k, n.box, static_cast<size_t>(lo - piece_pos.begin()),
                                        static_cast<size_t>(hi - piece_pos.begin()));
                else
                    gamma = criteria_for(*m_tables, k, g).value(rule);
                if (gamma < eps) {
                    approx.push_back({k, {}, nullptr});
                    bound += gamma;
                    continue;
                }
            }
            if (n.leaf()) {
                for (auto it = lo; it != hi; ++it) exact.push_back(pieces[static_cast<size_t>(it - piece_pos.begin())]);
                continue;
            }
            stack.push_back(n.child[1]);
            stack.push_back(n.child[0]);
        }
    }
    if (separated) {
        // One exact blocker closes the shaft: 0 whatever was approximated.
        ++stats.separated;
        return out;
    }
    out.exact_blockers = static_cast<long>(exact.size());
    out.clusters_approximated = static_cast<long>(approx.size());
    stats.approximated += out.clusters_approximated;
    stats.blockers += out.exact_blockers;

    // 2. Nothing approximated: the exact integral.
    if (approx.empty()) {
        const std::vector<Segment> exact_copy = exact;  // exchange_with_blockers reuses ws.blockers
        out.F = ExactVisibility::exchange_with_blockers(g.ci, g.cj, exact_copy, ws, stats) / g.L_i;
        return out;
    }

    // 3. Otherwise integrate over directions numerically.
    for (Approx& a : approx) a.table = &m_tables->table(a.node);
    const double tol = quadrature_share * std::max(eps, 1e-15) * 2 * g.L_i;
    MixedIntegral mi{*m_hierarchy, ws, stats, 0, 0, 0};
    const double integral = mi.solve(g.ci, g.cj, exact.data(), exact.size(), approx, tol, 0);
    out.arcs = mi.arcs;
    out.evaluations = mi.evals;
    out.F = std::max(0.0, integral / 2 / g.L_i);
    out.quadrature_error = mi.err / 2 / g.L_i;
    out.error_bound = bound + out.quadrature_error;
    return out;
}

}  // namespace flatrad
