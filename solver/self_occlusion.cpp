#include "solver/self_occlusion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/error.h"

namespace flatrad {

namespace {

// Exactly, for few segments: per facing side, its interval across u minus
// the overlaps with blockers in front of it (segments that do not cross:
// which of two is in front is the same all over their overlap, so its
// midpoint decides). O(n^2) per direction, both directions of a line at
// once: bins k and k + K/2 look along u and -u, where each pair's overlap
// is the same and the front one along u is the back one along -u.
void visible_fraction_exact(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins],
                            const int32_t* group, double* gseen, double* gall, double* dsum) {
    static_assert(directional_bins % 2 == 0, "bin k + K/2 looks along -u");
    constexpr int half = directional_bins / 2;
    struct Proj {
        double lo, hi, dlo, dhi;
        bool facing[2];  // along u, along -u
        bool blocker;
        bool active;  // faces a way, across some width: its hidden parts are measured
    };
    FLATRAD_ASSERT(n <= exact_up_to, "the exact path is for few segments");
    Proj pr[exact_up_to];
    // Per way and segment: the intervals of it hidden by blockers in front
    // (at most one per other segment), and how many.
    struct Span {
        double a, b;
        bool operator<(const Span& o) const { return a < o.a || (a == o.a && b < o.b); }
    };
    Span hidden[2][exact_up_to][exact_up_to - 1];  // (no initializer: written before read)
    int count[2][exact_up_to];
    const auto& dirs = bin_directions();
    auto depth_at = [](const Proj& q, double p) {
        return q.hi > q.lo ? q.dlo + (p - q.lo) / (q.hi - q.lo) * (q.dhi - q.dlo) : std::max(q.dlo, q.dhi);
    };
    // The length of [lo, hi] not covered by the m intervals in h (sorted
    // here; pairs in their total order, so that any sort gives the same
    // sequence and the same sum).
    auto uncovered = [](double lo, double hi, Span* h, int m) {
        for (int x = 1; x < m; ++x) {  // (insertion: a few of them)
            const Span key = h[x];
            int y = x;
            for (; y > 0 && key < h[y - 1]; --y) h[y] = h[y - 1];
            h[y] = key;
        }
        double at = lo, covered = 0;
        for (int x = 0; x < m; ++x) {
            const auto [a, b] = h[x];
            if (b <= at) continue;
            covered += b - std::max(a, at);
            at = b;
        }
        return hi - lo - covered;
    };
    for (int k = 0; k < half; ++k) {
        const Vec2 u = dirs[static_cast<size_t>(k)];
        const Vec2 v{-u.y, u.x};
        for (size_t i = 0; i < n; ++i) {
            const Segment& s = segs[i];
            double pa = dot(s.a, v), pb = dot(s.b, v), da = dot(s.a, u), db = dot(s.b, u);
            if (pa > pb) {
                std::swap(pa, pb);
                std::swap(da, db);
            }
            const Facing f = facing_ways(s, sides[i], u);
            pr[i] = {pa, pb, da, db, {f.way[0], f.way[1]}, (sides[i] & blocks) != 0, (f.way[0] || f.way[1]) && pb > pa};
        }
        // Each pair once: its overlap, the midpoint and both depths there
        // are the same whichever end asks, and the one in front along u is
        // behind along -u. Pairs go in (i, j) order with i < j, so each
        // segment's intervals arrive with the other end ascending, as a
        // loop over j per segment would give them (the same sorted lists,
        // bit for bit; half the pairs' work).
        for (size_t i = 0; i < n; ++i) count[0][i] = count[1][i] = 0;
        auto hide = [&](int w, size_t i, double lo, double hi) { hidden[w][i][count[w][i]++] = {lo, hi}; };
        for (size_t i = 0; i < n; ++i) {
            const Proj& a = pr[i];
            if (!a.active && !a.blocker) continue;
            for (size_t j = i + 1; j < n; ++j) {
                const Proj& b = pr[j];
                // i hidden by j needs i active and j a blocker; j by i the reverse.
                const bool i_by_j = a.active && b.blocker, j_by_i = a.blocker && b.active;
                if (!i_by_j && !j_by_i) continue;
                const double lo = std::max(a.lo, b.lo), hi = std::min(a.hi, b.hi);
                if (!(hi > lo)) continue;
                const double mid = 0.5 * (lo + hi);
                const double db = depth_at(b, mid), da = depth_at(a, mid);
                if (i_by_j) {
                    if (a.facing[0] && db > da) hide(0, i, lo, hi);  // j in front along u
                    if (a.facing[1] && db < da) hide(1, i, lo, hi);  // j in front along -u
                }
                if (j_by_i) {
                    if (b.facing[0] && da > db) hide(0, j, lo, hi);
                    if (b.facing[1] && da < db) hide(1, j, lo, hi);
                }
            }
        }
        double seen[2] = {0, 0}, all[2] = {0, 0};
        for (size_t i = 0; i < n; ++i) {
            const Proj& a = pr[i];
            if (!a.active) continue;
            for (int w = 0; w < 2; ++w)
                if (a.facing[w]) {
                    const double width = a.hi - a.lo, visible = uncovered(a.lo, a.hi, hidden[w][i], count[w][i]);
                    all[w] += width;
                    seen[w] += visible;
                    if (dsum) dsum[k + w * half] += visible * (w == 0 ? 1 : -1) * 0.5 * (a.dlo + a.dhi);
                    if (group) {
                        const size_t at = static_cast<size_t>(group[i]) * directional_bins + static_cast<size_t>(k + w * half);
                        gall[at] += width;
                        gseen[at] += visible;
                    }
                }
        }
        for (int w = 0; w < 2; ++w) {
            const double share = seen[w] / all[w];
            if (all[w] > 0 && std::isfinite(share)) out[k + w * half] = std::clamp(share, 0.0, 1.0);  // else unmeasured: 1
        }
    }
}

}  // namespace

