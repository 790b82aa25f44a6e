#pragma once
/// Brute-force oracle for the occluded flatland exchange L_i F_ij, written
/// from the definition (DESIGN.md §1) and sharing nothing with the line-space
/// method it checks (visibility/exact_visibility.h):
///
///     L_i F_ij = Int_{x in i} Int_{y in j} cos(phi_x) cos(phi_y) / (2 r) V(x, y) dy dx,
///
/// V = 1 when x is strictly on j's lit side, y on i's lit side and the open
/// segment xy meets no blocker.
///
///  - Inner integral, exact for each x: seen from x on i's line, a direction
///    is labelled by w = sin(angle from i's normal) = (z - x).t_i / |z - x|,
///    and the point-to-segment form factor of a fully visible piece is half
///    its w-extent (DESIGN.md §1). A point z of a blocker hides the point y of
///    j in its direction exactly when z lies in the closed region between
///    i's line and j's line, both lit sides (then z is on [x, y)): so each
///    blocker is clipped once to the two lit half-planes, and for each x its
///    shadow is the w-interval it spans, cut to j's w-interval. The visible
///    part of j is j's w-interval minus the union of shadows.
///  - Outer integral over x along i: adaptive Gauss-Kronrod (G7-K15) with a
///    global priority queue. Seeds split the domain at every "critical"
///    point, where i's line crosses the line through two of the endpoints
///    involved (j's clipped ends, the clipped blocker ends): between two
///    of them the order of all w-values is fixed, the visible measure is a
///    fixed signed sum of w(z; x), and the integrand is analytic, so K15
///    converges fast and |K15 - G7| (the G7 error, which dominates the K15
///    error by orders of magnitude on analytic pieces) is a safe upper bound
///    of each piece's error. The reported error is the plain sum of these.
///
/// Header-only, for tests. Segments are lit-left (geometry.h conventions).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <queue>
#include <utility>
#include <vector>

#include "engine/geometry.h"

namespace flatrad::bruteforce {

/// Options of the adaptive outer integration.
struct OracleOptions {
    /// Stop when the summed |K15 - G7| falls below rel_tol * |result|: 1e-12
    /// is about 1e4 ulps, well above the rounding noise of summing thousands
    /// of pieces, and far below any real disagreement.
    double rel_tol = 1e-12;
    /// ... or below abs_tol_per_length * L_i, for answers near 0 (fully
    /// blocked): w-values are sines, known to a few ulps, so a few 1e-16 per
    /// unit length of i is what rounding leaves; 1e-14 is a 50x margin.
    double abs_tol_per_length = 1e-14;
    /// Pieces narrower than (domain width) * 2^-max_depth are not split: they
    /// hold a jump that rounding moved off a split point, worth ~1e-15 * L_i.
    int max_depth = 50;
    /// Safety stop; hitting it leaves converged = false.
    long max_pieces = 2'000'000;
};

struct OracleResult {
    double value = 0;      ///< L_i F_ij
    double error = 0;      ///< sum over pieces of |K15 - G7|: the oracle's own error bound
    long pieces = 0;       ///< final number of integration pieces
    long critical = 0;     ///< seeds from critical points
    long evaluations = 0;  ///< inner integrals computed
    bool converged = true; ///< false when max_pieces was hit
};

namespace detail {

// Part of s on the closed left side of the directed line (p, q); nothing when
// that part is empty or a point, or when s lies on the line.
inline std::optional<Segment> clip_closed_left(const Segment& s, Vec2 p, Vec2 q) {
    const double oa = orient(p, q, s.a), ob = orient(p, q, s.b);
    if (oa >= 0 && ob >= 0) {
        if (oa == 0 && ob == 0) return std::nullopt;
        return s;
    }
    if (oa <= 0 && ob <= 0) return std::nullopt;
    const double t = oa / (oa - ob);
    const Vec2 m = lerp(s.a, s.b, t);
    return oa > 0 ? Segment{s.a, m} : Segment{m, s.b};
}

// Gauss-Kronrod 7-15 nodes and weights on [-1, 1] (Kronrod 1965; the values
// QUADPACK's qk15 lists). Node k: xgk[k]; odd k are the Gauss nodes.
inline constexpr std::array<double, 8> xgk = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
inline constexpr std::array<double, 8> wgk = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
// Gauss 7-point weights at xgk[1], xgk[3], xgk[5], xgk[7].
inline constexpr std::array<double, 4> wg = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct GkPiece {
    double t0, t1, k15, err;
    int depth;
    bool operator<(const GkPiece& o) const { return err < o.err; }  // max-heap on error
};

template <class F>
GkPiece gauss_kronrod(F&& f, double t0, double t1, int depth, long& evaluations) {
    const double c = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0);
    const double fc = f(c);
    double k15 = wgk[7] * fc, g7 = wg[3] * fc;
    for (int k = 0; k < 7; ++k) {
        const double s = f(c - h * xgk[k]) + f(c + h * xgk[k]);
        k15 += wgk[k] * s;
        if (k % 2 == 1) g7 += wg[k / 2] * s;
    }
    evaluations += 15;
    return {t0, t1, k15 * h, std::abs((k15 - g7) * h), depth};
}

}  // namespace detail

