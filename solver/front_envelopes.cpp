#include "solver/front_envelopes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "engine/error.h"
#include "solver/self_occlusion.h"

namespace flatrad {

namespace {

constexpr int K = directional_bins;
constexpr int half = K / 2;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// A piece of an envelope: over [x0, x1] of the axis across the bin, the
// segment at place `at` is the frontmost blocker.
struct Piece {
    double x0, x1;
    int32_t at;
};
using Envelope = std::vector<Piece>;

// The segments along one direction u (bin k): each one's interval across
// u, [lo, hi] (lo < hi, else it is no envelope's piece), its depth
// dot(x, u) at lo and the depth's slope along the axis, and which of its
// sides facing u and -u exist.
struct Projected {
    std::vector<double> lo, hi, dlo, slope;
    std::vector<uint8_t> faces;  // bit 0: its side facing u exists; bit 1: facing -u

    double depth(int32_t q, double p) const {
        const size_t s = static_cast<size_t>(q);
        return dlo[s] + (p - lo[s]) * slope[s];
    }
};

// Appends [x0, x1] of segment `at` to `out`, joined to the last piece when
// it continues it.
void emit(Envelope& out, double x0, double x1, int32_t at) {
    if (!(x1 > x0)) return;
    if (!out.empty() && out.back().at == at && out.back().x1 == x0) {
        out.back().x1 = x1;
        return;
    }
    out.push_back({x0, x1, at});
}

// The pointwise front of envelopes a and b (sign +1: the greater depth,
// along u; -1: the lesser, along -u) into `out`. Where two pieces overlap
// on [lo, hi], the one in front at both ends takes it; if they change
// places (crossing segments), the interval is split where their depths
// are equal.
void merge(std::span<const Piece> a, std::span<const Piece> b, double sign, const Projected& pr, Envelope& out) {
    out.clear();
    size_t i = 0, j = 0;
    double done = -std::numeric_limits<double>::infinity();  // everything left of it is in `out`
    while (i < a.size() && j < b.size()) {
        const Piece& p = a[i];
        const Piece& q = b[j];
        const double p0 = std::max(p.x0, done), q0 = std::max(q.x0, done);
        if (p.x1 <= q0) {  // p ends before q starts
            emit(out, p0, p.x1, p.at);
            done = p.x1;
            ++i;
            continue;
        }
        if (q.x1 <= p0) {
            emit(out, q0, q.x1, q.at);
            done = q.x1;
            ++j;
            continue;
        }
        if (p0 != q0) {  // one alone until the other starts
            const bool p_first = p0 < q0;
            emit(out, p_first ? p0 : q0, p_first ? q0 : p0, p_first ? p.at : q.at);
            done = p_first ? q0 : p0;
            continue;
        }
        const double lo = p0, hi = std::min(p.x1, q.x1);
        const double at_lo = sign * (pr.depth(p.at, lo) - pr.depth(q.at, lo));
        const double at_hi = sign * (pr.depth(p.at, hi) - pr.depth(q.at, hi));
        if (at_lo >= 0 && at_hi >= 0) {
            emit(out, lo, hi, p.at);
        } else if (at_lo <= 0 && at_hi <= 0) {
            emit(out, lo, hi, q.at);
        } else {
            // They cross inside: linear depths, equal at one point.
            const double t = std::clamp(lo + (hi - lo) * (at_lo / (at_lo - at_hi)), lo, hi);
            emit(out, lo, t, at_lo > 0 ? p.at : q.at);
            emit(out, t, hi, at_lo > 0 ? q.at : p.at);
        }
        done = hi;
        if (p.x1 == hi) ++i;
        if (q.x1 == hi) ++j;
    }
    for (; i < a.size(); ++i) emit(out, std::max(a[i].x0, done), a[i].x1, a[i].at);
    for (; j < b.size(); ++j) emit(out, std::max(b[j].x0, done), b[j].x1, b[j].at);
}

// Segment q (not a blocker) against envelope e (sign as in merge): the
// width of [lo, hi] where it lies in front of e or e is empty, and the
// integral of its depth (along the way) over that width.
std::pair<double, double> seen_in_front(int32_t q, const Envelope& e, double sign, const Projected& pr) {
    const size_t s = static_cast<size_t>(q);
    const double lo = pr.lo[s], hi = pr.hi[s];
    double width = 0, integral = 0;
    auto take = [&](double x0, double x1) {
        if (!(x1 > x0)) return;
        width += x1 - x0;
        integral += (x1 - x0) * sign * pr.depth(q, 0.5 * (x0 + x1));
    };
    // The first piece that ends past lo.
    auto it = std::upper_bound(e.begin(), e.end(), lo, [](double x, const Piece& p) { return x < p.x1; });
    double at = lo;
    for (; it != e.end() && it->x0 < hi && at < hi; ++it) {
        take(at, std::min(it->x0, hi));  // a gap of the envelope
        const double o0 = std::max(it->x0, at), o1 = std::min(it->x1, hi);
        if (o1 > o0) {
            const double d0 = sign * (pr.depth(q, o0) - pr.depth(it->at, o0));
            const double d1 = sign * (pr.depth(q, o1) - pr.depth(it->at, o1));
            if (d0 >= 0 && d1 >= 0) {
                take(o0, o1);
            } else if (d0 > 0 || d1 > 0) {
                const double t = std::clamp(o0 + (o1 - o0) * (d0 / (d0 - d1)), o0, o1);
                if (d0 > 0) take(o0, t);
                else take(t, o1);
            }
        }
        at = std::max(at, o1);
    }
    take(at, hi);
    return {width, integral};
}

// One direction pair (bins k and k + half) for every cluster: a post-order
// walk of the hierarchy, each node's two envelopes built from its
// children's (a leaf's from its blockers, one by one).
class DirectionPass {
public:
    DirectionPass(const Hierarchy& h, const std::vector<uint8_t>& sides_at, const EnvelopeClusters& c,
                  const std::vector<int32_t>& wanted, const std::vector<int32_t>& non_blockers,
                  const std::vector<std::pair<int32_t, int32_t>>& non_blocker_range,
                  const std::vector<std::pair<int32_t, int32_t>>& groups_by_first, EnvelopeShares& out)
        : m_h(h), m_sides(sides_at), m_c(c), m_wanted(wanted), m_non_blockers(non_blockers),
          m_non_blocker_range(non_blocker_range), m_groups_by_first(groups_by_first), m_out(out) {}

