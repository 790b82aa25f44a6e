#include "solver/hierarchical_solver.h"
#include "solver/closed_enclosure.h"
#include "solver/reachability.h"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <fmt/format.h>

#include "engine/compensated_sum.h"
#include "engine/error.h"
#include "engine/formfactor.h"
#include "engine/hierarchy.h"
#include "visibility/cluster_tables.h"
#include "visibility/exact_visibility.h"
#include "visibility/multiscale.h"

namespace flatrad {

namespace {

// closure_tolerance (solver/closed_enclosure.h) also serves below to tell
// a row sum of 1 from rounding.

// GMRES stops at ||E - (I - rho G) B|| <= gmres_tolerance ||E||. The
// operator is applied in double with sums of at most a few thousand terms,
// so 1e-12 is reachable and keeps B to ~1e-9 relative even where
// 1 / (1 - rho) = 1000 (white furnace 0.999).
constexpr double gmres_tolerance = 1e-12;
constexpr int gmres_restart = 60;
constexpr int gmres_max_applications = 2000;

struct Node {
    Segment seg;       // oriented lit-left
    int patch = -1;    // patch number; -1 for a sink
    int segment = -1;  // scene segment (blocker to skip)
    double s0 = 0, s1 = 1;  // parameter along the oriented patch
    double length = 0;
    int child = -1;    // first child; the second is child + 1
    int parent = -1;
    int depth = 0;
    bool sink() const { return patch < 0; }
};

struct Link {
    int r = -1, s = -1;   // receiver, sender
    double F = 0;         // F_rs (per unit length of r)
    double Fu = 0;        // unoccluded F_rs
    double vis_err = 0;   // multiscale bound on |F - F_exact|
    double w = 0;         // how unevenly F spreads over r: L_r (kernel + occlusion variation)
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Restarted GMRES with Givens rotations (Saad & Schultz 1986) for A x = b,
// A given as apply(x) -> A x. Returns the number of applications.
template <class Apply>
long gmres(const Apply& apply, const Eigen::VectorXd& b, Eigen::VectorXd& x, double& rel_residual) {
    const double bnorm = b.norm();
    long apps = 0;
    if (bnorm == 0) {
        x.setZero();
        rel_residual = 0;
        return 0;
    }
    const int n = static_cast<int>(b.size());
    const int m = std::min(gmres_restart, n);
    Eigen::MatrixXd V(n, m + 1), H = Eigen::MatrixXd::Zero(m + 1, m);
    Eigen::VectorXd cs(m), sn(m), g(m + 1);
    Eigen::VectorXd r = b - apply(x);
    ++apps;
    double beta = r.norm();
    rel_residual = beta / bnorm;
    while (rel_residual > gmres_tolerance && apps < gmres_max_applications) {
        V.col(0) = r / beta;
        g.setZero();
        g(0) = beta;
        H.setZero();
        int k = 0;
        for (; k < m && apps < gmres_max_applications; ++k) {
            Eigen::VectorXd w = apply(V.col(k));
            ++apps;
            for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
                H(i, k) = w.dot(V.col(i));
                w -= H(i, k) * V.col(i);
            }
            H(k + 1, k) = w.norm();
            if (H(k + 1, k) > 0) V.col(k + 1) = w / H(k + 1, k);
            for (int i = 0; i < k; ++i) {
                const double t = cs(i) * H(i, k) + sn(i) * H(i + 1, k);
                H(i + 1, k) = -sn(i) * H(i, k) + cs(i) * H(i + 1, k);
                H(i, k) = t;
            }
            const double d = std::hypot(H(k, k), H(k + 1, k));
            cs(k) = d > 0 ? H(k, k) / d : 1;
            sn(k) = d > 0 ? H(k + 1, k) / d : 0;
            H(k, k) = d;
            H(k + 1, k) = 0;
            g(k + 1) = -sn(k) * g(k);
            g(k) = cs(k) * g(k);
            if (std::abs(g(k + 1)) <= gmres_tolerance * bnorm || H(k, k) == 0) {
                ++k;
                break;
            }
        }
        // Solve the small triangular system and update x.
        Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
        x += V.leftCols(k) * y;
        r = b - apply(x);
        ++apps;
        beta = r.norm();
        const double prev = rel_residual;
        rel_residual = beta / bnorm;
        if (!(rel_residual < prev)) break;  // stagnation: no progress in a whole cycle
    }
    return apps;
}

class HierarchicalSolver {
public:
    HierarchicalSolver(const Scene& scene, const HierarchicalOptions& o)
        : m_scene(scene),
          m_opt(o),
          m_C(scene.channels),
          m_hierarchy(scene.segment_geometry()),
          m_tables(m_hierarchy),
          m_vis(m_hierarchy, m_tables) {
        m_threads = o.threads > 0 ? o.threads : omp_get_max_threads();
        m_vis_eps = o.vis_eps >= 0 ? o.vis_eps : o.eps / 10;
    }