/// The oracle's view of one pair: everything that does not depend on x.
class Oracle {
public:
    Oracle(const Segment& i, const Segment& j, const std::vector<Segment>& blockers) : m_i(i) {
        m_L_i = i.length();
        m_tangent = i.direction() / m_L_i;
        // x must lie strictly on j's lit side: i's parameter range [m_t0, m_t1].
        const double oa = orient(j.a, j.b, i.a), ob = orient(j.a, j.b, i.b);
        if (oa <= 0 && ob <= 0) return;
        m_t0 = 0;
        m_t1 = 1;
        if (oa <= 0) m_t0 = oa / (oa - ob);
        if (ob <= 0) m_t1 = oa / (oa - ob);
        // y must lie on i's lit side (closed; the boundary has kernel 0).
        const auto jc = detail::clip_closed_left(j, i.a, i.b);
        if (!jc || !(m_t0 < m_t1)) return;
        m_j = *jc;
        m_active = true;
        // Blockers matter only between the two lines, on both lit sides
        // (closed): outside that region no open segment xy passes. A piece
        // lying on i's line or on j's line touches xy at x or y only.
        for (const Segment& b : blockers) {
            auto bi = detail::clip_closed_left(b, i.a, i.b);
            if (!bi) continue;
            auto bij = detail::clip_closed_left(*bi, j.a, j.b);
            if (!bij) continue;
            if (bij->a == bij->b) continue;
            m_blockers.push_back(*bij);
        }
    }

    bool active() const { return m_active; }
    double t0() const { return m_t0; }
    double t1() const { return m_t1; }
    const std::vector<Segment>& blocker_pieces() const { return m_blockers; }
    const Segment& j_clipped() const { return m_j; }

    /// Point on i at parameter t.
    Vec2 point(double t) const { return lerp(m_i.a, m_i.b, t); }

    /// Exact inner integral: the form factor from the point x (on i, with
    /// i's normal) to the parts of j it sees, Int_j cos cos / (2 r) V dy.
    double visible_point_form_factor(Vec2 x) const {
        if (!m_active || !(orient(m_j.a, m_j.b, x) > 0)) return 0;
        const double wa = w(x, m_j.a), wb = w(x, m_j.b);
        const double lo = std::min(wa, wb), hi = std::max(wa, wb);
        m_shadows.clear();
        for (const Segment& b : m_blockers) {
            double p = w(x, b.a), q = w(x, b.b);
            // A blocker end at x itself (a blocker touching i there): the
            // blocker spans one direction, that of its other end.
            if (std::isnan(p)) p = q;
            if (std::isnan(q)) q = p;
            if (std::isnan(p)) continue;
            const double s = std::max(std::min(p, q), lo), e = std::min(std::max(p, q), hi);
            if (s < e) m_shadows.emplace_back(s, e);
        }
        std::sort(m_shadows.begin(), m_shadows.end());
        // Sum the gaps (not hi - lo minus the cover: no cancellation when
        // almost everything is hidden).
        double visible = 0, reach = lo;
        for (const auto& [s, e] : m_shadows) {
            if (s > reach) visible += s - reach;
            reach = std::max(reach, e);
        }
        if (hi > reach) visible += hi - reach;
        return 0.5 * visible;
    }

    /// Parameters on i where the line through two endpoints (of j's clipped
    /// part and of blocker pieces) crosses i's line, inside (t0, t1), sorted
    /// and with t0, t1 added.
    std::vector<double> critical_parameters() const {
        std::vector<Vec2> pts{m_j.a, m_j.b};
        for (const Segment& b : m_blockers) {
            pts.push_back(b.a);
            pts.push_back(b.b);
        }
        std::vector<double> ts{m_t0, m_t1};
        for (size_t k = 0; k < pts.size(); ++k)
            for (size_t l = k + 1; l < pts.size(); ++l) {
                if (pts[k] == pts[l]) continue;
                const double oa = orient(pts[k], pts[l], m_i.a), ob = orient(pts[k], pts[l], m_i.b);
                if (oa == ob) continue;  // parallel to i (or on its line)
                const double t = oa / (oa - ob);
                if (t > m_t0 && t < m_t1) ts.push_back(t);
            }
        std::sort(ts.begin(), ts.end());
        ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
        return ts;
    }