namespace {

// Both visible_fraction()s: with `group`, also each group's seen and
// facing lobes per bin (gseen, gall: groups x K, zeroed by the caller).
void measure(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins], int lines,
             const int32_t* group, double* gseen, double* gall, double* dsum) {
    std::fill(out, out + directional_bins, 1.0);
    if (n < 2) return;  // one segment cannot hide itself
    if (lines == 0 && n <= exact_up_to) return visible_fraction_exact(segs, sides, n, out, group, gseen, gall, dsum);
    const int M = lines > 0 ? lines : static_cast<int>(std::clamp<size_t>(2 * n, 64, 1024));
    const size_t Ms = static_cast<size_t>(M);
    // Bins k and k + K/2 look along u and -u: the same lines across, each
    // segment meeting the same ones at the same depths, the frontmost
    // blocker along -u being the hindmost along u. Both are measured in one
    // pass over the segments, w = 0 along u, w = 1 along -u.
    // Per line and way: the frontmost blocker's depth and which segment it
    // is (-1: none). What a line sees is summed per segment instead, as it
    // is found: the existing sides facing each way that a segment's lines
    // meet (all), and a segment that cannot block where it lies in front
    // of the frontmost blocker (seen). Only the frontmost blocker of a
    // line is known at the end, so its share is summed over the lines
    // then. (Per-line counts gave the same integer sums for twice the
    // stores in the loop over lines, the hot spot of a forest's build.)
    constexpr int half = directional_bins / 2;
    thread_local std::vector<double> depth[2];
    thread_local std::vector<int32_t> front_of[2];
    thread_local std::vector<uint8_t> faces[2];  // per segment: its side facing that way exists
    for (int w = 0; w < 2; ++w) {
        front_of[w].resize(Ms);
        depth[w].resize(Ms);
        faces[w].resize(n);
    }
    const auto& dirs = bin_directions();
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int k = 0; k < half; ++k) {
        const Vec2 u = dirs[static_cast<size_t>(k)];
        const Vec2 v{-u.y, u.x};  // across the lines
        double lo = inf, hi = -inf;
        for (size_t i = 0; i < n; ++i) {
            const double pa = dot(segs[i].a, v), pb = dot(segs[i].b, v);
            lo = std::min({lo, pa, pb});
            hi = std::max({hi, pa, pb});
        }
        const double wl = (hi - lo) / M;
        // Every segment along u (nothing faces it), or an extent past the
        // largest double (coordinates near 1e308): left at 1, unmeasured.
        if (!(wl > 0) || !std::isfinite(wl)) continue;
        // Depths along u; along -u the frontmost is the least of them.
        std::fill(depth[0].begin(), depth[0].end(), -inf);
        std::fill(depth[1].begin(), depth[1].end(), inf);
        for (int w = 0; w < 2; ++w) std::fill(front_of[w].begin(), front_of[w].end(), -1);
        long seen[2] = {0, 0}, all[2] = {0, 0};
        // Blockers first (the depth buffers), then the segments that cannot
        // block: seen where in front of the frontmost blocker.
        for (int pass = 0; pass < 2; ++pass) {
            for (size_t i = 0; i < n; ++i) {
                const bool blocker = (sides[i] & blocks) != 0;
                if (blocker != (pass == 0)) continue;
                const Segment& s = segs[i];
                // The sides facing u and -u, if they exist (a segment along
                // u faces nothing and covers a line's centre only by
                // rounding).
                const Facing f = facing_ways(s, sides[i], u);
                const bool* facing = f.way;
                faces[0][i] = facing[0];
                faces[1][i] = facing[1];
                if (!blocker && !facing[0] && !facing[1]) continue;
                double pa = dot(s.a, v), pb = dot(s.b, v), da = dot(s.a, u), db = dot(s.b, u);
                if (pa > pb) {
                    std::swap(pa, pb);
                    std::swap(da, db);
                }
                // Lines j, at lo + (j + 1/2) wl, within [pa, pb].
                const int j0 = std::max(0, static_cast<int>(std::ceil((pa - lo) / wl - 0.5)));
                const int j1 = std::min(M - 1, static_cast<int>(std::floor((pb - lo) / wl - 0.5)));
                if (j1 < j0) continue;
                // The depth at line j: linear in j (a segment across no
                // width, at most one line: its middle).
                const double span = pb - pa;
                const double slope = span > 0 ? (db - da) / span : 0.0;
                const double d_lo = span > 0 ? da + (lo + 0.5 * wl - pa) * slope : 0.5 * (da + db);
                const double d_step = wl * slope;
                const int32_t me = static_cast<int32_t>(i);
                const long met = j1 - j0 + 1;
                all[0] += facing[0] ? met : 0;
                all[1] += facing[1] ? met : 0;
                long seen_here[2] = {0, 0};
                double depth_here[2] = {0, 0};
                if (pass == 0) {
                    double* d0 = depth[0].data();
                    double* d1 = depth[1].data();
                    int32_t* f0 = front_of[0].data();
                    int32_t* f1 = front_of[1].data();
                    for (int j = j0; j <= j1; ++j) {
                        const double d = d_lo + j * d_step;
                        if (d > d0[j]) {
                            d0[j] = d;
                            f0[j] = me;
                        }
                        if (d < d1[j]) {
                            d1[j] = d;
                            f1[j] = me;
                        }
                    }
                } else {
                    for (int j = j0; j <= j1; ++j) {
                        const size_t js = static_cast<size_t>(j);
                        const double d = d_lo + j * d_step;
                        const bool s0 = facing[0] && d >= depth[0][js], s1 = facing[1] && d <= depth[1][js];
                        seen_here[0] += s0;
                        seen_here[1] += s1;
                        depth_here[0] += s0 ? d : 0.0;
                        depth_here[1] += s1 ? -d : 0.0;
                    }
                    seen[0] += seen_here[0];
                    seen[1] += seen_here[1];
                }
                if (dsum && pass == 1) {
                    dsum[k] += depth_here[0];
                    dsum[k + half] += depth_here[1];
                }
                if (group) {
                    const size_t g = static_cast<size_t>(group[i]) * directional_bins;
                    for (int w = 0; w < 2; ++w) {
                        const size_t at = g + static_cast<size_t>(k + w * half);
                        gall[at] += facing[w] ? met : 0;
                        gseen[at] += static_cast<double>(seen_here[w]);
                    }
                }
            }
        }
        for (int w = 0; w < 2; ++w) {
            const int32_t* of = front_of[w].data();
            const uint8_t* fw = faces[w].data();
            for (size_t j = 0; j < Ms; ++j) {
                const int32_t i = of[j];
                if (i < 0 || !fw[i]) continue;
                ++seen[w];
                if (group) gseen[static_cast<size_t>(group[i]) * directional_bins + static_cast<size_t>(k + w * half)] += 1;
                if (dsum) dsum[k + w * half] += w == 0 ? depth[0][j] : -depth[1][j];
            }
            if (all[w] > 0) out[k + w * half] = static_cast<double>(seen[w]) / static_cast<double>(all[w]);
        }
    }
}

}  // namespace