    Solution run();

private:
    const Material& material(int patch) const {
        return m_scene.materials[static_cast<size_t>(m_scene.patches[static_cast<size_t>(patch)].material)];
    }
    double rho(int node, int c) const {
        const Node& n = m_nodes[static_cast<size_t>(node)];
        return n.sink() ? 0.0 : material(n.patch).reflectance[static_cast<size_t>(c)];
    }
    double emission(int node, int c) const {
        const Node& n = m_nodes[static_cast<size_t>(node)];
        return n.sink() ? 0.0 : material(n.patch).emission[static_cast<size_t>(c)];
    }
    void refuse_closed_white() const;
    void build_roots();
    void initial_links();
    void compute_links(std::vector<Link>& links);
    int split(int node);
    bool refine();
    void solve();
    void collect_leaves();
    Eigen::VectorXd apply_G(const Eigen::VectorXd& x, std::vector<double>& Bn, std::vector<double>& Hn) const;

    const Scene& m_scene;
    HierarchicalOptions m_opt;
    int m_C;
    int m_threads = 1;
    double m_vis_eps = 0;
    Hierarchy m_hierarchy;
    ClusterTables m_tables;
    MultiscaleVisibility m_vis;
    std::vector<Node> m_nodes;
    int m_patch_roots = 0;  // nodes [0, patches) are patch roots, then sink roots
    std::vector<Link> m_links;
    long m_left_out = 0;              // patches no emitter can reach (no links)
    std::vector<int> m_leaves;        // patch-tree leaves
    std::vector<char> m_closed;       // per patch: sees only lit patches (row sum 1)
    // Per leaf of a closed patch: the row-sum deficit 1 - (own + ancestors'
    // F), the ancestors' total F and total weight w (0 elsewhere).
    std::vector<double> m_deficit, m_anc_F, m_anc_w;
    std::vector<int> m_leaf_index;    // node -> index in m_leaves, -1 otherwise
    std::vector<std::vector<double>> m_B;  // per channel, per node (pulled)
    std::vector<std::vector<double>> m_H;  // per channel, per node (pushed: leaves complete)
    std::vector<double> m_Bmax;       // per node, max over channels
    VisibilityStats m_stats;
    double m_ff_time = 0, m_solve_time = 0, m_residual = 0;
    long m_iterations = 0;
};

void HierarchicalSolver::refuse_closed_white() const {
    for (int c = 0; c < m_C; ++c) {
        std::vector<int> white;
        for (size_t p = 0; p < m_scene.patches.size(); ++p)
            if (material(static_cast<int>(p)).reflectance[static_cast<size_t>(c)] == 1.0) white.push_back(static_cast<int>(p));
        if (white.empty()) continue;
        // Exact patch-to-patch form factors within the reflectance-1 set;
        // drop patches that leak until the set is stable (as solve_exact).
        const int n = static_cast<int>(white.size());
        Eigen::MatrixXd F = Eigen::MatrixXd::Zero(n, n);
        const ExactVisibility exact(m_hierarchy);
        ExactWorkspace ws;
        VisibilityStats st;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                const Patch& pa = m_scene.patches[static_cast<size_t>(white[static_cast<size_t>(a)])];
                const Patch& pb = m_scene.patches[static_cast<size_t>(white[static_cast<size_t>(b)])];
                if (pa.segment == pb.segment) continue;
                F(a, b) = exact.exchange(pa.oriented(m_scene.segments), pb.oriented(m_scene.segments), pa.segment,
                                         pb.segment, ws, st) / pa.length;
            }
        std::vector<double> rho(static_cast<size_t>(n), 1.0);
        const std::vector<int> closed = closed_white_set(F, rho);
        if (!closed.empty()) {
            std::vector<int> patches;
            for (int a : closed) patches.push_back(white[static_cast<size_t>(a)]);
            flatrad::refuse_closed_white(m_scene, patches, c);
        }
    }
}

void HierarchicalSolver::build_roots() {
    for (size_t p = 0; p < m_scene.patches.size(); ++p) {
        Node n;
        n.seg = m_scene.patch_segment(static_cast<int>(p));
        n.patch = static_cast<int>(p);
        n.segment = m_scene.patches[p].segment;
        n.length = m_scene.patches[p].length;
        m_nodes.push_back(n);
    }
    m_patch_roots = static_cast<int>(m_nodes.size());
    m_closed.assign(static_cast<size_t>(m_patch_roots), 0);
    // Unlit sides absorb everything they receive (SPEC): receive-only sinks.
    for (size_t s = 0; s < m_scene.segments.size(); ++s) {
        const SceneSegment& ss = m_scene.segments[s];
        for (int side = 0; side < 2; ++side) {
            if (side == 0 ? ss.lit_left : ss.lit_right) continue;
            Node n;
            n.seg = side == 0 ? ss.seg : ss.seg.reversed();
            n.segment = static_cast<int>(s);
            n.length = ss.seg.length();
            m_nodes.push_back(n);
        }
    }
}

// F for each link (both must be set: r, s), dropping the ones that do not see
// each other. An empty shaft costs crossed strings only (in the visibility
// module; counted there as `unoccluded`).
void HierarchicalSolver::compute_links(std::vector<Link>& links) {
    const auto t0 = Clock::now();
    const long n = static_cast<long>(links.size());
#pragma omp parallel num_threads(m_threads)
    {
        ExactWorkspace ws;
        VisibilityStats local;
#pragma omp for schedule(dynamic, 16)
        for (long k = 0; k < n; ++k) {
            Link& l = links[static_cast<size_t>(k)];
            const Node& r = m_nodes[static_cast<size_t>(l.r)];
            const Node& s = m_nodes[static_cast<size_t>(l.s)];
            l.Fu = form_factor_unoccluded(r.seg, s.seg);
            if (!(l.Fu > 0)) {
                ++local.culled;
                l.F = 0;
                continue;
            }
            const MultiscaleResult m =
                m_vis.form_factor(r.seg, s.seg, r.segment, s.segment, m_vis_eps, GammaRule::Bound, ws, local);
            l.F = m.F;
            l.vis_err = m.error_bound;
            if (!r.sink()) {
                double rv = 0;
                for (int q = 0; q < 4; ++q) {
                    const Segment rq{lerp(r.seg.a, r.seg.b, q / 4.0), lerp(r.seg.a, r.seg.b, (q + 1) / 4.0)};
                    rv += 0.25 * std::abs(form_factor_unoccluded(rq, s.seg) - l.Fu);
                }
                l.w = r.length * (rv + std::max(0.0, std::min(l.F, l.Fu - l.F)));
            }
        }
#pragma omp critical
        m_stats += local;
    }
    links.erase(std::remove_if(links.begin(), links.end(), [](const Link& l) { return !(l.F > 0); }), links.end());
    m_ff_time += seconds_since(t0);
}

void HierarchicalSolver::initial_links() {
    std::vector<Link> links;
    const int P = m_patch_roots, N = static_cast<int>(m_nodes.size());
    for (int r = 0; r < N; ++r)
        for (int s = 0; s < P; ++s) {
            if (m_nodes[static_cast<size_t>(r)].segment == m_nodes[static_cast<size_t>(s)].segment) continue;
            if (!clip_to_lit_halfplanes(m_nodes[static_cast<size_t>(r)].seg, m_nodes[static_cast<size_t>(s)].seg)) continue;
            links.push_back({r, s});
        }
    compute_links(links);
    // Pay only for what can be lit (solver/reachability.h): patches joined
    // by a link that may carry light (F, or its visibility bound, above 0)
    // exchange both ways; a link whose sender no emitter can reach carries
    // nothing, ever. Such links live only among unreached patches, so
    // dropping them leaves every reached patch's links as they were.
    // A pair whose approximate F cannot be told from 0 (F within its
    // visibility bound) is settled by the exact exchange.
    std::vector<std::pair<int, int>> exchanging;
    const ExactVisibility exact(m_hierarchy);
    ExactWorkspace ws;
    for (const Link& l : links) {
        if (l.r >= P || l.r > l.s) continue;
        // Grazing corners leave form factors of rounding size (1e-33 seen);
        // below 64 ulps a pair is taken as dark: it could carry at most that
        // fraction of its light.
        constexpr double noise = 64 * std::numeric_limits<double>::epsilon();
        bool carries = l.F > l.vis_err + noise;
        if (!carries && l.F + l.vis_err > noise) {
            const Node& nr = m_nodes[static_cast<size_t>(l.r)];
            const Node& ns = m_nodes[static_cast<size_t>(l.s)];
            carries = exact.exchange(nr.seg, ns.seg, nr.segment, ns.segment, ws, m_stats) >
                      noise * std::min(nr.length, ns.length);
        }
        if (carries) exchanging.push_back({l.r, l.s});
    }
    std::vector<char> emits(static_cast<size_t>(P), 0);
    for (int p = 0; p < P; ++p)
        for (int c = 0; c < m_C; ++c) emits[static_cast<size_t>(p)] = emits[static_cast<size_t>(p)] || emission(p, c) > 0;
    const std::vector<char> reached = reachable_patches(P, exchanging, emits);
    m_left_out = 0;
    for (int p = 0; p < P; ++p) m_left_out += reached[static_cast<size_t>(p)] ? 0 : 1;
    // Drop links from unreached senders, and links into unreached patches
    // (only rounding-level F can join the two: they would carry noise).
    links.erase(std::remove_if(links.begin(), links.end(),
                               [&](const Link& l) {
                                   return !reached[static_cast<size_t>(l.s)] ||
                                          (l.r < P && !reached[static_cast<size_t>(l.r)]);
                               }),
                links.end());
    m_links = std::move(links);
    // A patch whose links to lit patches sum to 1 sees nothing else (no
    // sink, no escape) at any of its points: the escape fraction and the
    // form factor to sinks are >= 0 pointwise and average to 0 over it.
    std::vector<double> sum(static_cast<size_t>(P), 0.0), bound(static_cast<size_t>(P), closure_tolerance);
    std::vector<char> sees_sink(static_cast<size_t>(P), 0);
    for (const Link& l : m_links) {
        if (m_nodes[static_cast<size_t>(l.r)].sink()) {
            // Reciprocity: s sees the sink with F_sr = L_r F_rs / L_s. Below
            // closure_tolerance (beyond the visibility bound) it is rounding:
            // grazing lines through a closed shape's shared vertices.
            const double ratio = m_nodes[static_cast<size_t>(l.r)].length / m_nodes[static_cast<size_t>(l.s)].length;
            if (ratio * (l.F - l.vis_err) > closure_tolerance) sees_sink[static_cast<size_t>(l.s)] = 1;
            continue;
        }
        sum[static_cast<size_t>(l.r)] += l.F;
        bound[static_cast<size_t>(l.r)] += l.vis_err;
    }
    m_closed.assign(static_cast<size_t>(P), 0);
    for (int p = 0; p < P; ++p)
        m_closed[static_cast<size_t>(p)] =
            !sees_sink[static_cast<size_t>(p)] && std::abs(1 - sum[static_cast<size_t>(p)]) <= bound[static_cast<size_t>(p)];
}

// Creates the two children of `node` if it has none; returns the first.
int HierarchicalSolver::split(int node) {
    if (m_nodes[static_cast<size_t>(node)].child >= 0) return m_nodes[static_cast<size_t>(node)].child;
    const Node parent = m_nodes[static_cast<size_t>(node)];
    const int first = static_cast<int>(m_nodes.size());
    const Vec2 mid = lerp(parent.seg.a, parent.seg.b, 0.5);
    for (int k = 0; k < 2; ++k) {
        Node c = parent;
        c.seg = k == 0 ? Segment{parent.seg.a, mid} : Segment{mid, parent.seg.b};
        c.s0 = k == 0 ? parent.s0 : 0.5 * (parent.s0 + parent.s1);
        c.s1 = k == 0 ? 0.5 * (parent.s0 + parent.s1) : parent.s1;
        c.length = 0.5 * parent.length;
        c.child = -1;
        c.parent = node;
        c.depth = parent.depth + 1;
        m_nodes.push_back(c);
        for (int ch = 0; ch < m_C; ++ch) {
            m_B[static_cast<size_t>(ch)].push_back(m_B[static_cast<size_t>(ch)][static_cast<size_t>(node)]);
            m_H[static_cast<size_t>(ch)].push_back(m_H[static_cast<size_t>(ch)][static_cast<size_t>(node)]);
        }
        m_Bmax.push_back(m_Bmax[static_cast<size_t>(node)]);
    }
    m_nodes[static_cast<size_t>(node)].child = first;
    return first;
}

// One refinement round with the current solution: returns whether a link split.
bool HierarchicalSolver::refine() {
    // eps_abs = eps * W / N (see the header).
    CompensatedSum W;
    for (int p = 0; p < m_patch_roots; ++p) W.add(m_nodes[static_cast<size_t>(p)].length * m_Bmax[static_cast<size_t>(p)]);
    const double eps_abs = m_opt.eps * W.value() / std::max(1, m_patch_roots);
    if (!(eps_abs > 0)) return false;

    std::vector<int> work(m_links.size());
    for (size_t k = 0; k < work.size(); ++k) work[k] = static_cast<int>(k);
    bool any = false;
    std::vector<char> decision;
    while (!work.empty()) {
        // 1. Decide (in parallel; only cheap unoccluded form factors).
        decision.assign(work.size(), 0);
        const long nw = static_cast<long>(work.size());
#pragma omp parallel for num_threads(m_threads) schedule(dynamic, 64)
        for (long k = 0; k < nw; ++k) {
            const Link& l = m_links[static_cast<size_t>(work[static_cast<size_t>(k)])];
            const Node& r = m_nodes[static_cast<size_t>(l.r)];
            const Node& s = m_nodes[static_cast<size_t>(l.s)];
            const bool can_r = !r.sink() && r.depth < m_opt.max_depth;
            const bool can_s = s.depth < m_opt.max_depth;
            if (!can_r && !can_s) continue;
            // All received power matters: rho of it for B, 1 - rho for the
            // absorbed totals (a black lamp's B is its E, but what it absorbs
            // is part of the balance).
            const double power = m_Bmax[static_cast<size_t>(l.s)] * r.length;
            if (!(power > 0)) continue;
            // Kernel variation over quarters of each side.
            double rv = 0, sv = 0;
            for (int q = 0; q < 4; ++q) {
                const Segment sq{lerp(s.seg.a, s.seg.b, q / 4.0), lerp(s.seg.a, s.seg.b, (q + 1) / 4.0)};
                sv += std::abs(form_factor_unoccluded(r.seg, sq) - 0.25 * l.Fu);
                if (!r.sink()) {
                    const Segment rq{lerp(r.seg.a, r.seg.b, q / 4.0), lerp(r.seg.a, r.seg.b, (q + 1) / 4.0)};
                    rv += 0.25 * std::abs(form_factor_unoccluded(rq, s.seg) - l.Fu);
                }
            }
            const double occlusion = std::max(0.0, std::min(l.F, l.Fu - l.F));
            double err = power * (std::max(rv, sv) + occlusion + l.vis_err);
            // The sender's own unevenness, where other links already split it:
            // the link spreads B_s's mean, not its halves' values.
            if (s.child >= 0) {
                const size_t a = static_cast<size_t>(s.child);
                double dB = 0;
                for (int c = 0; c < m_C; ++c)
                    dB = std::max(dB, std::abs(m_B[static_cast<size_t>(c)][a] - m_B[static_cast<size_t>(c)][a + 1]));
                err += r.length * l.F * 0.5 * dB;
            }
            if (err <= eps_abs) continue;
            const bool split_r = can_r && (!can_s || r.length >= s.length);
            decision[static_cast<size_t>(k)] = split_r ? 1 : 2;
        }
        // 2. Split (serially: creates nodes), collecting the children links.
        std::vector<Link> fresh;
        std::vector<char> dead(m_links.size(), 0);
        for (size_t k = 0; k < work.size(); ++k) {
            if (!decision[k]) continue;
            const Link l = m_links[static_cast<size_t>(work[k])];
            dead[static_cast<size_t>(work[k])] = 1;
            any = true;
            if (decision[k] == 1) {
                const int c = split(l.r);
                fresh.push_back({c, l.s});
                fresh.push_back({c + 1, l.s});
            } else {
                const int c = split(l.s);
                fresh.push_back({l.r, c});
                fresh.push_back({l.r, c + 1});
            }
        }
        if (fresh.empty()) break;
        // 3. Form factors of the new links (in parallel), then swap them in.
        compute_links(fresh);
        std::vector<Link> kept;
        kept.reserve(m_links.size() + fresh.size());
        for (size_t k = 0; k < m_links.size(); ++k)
            if (!dead[k]) kept.push_back(m_links[k]);
        work.clear();
        for (const Link& l : fresh) {
            work.push_back(static_cast<int>(kept.size()));
            kept.push_back(l);
        }
        m_links = std::move(kept);
    }
    return any;
}

void HierarchicalSolver::collect_leaves() {
    m_leaves.clear();
    m_leaf_index.assign(m_nodes.size(), -1);
    for (size_t k = 0; k < m_nodes.size(); ++k)
        if (!m_nodes[k].sink() && m_nodes[k].child < 0) {
            m_leaf_index[k] = static_cast<int>(m_leaves.size());
            m_leaves.push_back(static_cast<int>(k));
        }
    // Row sums per leaf: its own links' F (exact averages over the leaf) and
    // its ancestors' (averages over larger pieces: the refinement error).
    std::vector<double> own(m_nodes.size(), 0.0), anc(m_nodes.size(), 0.0);
    std::vector<double> own_w(m_nodes.size(), 0.0), anc_w(m_nodes.size(), 0.0);
    for (const Link& l : m_links) {
        own[static_cast<size_t>(l.r)] += l.F;
        own_w[static_cast<size_t>(l.r)] += l.w;
    }
    for (size_t k = 0; k < m_nodes.size(); ++k)
        if (m_nodes[k].parent >= 0) {
            const size_t q = static_cast<size_t>(m_nodes[k].parent);
            anc[k] = anc[q] + own[q];
            anc_w[k] = anc_w[q] + own_w[q];
        }
    m_deficit.assign(m_leaves.size(), 0.0);
    m_anc_F.assign(m_leaves.size(), 0.0);
    m_anc_w.assign(m_leaves.size(), 0.0);
    for (size_t i = 0; i < m_leaves.size(); ++i) {
        const size_t k = static_cast<size_t>(m_leaves[i]);
        if (!m_closed[static_cast<size_t>(m_nodes[k].patch)]) continue;
        m_deficit[i] = 1 - own[k] - anc[k];
        m_anc_F[i] = anc[k];
        m_anc_w[i] = anc_w[k];
    }
}

// G(x): pull the leaf radiosities x up the trees, gather along the links,
// push the irradiance down to the leaves. Bn, Hn receive the per-node values.
Eigen::VectorXd HierarchicalSolver::apply_G(const Eigen::VectorXd& x, std::vector<double>& Bn,
                                            std::vector<double>& Hn) const {
    const size_t N = m_nodes.size();
    Bn.assign(N, 0.0);
    Hn.assign(N, 0.0);
    std::vector<double> Hw(N, 0.0);  // sum of w * B_sender (row-sum correction)
    // Pull: children have larger numbers than their parent.
    for (size_t k = N; k-- > 0;) {
        const Node& n = m_nodes[k];
        if (n.sink()) continue;
        if (n.child < 0) {
            Bn[k] = x(m_leaf_index[k]);
        } else {
            const size_t a = static_cast<size_t>(n.child);
            Bn[k] = (m_nodes[a].length * Bn[a] + m_nodes[a + 1].length * Bn[a + 1]) / n.length;
        }
    }
    // Gather.
    for (const Link& l : m_links) {
        Hn[static_cast<size_t>(l.r)] += l.F * Bn[static_cast<size_t>(l.s)];
        Hw[static_cast<size_t>(l.r)] += l.w * Bn[static_cast<size_t>(l.s)];
    }
    // Push. A closed patch's leaf adds its row-sum deficit times the
    // w-weighted mean radiosity of its ancestors' senders.
    for (size_t k = 0; k < N; ++k) {
        if (m_nodes[k].parent < 0) continue;
        const size_t q = static_cast<size_t>(m_nodes[k].parent);
        const int i = m_leaf_index[k];
        double correction = 0;
        if (i >= 0) {
            const size_t ii = static_cast<size_t>(i);
            if (m_anc_w[ii] > 0)
                correction = m_deficit[ii] * Hw[q] / m_anc_w[ii];
            else if (m_anc_F[ii] > 0)
                correction = m_deficit[ii] * Hn[q] / m_anc_F[ii];
        }
        Hn[k] += Hn[q] + correction;
        Hw[k] += Hw[q];
    }
    Eigen::VectorXd g(static_cast<Eigen::Index>(m_leaves.size()));
    for (size_t i = 0; i < m_leaves.size(); ++i) g(static_cast<Eigen::Index>(i)) = Hn[static_cast<size_t>(m_leaves[i])];
    return g;
}

void HierarchicalSolver::solve() {
    const auto t0 = Clock::now();
    collect_leaves();
    const Eigen::Index n = static_cast<Eigen::Index>(m_leaves.size());
    std::vector<double> Bn, Hn;
    for (int c = 0; c < m_C; ++c) {
        Eigen::VectorXd E(n), rho_l(n), x(n);
        for (Eigen::Index i = 0; i < n; ++i) {
            const int node = m_leaves[static_cast<size_t>(i)];
            E(i) = emission(node, c);
            rho_l(i) = rho(node, c);
            x(i) = m_B[static_cast<size_t>(c)][static_cast<size_t>(node)];  // warm start
        }
        auto apply = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
            return v - rho_l.cwiseProduct(apply_G(v, Bn, Hn));
        };
        double rel = 0;
        m_iterations += gmres(apply, E, x, rel);
        // Final per-node values and the residual (inf-norm, as solve_exact).
        const Eigen::VectorXd r = E - apply(x);
        const double scale = std::max(E.cwiseAbs().maxCoeff(), x.cwiseAbs().maxCoeff());
        if (scale > 0) m_residual = std::max(m_residual, r.cwiseAbs().maxCoeff() / scale);
        m_B[static_cast<size_t>(c)] = Bn;
        m_H[static_cast<size_t>(c)] = Hn;
    }
    for (size_t k = 0; k < m_nodes.size(); ++k) {
        double b = 0;
        for (int c = 0; c < m_C; ++c) b = std::max(b, m_B[static_cast<size_t>(c)][k]);
        m_Bmax[k] = b;
    }
    m_solve_time += seconds_since(t0);
}