    void run(int k) {
        m_k = k;
        const size_t N = m_sides.size();
        const Vec2 u = bin_directions()[static_cast<size_t>(k)];
        const Vec2 v{-u.y, u.x};  // across
        Projected& pr = m_pr;
        pr.lo.resize(N);
        pr.hi.resize(N);
        pr.dlo.resize(N);
        pr.slope.resize(N);
        pr.faces.resize(N);
        bool finite = true;
        for (size_t q = 0; q < N; ++q) {
            const Segment& s = m_h.segment_at(static_cast<int32_t>(q));
            double pa = dot(s.a, v), pb = dot(s.b, v), da = dot(s.a, u), db = dot(s.b, u);
            if (pa > pb) {
                std::swap(pa, pb);
                std::swap(da, db);
            }
            finite = finite && std::isfinite(pa) && std::isfinite(pb) && std::isfinite(da) && std::isfinite(db) &&
                     std::isfinite(pb - pa);
            const double span = pb - pa;
            pr.lo[q] = pa;
            pr.hi[q] = pb;
            pr.dlo[q] = span > 0 ? da : 0.5 * (da + db);
            pr.slope[q] = span > 0 ? (db - da) / span : 0.0;
            const Facing f = facing_ways(s, m_sides[q], u);
            pr.faces[q] = static_cast<uint8_t>((f.way[0] ? 1 : 0) | (f.way[1] ? 2 : 0));
        }
        // This pass's bins start unmeasured (shares 1, front NaN).
        for (const size_t bin : {static_cast<size_t>(k), static_cast<size_t>(k + half)}) {
            std::fill_n(m_out.whole_by_bin.begin() + static_cast<std::ptrdiff_t>(bin * m_out.clusters), m_out.clusters, 1.0);
            std::fill_n(m_out.front_by_bin.begin() + static_cast<std::ptrdiff_t>(bin * m_out.clusters), m_out.clusters, nan);
            std::fill_n(m_out.group_by_bin.begin() + static_cast<std::ptrdiff_t>(bin * m_out.groups), m_out.groups, 1.0);
        }
        if (!finite) return;  // unmeasured
        const size_t H = m_h.nodes().size();
        for (auto& a : m_all) a.assign(H, 0.0);
        if (m_levels.size() < static_cast<size_t>(m_h.depth()) + 2) m_levels.resize(static_cast<size_t>(m_h.depth()) + 2);
        if (m_h.root() >= 0) build(m_h.root(), 0);
    }

private:
    struct Level {
        Envelope front, back;            // this node's, once built
        Envelope held_front, held_back;  // its first child's, while the second is built
        Envelope scratch;
    };