void visible_fraction(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins], int lines) {
    measure(segs, sides, n, out, lines, nullptr, nullptr, nullptr, nullptr);
}

void visible_fraction(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins],
                      const int32_t* group, int groups, double* group_out, int lines, double* front) {
    const size_t G = static_cast<size_t>(groups) * directional_bins;
    thread_local std::vector<double> seen, all;
    seen.assign(G, 0.0);
    all.assign(G, 0.0);
    double dsum[directional_bins] = {};
    measure(segs, sides, n, out, lines, group, seen.data(), all.data(), front ? dsum : nullptr);
    if (front)
        for (int k = 0; k < directional_bins; ++k) {
            // The groups' seen lobes summed, per bin (also what `out` is of all).
            double s = 0;
            for (int q = 0; q < groups; ++q) s += seen[static_cast<size_t>(q) * directional_bins + static_cast<size_t>(k)];
            const double mean = dsum[k] / s;
            front[k] = s > 0 && std::isfinite(mean) ? mean : std::numeric_limits<double>::quiet_NaN();
        }
    for (size_t q = 0; q < G; ++q) {
        const double share = seen[q] / all[q];
        group_out[q] = all[q] > 0 && std::isfinite(share) ? std::clamp(share, 0.0, 1.0) : 1.0;
    }
}

}  // namespace flatrad