    /// L_i F_ij with its error bound.
    OracleResult integrate(const OracleOptions& opt = {}) const {
        OracleResult r;
        if (!m_active) return r;
        auto f = [&](double t) { return m_L_i * visible_point_form_factor(point(t)); };
        const std::vector<double> ts = critical_parameters();
        r.critical = static_cast<long>(ts.size()) - 2;
        std::priority_queue<detail::GkPiece> open;
        std::vector<detail::GkPiece> done;
        double total = 0, err = 0;
        for (size_t k = 0; k + 1 < ts.size(); ++k) {
            const auto p = detail::gauss_kronrod(f, ts[k], ts[k + 1], 0, r.evaluations);
            total += p.k15;
            err += p.err;
            open.push(p);
        }
        const double min_width = (m_t1 - m_t0) * std::ldexp(1.0, -opt.max_depth);
        const double abs_tol = opt.abs_tol_per_length * m_L_i;
        long pieces = static_cast<long>(open.size());
        while (!open.empty() && err > std::max(abs_tol, opt.rel_tol * std::abs(total))) {
            if (pieces >= opt.max_pieces) {
                r.converged = false;
                break;
            }
            const detail::GkPiece p = open.top();
            open.pop();
            const double mid = 0.5 * (p.t0 + p.t1);
            if (p.t1 - p.t0 < min_width || !(mid > p.t0 && mid < p.t1)) {
                done.push_back(p);  // keeps its error in the sum
                continue;
            }
            const auto left = detail::gauss_kronrod(f, p.t0, mid, p.depth + 1, r.evaluations);
            const auto right = detail::gauss_kronrod(f, mid, p.t1, p.depth + 1, r.evaluations);
            total += left.k15 + right.k15 - p.k15;
            err += left.err + right.err - p.err;
            open.push(left);
            open.push(right);
            ++pieces;
        }
        // Final sums from scratch (the running ones drift), smallest first.
        while (!open.empty()) {
            done.push_back(open.top());
            open.pop();
        }
        std::sort(done.begin(), done.end(),
                  [](const auto& x, const auto& y) { return std::abs(x.k15) < std::abs(y.k15); });
        r.value = 0;
        r.error = 0;
        for (const auto& p : done) {
            r.value += p.k15;
            r.error += p.err;
        }
        r.pieces = static_cast<long>(done.size());
        return r;
    }

private:
    // w = sin of the angle from i's normal to the direction x -> z.
    double w(Vec2 x, Vec2 z) const {
        const Vec2 d = z - x;
        const double n = norm(d);
        if (n == 0) return std::nan("");
        return std::clamp(dot(d, m_tangent) / n, -1.0, 1.0);
    }

    Segment m_i;
    double m_L_i = 0;
    Vec2 m_tangent;
    bool m_active = false;
    double m_t0 = 0, m_t1 = 0;
    Segment m_j;
    std::vector<Segment> m_blockers;
    mutable std::vector<std::pair<double, double>> m_shadows;
};

/// L_i F_ij for lit-left i, j with the given blockers, by the oracle.
inline OracleResult exchange_bruteforce(const Segment& i, const Segment& j,
                                        const std::vector<Segment>& blockers,
                                        const OracleOptions& opt = {}) {
    return Oracle(i, j, blockers).integrate(opt);
}

/// Whether the open segment xy meets the closed segment [p, q] in a way that
/// blocks it (crossing or touching from one side; grazing along the segment
/// and touching at x or y only are measure-zero and count as open).
inline bool ray_blocked(Vec2 x, Vec2 y, const Segment& blocker) {
    const double o1 = orient(x, y, blocker.a), o2 = orient(x, y, blocker.b);
    const double o3 = orient(blocker.a, blocker.b, x), o4 = orient(blocker.a, blocker.b, y);
    if (o1 == 0 && o2 == 0) return false;
    const bool blocker_spans_line = (o1 <= 0 && o2 >= 0) || (o1 >= 0 && o2 <= 0);
    const bool ends_strictly_apart = (o3 < 0 && o4 > 0) || (o3 > 0 && o4 < 0);
    return blocker_spans_line && ends_strictly_apart;
}

/// Independent check of the inner integral by plain ray casting: midpoint
/// rule over `samples` points y of j, kernel cos cos / (2 r) times V from
/// ray_blocked against every (unclipped) blocker. First order accurate at
/// shadow edges; returns the value and the largest kernel sample times the
/// step (the error per shadow edge).
inline std::pair<double, double> point_form_factor_raycast(Vec2 x, const Segment& i, const Segment& j,
                                                           const std::vector<Segment>& blockers,
                                                           int samples) {
    const Vec2 n_i = i.left_normal(), n_j = j.left_normal();
    if (!(orient(j.a, j.b, x) > 0)) return {0, 0};
    const double h = j.length() / samples;
    double sum = 0, kmax = 0;
    for (int k = 0; k < samples; ++k) {
        const Vec2 y = lerp(j.a, j.b, (k + 0.5) / samples);
        const Vec2 d = y - x;
        const double r = norm(d);
        const double cx = dot(d, n_i) / r, cy = -dot(d, n_j) / r;
        if (cx <= 0 || cy <= 0) continue;
        const double kernel = cx * cy / (2 * r);
        kmax = std::max(kmax, kernel);
        bool blocked = false;
        for (const Segment& b : blockers)
            if (ray_blocked(x, y, b)) {
                blocked = true;
                break;
            }
        if (!blocked) sum += kernel;
    }
    return {sum * h, kmax * h};
}

}  // namespace flatrad::bruteforce