    // Node `node` at recursion depth d: its envelopes into m_levels[d],
    // its facing widths into m_all; measured if wanted.
    void build(int32_t node, size_t d) {
        const ClusterNode& n = m_h.node(node);
        Level& L = m_levels[d];
        L.front.clear();
        L.back.clear();
        if (n.leaf()) {
            for (int32_t q = n.first; q < n.first + n.count; ++q) {
                const size_t s = static_cast<size_t>(q);
                for (int w = 0; w < 2; ++w)
                    if (m_pr.faces[s] & (1 << w)) m_all[static_cast<size_t>(w)][static_cast<size_t>(node)] += m_pr.hi[s] - m_pr.lo[s];
                if (!(m_sides[s] & blocks) || !(m_pr.hi[s] > m_pr.lo[s])) continue;
                const Piece one[1] = {{m_pr.lo[s], m_pr.hi[s], q}};
                merge(L.front, one, 1.0, m_pr, L.scratch);
                std::swap(L.front, L.scratch);
                merge(L.back, one, -1.0, m_pr, L.scratch);
                std::swap(L.back, L.scratch);
            }
        } else {
            FLATRAD_ASSERT(d + 1 < m_levels.size(), "the hierarchy is no deeper than it says");
            build(n.child[0], d + 1);
            std::swap(L.held_front, m_levels[d + 1].front);
            std::swap(L.held_back, m_levels[d + 1].back);
            build(n.child[1], d + 1);
            const Level& R = m_levels[d + 1];
            merge(L.held_front, R.front, 1.0, m_pr, L.front);
            merge(L.held_back, R.back, -1.0, m_pr, L.back);
            for (int w = 0; w < 2; ++w) {
                auto& all = m_all[static_cast<size_t>(w)];
                all[static_cast<size_t>(node)] = all[static_cast<size_t>(n.child[0])] + all[static_cast<size_t>(n.child[1])];
            }
        }
        const int32_t c = m_wanted[static_cast<size_t>(node)];
        if (c >= 0) measure(c, L);
    }

    // Cluster c from its envelopes.
    void measure(int32_t c, const Level& L) {
        // (first place, group) of c's groups, by first place.
        const int32_t g0 = m_c.group_begin[static_cast<size_t>(c)];
        const size_t G = static_cast<size_t>(m_c.group_begin[static_cast<size_t>(c) + 1] - g0);
        const auto by_first = m_groups_by_first.begin() + g0;
        auto group_of = [&](int32_t q) {
            const auto it = std::upper_bound(by_first, by_first + static_cast<std::ptrdiff_t>(G), q,
                                             [](int32_t x, const std::pair<int32_t, int32_t>& p) { return x < p.first; });
            return static_cast<size_t>(std::prev(it)->second - g0);
        };
        const auto [nb_first, nb_last] = m_non_blocker_range[static_cast<size_t>(c)];
        const auto nb_lo = m_non_blockers.begin() + nb_first, nb_hi = m_non_blockers.begin() + nb_last;
        for (int w = 0; w < 2; ++w) {
            const Envelope& e = w == 0 ? L.front : L.back;
            const double sign = w == 0 ? 1.0 : -1.0;
            const uint8_t bit = static_cast<uint8_t>(1 << w);
            m_seen.assign(G, 0.0);
            double depth_sum = 0;
            for (const Piece& p : e) {
                if (!(m_pr.faces[static_cast<size_t>(p.at)] & bit)) continue;
                const double width = p.x1 - p.x0;
                m_seen[group_of(p.at)] += width;
                depth_sum += width * sign * m_pr.depth(p.at, 0.5 * (p.x0 + p.x1));
            }
            for (auto it = nb_lo; it != nb_hi; ++it) {
                if (!(m_pr.faces[static_cast<size_t>(*it)] & bit)) continue;
                const auto [width, integral] = seen_in_front(*it, e, sign, m_pr);
                m_seen[group_of(*it)] += width;
                depth_sum += integral;
            }
            const size_t bin = static_cast<size_t>(m_k + w * half);
            double seen = 0, all = 0;
            for (size_t g = 0; g < G; ++g) {
                const int32_t group = g0 + static_cast<int32_t>(g);
                const double a = m_all[static_cast<size_t>(w)][static_cast<size_t>(m_c.group_node[static_cast<size_t>(group)])];
                const double share = m_seen[g] / a;
                m_out.group_by_bin[bin * m_out.groups + static_cast<size_t>(group)] =
                    a > 0 && std::isfinite(share) ? std::clamp(share, 0.0, 1.0) : 1.0;
                seen += m_seen[g];
                all += a;
            }
            const double share = seen / all, mean = depth_sum / seen;
            const size_t at = bin * m_out.clusters + static_cast<size_t>(c);
            if (all > 0 && std::isfinite(share)) m_out.whole_by_bin[at] = std::clamp(share, 0.0, 1.0);
            m_out.front_by_bin[at] = seen > 0 && std::isfinite(mean) ? mean : nan;
        }
    }