Solution HierarchicalSolver::run() {
    const auto t_start = Clock::now();
    refuse_closed_white();
    build_roots();
    m_B.assign(static_cast<size_t>(m_C), std::vector<double>(m_nodes.size(), 0.0));
    m_H = m_B;
    m_Bmax.assign(m_nodes.size(), 0.0);
    bool lit = false;
    for (int p = 0; p < m_patch_roots; ++p)
        for (int c = 0; c < m_C; ++c) lit = lit || emission(p, c) > 0;

    if (lit) {
        // Refine, solve, refine again until no link splits.
        initial_links();
        solve();
        for (int pass = 0; pass < m_opt.max_passes; ++pass) {
            if (!refine()) break;
            solve();
        }
    } else {
        collect_leaves();  // nothing emits: B = 0 everywhere, no link needed
    }

    Solution sol;
    sol.method = "hierarchical";
    sol.subdivide = 1;
    sol.eps = m_opt.eps;
    sol.vis_eps = m_vis_eps;
    sol.channels = m_C;
    sol.patches.resize(m_scene.patches.size());
    for (int leaf : m_leaves) {
        const Node& nd = m_nodes[static_cast<size_t>(leaf)];
        const Patch& patch = m_scene.patches[static_cast<size_t>(nd.patch)];
        ElementValue v;
        // The oriented segment runs against the file order for a right-lit patch.
        v.t0 = patch.lit_left ? nd.s0 : 1 - nd.s1;
        v.t1 = patch.lit_left ? nd.s1 : 1 - nd.s0;
        for (int c = 0; c < m_C; ++c) v.B.push_back(m_B[static_cast<size_t>(c)][static_cast<size_t>(leaf)]);
        sol.patches[static_cast<size_t>(nd.patch)].elements.push_back(std::move(v));
    }
    for (size_t p = 0; p < sol.patches.size(); ++p) {
        PatchResult& pr = sol.patches[p];
        std::sort(pr.elements.begin(), pr.elements.end(),
                  [](const ElementValue& x, const ElementValue& y) { return x.t0 < y.t0; });
        for (int c = 0; c < m_C; ++c) pr.radiosity.push_back(m_B[static_cast<size_t>(c)][p]);  // root = pulled mean
    }

    // Totals: absorbed by patches ((1 - rho) H) and sinks; escaped = sent - landed.
    for (int c = 0; c < m_C; ++c) {
        const auto& B = m_B[static_cast<size_t>(c)];
        const auto& H = m_H[static_cast<size_t>(c)];
        CompensatedSum emitted, absorbed, sent, landed;
        for (int leaf : m_leaves) {
            const double L = m_nodes[static_cast<size_t>(leaf)].length;
            emitted.add(L * emission(leaf, c));
            absorbed.add(L * (1 - rho(leaf, c)) * H[static_cast<size_t>(leaf)]);
            sent.add(L * B[static_cast<size_t>(leaf)]);
            landed.add(L * H[static_cast<size_t>(leaf)]);
        }
        for (const Link& l : m_links) {
            if (!m_nodes[static_cast<size_t>(l.r)].sink()) continue;
            const double P = m_nodes[static_cast<size_t>(l.r)].length * l.F * B[static_cast<size_t>(l.s)];
            landed.add(P);
            absorbed.add(P);
        }
        const double em = emitted.value(), ab = absorbed.value();
        double es = sent.value() - landed.value();
        if (std::abs(es) <= 1e-12 * std::max(em, ab)) es = 0;
        sol.totals.emitted.push_back(em);
        sol.totals.absorbed.push_back(ab);
        sol.totals.escaped.push_back(es);
        sol.totals.balance.push_back(em > 0 ? std::abs(em - ab - es) / em : 0.0);
    }

    sol.stats.form_factor_time_s = m_ff_time;
    sol.stats.linear_solve_time_s = m_solve_time;
    sol.stats.elements = static_cast<long>(m_leaves.size());
    sol.stats.links = static_cast<long>(m_links.size());
    sol.stats.patches_left_out = m_left_out;
    sol.stats.iterations = m_iterations;
    sol.stats.residual = m_residual;
    sol.stats.threads = m_threads;
    sol.stats.visibility = m_stats;
    sol.stats.time_s = seconds_since(t_start);
    return sol;
}

}  // namespace

Solution solve_hierarchical(const Scene& scene, const HierarchicalOptions& options) {
    if (!(std::isfinite(options.eps) && options.eps > 0))
        throw InputError(scene.file, "--eps", fmt::format("expected a finite number > 0, found {}", options.eps));
    if (!std::isfinite(options.vis_eps))
        throw InputError(scene.file, "--vis-eps", fmt::format("expected a finite number >= 0, found {}", options.vis_eps));
    if (options.max_depth < 0)
        throw InputError(scene.file, "", fmt::format("max_depth: expected >= 0, found {}", options.max_depth));
    HierarchicalSolver solver(scene, options);
    return solver.run();
}

}  // namespace flatrad
