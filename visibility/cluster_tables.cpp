#include "visibility/cluster_tables.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/error.h"

namespace flatrad {

namespace {

constexpr double pi = 3.14159265358979323846;

struct Interval {
    double lo, hi;
};

// Projection of the box onto n(theta) = (-sin, cos): [min, max] over corners.
Interval box_projection(const Box& b, double nx, double ny) {
    const double p[4] = {nx * b.lo.x + ny * b.lo.y, nx * b.hi.x + ny * b.lo.y, nx * b.hi.x + ny * b.hi.y,
                         nx * b.lo.x + ny * b.hi.y};
    return {std::min({p[0], p[1], p[2], p[3]}), std::max({p[0], p[1], p[2], p[3]})};
}

// Union of the segments' shadows on n, sorted and merged, clipped to `range`.
void shadow_union(const Segment* segs, size_t n, double nx, double ny, Interval range, std::vector<Interval>& out) {
    out.clear();
    for (size_t k = 0; k < n; ++k) {
        const double a = nx * segs[k].a.x + ny * segs[k].a.y, b = nx * segs[k].b.x + ny * segs[k].b.y;
        const double lo = std::max(std::min(a, b), range.lo), hi = std::min(std::max(a, b), range.hi);
        if (hi > lo) out.push_back({lo, hi});
    }
    std::sort(out.begin(), out.end(), [](const Interval& x, const Interval& y) { return x.lo < y.lo; });
    size_t w = 0;
    for (size_t k = 0; k < out.size(); ++k) {
        if (w > 0 && out[k].lo <= out[w - 1].hi)
            out[w - 1].hi = std::max(out[w - 1].hi, out[k].hi);
        else
            out[w++] = out[k];
    }
    out.resize(w);
}

// L2 distance between two piecewise-constant profiles, each `bins` equal
// cells over [-h, h] (box-centred p), 1 outside. The two grids are merged
// in one pass (both are sorted).
double profile_distance(const double* f, double hf, const double* g, double hg) {
    constexpr int n = ClusterTables::bins;
    auto value = [](const double* v, double h, double p) {
        if (p <= -h || p >= h || h <= 0) return 1.0;
        const int k = std::min(n - 1, static_cast<int>((p + h) / (2 * h) * n));
        return v[k];
    };
    double sum = 0, prev = std::min(-hf, -hg);
    int a = 0, b = 0;
    while (a <= n || b <= n) {
        const double xa = a <= n ? -hf + 2 * hf * a / n : INFINITY;
        const double xb = b <= n ? -hg + 2 * hg * b / n : INFINITY;
        const double x = std::min(xa, xb);
        if (xa <= xb) ++a;
        if (xb <= xa) ++b;
        if (x > prev) {
            const double m = 0.5 * (prev + x);
            const double d = value(f, hf, m) - value(g, hg, m);
            sum += (x - prev) * d * d;
        }
        prev = x;
    }
    return std::sqrt(sum);
}

}  // namespace

ClusterTables::ClusterTables(const Hierarchy& hierarchy)
    : m_hierarchy(&hierarchy),
      m_tables(hierarchy.nodes().size()),
      m_once(new std::once_flag[hierarchy.nodes().size()]) {}

double ClusterTables::build_seconds() const { return static_cast<double>(m_build_ns.load()) * 1e-9; }

size_t ClusterTables::bytes_per_table() { return sizeof(ClusterTable) + 6 * directions * sizeof(double); }

const ClusterTable& ClusterTables::table(int node) const {
    std::call_once(m_once[static_cast<size_t>(node)], [&] { build(node); });
    return *m_tables[static_cast<size_t>(node)];
}

void ClusterTables::build(int node) const {
    const auto t0 = std::chrono::steady_clock::now();
    const ClusterNode& nd = m_hierarchy->node(node);
    std::vector<Segment> segs;
    segs.reserve(static_cast<size_t>(nd.count));
    for (int k = nd.first; k < nd.first + nd.count; ++k) {
        const int s = m_hierarchy->order()[static_cast<size_t>(k)];
        if (m_hierarchy->can_block(s)) segs.push_back(m_hierarchy->segments()[static_cast<size_t>(s)]);  // only blockers cast shadows
    }

    auto t = std::make_unique<ClusterTable>();
    for (auto* v : {&t->delta_p, &t->tau_bar, &t->L1, &t->R2, &t->R2f, &t->R1}) v->resize(directions);
    std::vector<double> profile(static_cast<size_t>(directions) * bins);
    std::vector<Interval> shadows;
    const Vec2 c = nd.box.center();
    for (int k = 0; k < directions; ++k) {
        const double theta = (k + 0.5) * pi / directions;
        const double nx = -std::sin(theta), ny = std::cos(theta);
        const Interval box = box_projection(nd.box, nx, ny);
        const double dp = box.hi - box.lo;
        shadow_union(segs.data(), segs.size(), nx, ny, box, shadows);
        // Coverage per level-of-detail cell, and in all.
        double* cell = &profile[static_cast<size_t>(k) * bins];
        std::fill(cell, cell + bins, 0.0);
        double covered = 0;
        const double w = dp / bins;
        for (const Interval& s : shadows) {
            covered += s.hi - s.lo;
            if (w <= 0) continue;
            const int b0 = std::clamp(static_cast<int>((s.lo - box.lo) / w), 0, bins - 1);
            const int b1 = std::clamp(static_cast<int>((s.hi - box.lo) / w), 0, bins - 1);
            for (int b = b0; b <= b1; ++b) {
                const double lo = std::max(s.lo, box.lo + b * w), hi = std::min(s.hi, box.lo + (b + 1) * w);
                if (hi > lo) cell[b] += hi - lo;
            }
        }
        const double tau = dp > 0 ? std::clamp(1 - covered / dp, 0.0, 1.0) : 1.0;
        double r2f = 0;
        for (int b = 0; b < bins; ++b) {
            cell[b] = w > 0 ? std::clamp(1 - cell[b] / w, 0.0, 1.0) : 1.0;
            r2f += w * (cell[b] - tau) * (cell[b] - tau);
        }
        const size_t ks = static_cast<size_t>(k);
        t->delta_p[ks] = dp;
        t->tau_bar[ks] = tau;
        t->L1[ks] = 2 * dp * tau * (1 - tau);
        t->R2[ks] = std::sqrt(dp * tau * (1 - tau));
        t->R2f[ks] = std::sqrt(r2f);
        (void)c;
    }
    // R1: largest filtered change within Delta_theta (periodic in pi).
    const int reach = static_cast<int>(std::ceil(max_delta_theta / (pi / directions)));
    for (int k = 0; k < directions; ++k) {
        double r1 = 0;
        const double hk = 0.5 * t->delta_p[static_cast<size_t>(k)];
        // The sup over |theta' - theta| <= Delta_theta is taken over offsets
        // 1, 2, 4, ... samples and the reach itself, on both sides: the
        // profiles drift smoothly with theta, so the sup sits at the far end
        // or near a nearby jump; 2 log2(reach) + 2 comparisons instead of 2 reach.
        int offsets[16], n_off = 0;
        for (int d = 1; d < reach && n_off < 14; d *= 2) {
            offsets[n_off++] = d;
            offsets[n_off++] = -d;
        }
        offsets[n_off++] = reach;
        offsets[n_off++] = -reach;
        for (int oi = 0; oi < n_off; ++oi) {
            const int d = offsets[oi];
            const int q = ((k + d) % directions + directions) % directions;
            const double hq = 0.5 * t->delta_p[static_cast<size_t>(q)];
            // Lines of direction theta + pi are the same lines with p negated:
            // across the wrap, the profile is read backwards.
            const bool wrapped = (k + d < 0) || (k + d >= directions);
            if (!wrapped) {
                r1 = std::max(r1, profile_distance(&profile[static_cast<size_t>(k) * bins], hk,
                                                   &profile[static_cast<size_t>(q) * bins], hq));
            } else {
                double rev[bins];
                for (int b = 0; b < bins; ++b) rev[b] = profile[static_cast<size_t>(q) * bins + (bins - 1 - b)];
                r1 = std::max(r1, profile_distance(&profile[static_cast<size_t>(k) * bins], hk, rev, hq));
            }
        }
        t->R1[static_cast<size_t>(k)] = r1;
    }
    m_tables[static_cast<size_t>(node)] = std::move(t);
    ++m_built;
    m_build_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
}

ClusterTables::Sample ClusterTables::at(int node, double theta) const {
    const ClusterTable& t = table(node);
    const double step = pi / directions;
    double x = theta / step - 0.5;
    const double fl = std::floor(x);
    const double f = x - fl;
    const long k0l = static_cast<long>(fl);
    const int k0 = static_cast<int>(((k0l % directions) + directions) % directions);
    const int k1 = (k0 + 1) % directions;
    auto lin = [&](const std::vector<double>& v) {
        return (1 - f) * v[static_cast<size_t>(k0)] + f * v[static_cast<size_t>(k1)];
    };
    Sample s;
    s.delta_p = lin(t.delta_p);
    s.tau_bar = lin(t.tau_bar);
    s.L1 = lin(t.L1);
    s.R2 = lin(t.R2);
    s.R2f = lin(t.R2f);
    s.R1 = lin(t.R1);
    s.interp_err = std::abs(t.tau_bar[static_cast<size_t>(k1)] - t.tau_bar[static_cast<size_t>(k0)]);
    return s;
}

double ClusterTables::tau_bar_at(const ClusterTable& t, double theta) {
    const double step = pi / directions;
    const double x = theta / step - 0.5;
    const double fl = std::floor(x);
    const double f = x - fl;
    const long k0l = static_cast<long>(fl);
    const size_t k0 = static_cast<size_t>(((k0l % directions) + directions) % directions);
    const size_t k1 = (k0 + 1) % directions;
    return (1 - f) * t.tau_bar[k0] + f * t.tau_bar[k1];
}

double ClusterTables::max_l1_over(int node, double theta0, double theta1) const {
    const ClusterTable& t = table(node);
    const double step = pi / directions;
    const long k_lo = static_cast<long>(std::floor(theta0 / step - 0.5));
    const long k_hi = static_cast<long>(std::floor(theta1 / step - 0.5)) + 1;
    double m = 0;
    for (long k = k_lo; k <= k_hi && k <= k_lo + directions; ++k) {
        const size_t q = static_cast<size_t>(((k % directions) + directions) % directions);
        const size_t q1 = (q + 1) % directions;
        const double err = std::abs(t.tau_bar[q1] - t.tau_bar[q]);
        // L1 changes by at most 2 delta_p |d tau_bar| across the interval, and the
        // interpolated tau_bar is off by at most err: 3 delta_p err in all.
        m = std::max(m, std::max(t.L1[q], t.L1[q1]) + 3 * std::max(t.delta_p[q], t.delta_p[q1]) * err);
    }
    return m;
}

double exact_tau_bar(const std::vector<Segment>& segments, const Box& box, double theta) {
    const double nx = -std::sin(theta), ny = std::cos(theta);
    const Interval b = box_projection(box, nx, ny);
    std::vector<Interval> u;
    shadow_union(segments.data(), segments.size(), nx, ny, b, u);
    double covered = 0;
    for (const Interval& s : u) covered += s.hi - s.lo;
    return 1 - covered / (b.hi - b.lo);
}

}  // namespace flatrad