    const Hierarchy& m_h;
    const std::vector<uint8_t>& m_sides;
    const EnvelopeClusters& m_c;
    const std::vector<int32_t>& m_wanted;
    const std::vector<int32_t>& m_non_blockers;
    const std::vector<std::pair<int32_t, int32_t>>& m_non_blocker_range;
    const std::vector<std::pair<int32_t, int32_t>>& m_groups_by_first;
    EnvelopeShares& m_out;
    int m_k = 0;
    Projected m_pr;
    std::vector<double> m_all[2];  // per hierarchy node and way: its facing sides' widths
    std::vector<Level> m_levels;
    std::vector<double> m_seen;
};

}  // namespace

EnvelopeShares cluster_visible_fractions(const Hierarchy& h, const std::vector<uint8_t>& sides_at,
                                         const EnvelopeClusters& clusters, int threads) {
    const size_t C = clusters.node.size();
    FLATRAD_ASSERT(clusters.group_begin.size() == C + 1, "group_begin has one entry per cluster and one more");
    FLATRAD_ASSERT(sides_at.size() == h.order().size(), "one sides entry per place");
    const size_t G = clusters.group_node.size();
    EnvelopeShares out;
    out.clusters = C;
    out.groups = G;
    out.whole_by_bin.resize(C * K);  // (each pass writes its bins in full: DirectionPass::run)
    out.group_by_bin.resize(G * K);
    out.front_by_bin.resize(C * K);
    std::vector<int32_t> wanted(h.nodes().size(), -1);
    std::vector<int32_t> non_blockers;
    for (size_t q = 0; q < sides_at.size(); ++q)
        if (!(sides_at[q] & blocks)) non_blockers.push_back(static_cast<int32_t>(q));
    // Per cluster, found once for every pass: its groups as (first place,
    // group) by first place, at group_begin[c] on, and its non-blockers,
    // non_blockers[range.first, range.second). (Flat arrays: a vector per
    // cluster, and a search of the whole scene's non-blockers per cluster
    // and pass, kept the passes waiting on memory: 5.2 s -> 3.6 s on the
    // 10^6 forest, two threads.)
    std::vector<std::pair<int32_t, int32_t>> by_first(G);
    std::vector<std::pair<int32_t, int32_t>> nb_range(C, {0, 0});
    for (size_t c = 0; c < C; ++c) {
        const ClusterNode& n = h.node(clusters.node[c]);
        if (n.count < 2) continue;  // one segment cannot hide itself: unmeasured
        wanted[static_cast<size_t>(clusters.node[c])] = static_cast<int32_t>(c);
        const auto mine = by_first.begin() + clusters.group_begin[c], end = by_first.begin() + clusters.group_begin[c + 1];
        for (int32_t g = clusters.group_begin[c]; g < clusters.group_begin[c + 1]; ++g)
            by_first[static_cast<size_t>(g)] = {h.node(clusters.group_node[static_cast<size_t>(g)]).first, g};
        std::sort(mine, end);
        [[maybe_unused]] int32_t next = n.first;  // the groups, by first place, follow one another
        for (auto it = mine; it != end; ++it) {
            FLATRAD_ASSERT(it->first == next, "a cluster's groups tile its places");
            next = it->first + h.node(clusters.group_node[static_cast<size_t>(it->second)]).count;
        }
        FLATRAD_ASSERT(next == n.first + n.count, "a cluster's groups tile its places");
        const auto lo = std::lower_bound(non_blockers.begin(), non_blockers.end(), n.first);
        const auto hi = std::lower_bound(lo, non_blockers.end(), n.first + n.count);
        nb_range[c] = {static_cast<int32_t>(lo - non_blockers.begin()), static_cast<int32_t>(hi - non_blockers.begin())};
    }
#pragma omp parallel num_threads(std::max(1, std::min(threads, half)))
    {
        DirectionPass pass(h, sides_at, clusters, wanted, non_blockers, nb_range, by_first, out);
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < half; ++k) pass.run(k);
    }
    return out;
}

}  // namespace flatrad
