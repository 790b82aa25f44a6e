#pragma once
/// Multi-scale visibility (Soler 1995, "Caractérisation multi-échelles de la
/// visibilité pour les calculs de radiosité", §2-3; DESIGN.md §2).
///
/// The occluded form factor between two segments is the line-space integral
/// of DESIGN §1 with a hierarchical transmittance tau_H in place of the
/// exact one: walking the cluster hierarchy through the pair's shaft,
///   - a leaf's segments are exact blockers;
///   - a cluster wholly inside the shaft whose criterion Gamma is below eps
///     is replaced by its mean directional transmittance tau_bar(theta) over
///     the lines that cross its box;
///   - any other cluster is opened (its children visited). A cluster that
///     is not wholly inside the shaft is never approximated.
/// With nothing approximated the result is the exact form factor (same code
/// path as ExactVisibility). Otherwise the integral over directions is done
/// by adaptive Gauss-Kronrod between the critical directions of the exact
/// part, to 1e-3 eps; its error estimate is added to the bound.
///
/// Before either, where the caller enables them, bands of pieces across a
/// crowded shaft may show it closed or bound it within the tolerance
/// (set_min_pieces_to_prove_closed, opaque_band.h; in a long shaft only the
/// slabs around the bands' depths are walked for that, the rest only if
/// they do not settle the query); then, where enabled
/// (set_min_pieces_to_bound; the hierarchical solver does both, from 32
/// pieces, and bounds loose queries from 8), a shaft crowded with blocker
/// pieces is tried with guaranteed
/// bounds by direction bins
/// (direction_bounds.h): the pieces' shadows widened and narrowed by how
/// far they can move within a bin, bins halved worst first. If the bounds
/// close to within 2 eps within a budget of bins (2 per piece), their
/// midpoint is the answer and their half-gap the claimed bound
/// (stats.bounded); otherwise the walk goes on as above. A loose query (a
/// tolerance of at least loose_tolerance of the pair's unoccluded exchange)
/// starts from fewer bins and also gets their midpoint rule
/// (MultiscaleResult::estimate). The exact integral
/// of n pieces meets ~n^2 critical directions; a bin costs two sorts of n
/// shadows, and a dense forest covers most of the window, so few bins are
/// needed.
///
/// Errors of several approximated clusters add up (for factors in [0, 1],
/// |prod a - prod b| <= sum |a - b|), so the claimed bound is the sum of the
/// criteria used. Each cluster is tested against eps alone, as in the paper.
#include <limits>
#include <optional>
#include <string>

#include "visibility/cluster_tables.h"
#include "visibility/exact_visibility.h"

namespace flatrad {

/// Which criterion decides (and bounds) an approximation. All are errors
/// in F_ij (absolute), for one cluster.
enum class GammaRule {
    /// Line-space bound with L1 norms, aware of where the cluster interacts
    /// (the default). tau - tau_bar integrates to zero over the cluster's
    /// lines, so the approximation is exact at every direction where the
    /// cluster's shadow lies inside the overlap window and meets no other
    /// piece's shadow; elsewhere its error is at most ||tau - tau_bar||_L1 / 2.
    /// Error in F <= 1/(4 L_i) Integral_{interacting} L1 dtheta plus the
    /// table's interpolation error (see Interactions in multiscale.cpp).
    Bound,
    /// The same bound assuming interaction at every direction:
    /// delta_theta max L1 / (2 L_i) plus interpolation. Simpler, looser.
    BoundUniform,
    /// The paper's Gamma as written: (2 delta_theta sqrt(delta_p) / r_min) |T| (R1 + R2),
    /// with the filtered R1, R2 at theta_12.
    Paper,
    /// DESIGN §2's line-space variant: delta_theta sqrt(delta_p) (R1 + R2) / L_i.
    LineSpace,
};

const char* gamma_rule_name(GammaRule r);
/// The rule called `name` (as gamma_rule_name writes it), if any.
std::optional<GammaRule> gamma_rule_from_name(const std::string& name);

/// The three criteria of one cluster for one pair (for experiments).
struct ClusterCriteria {
    double paper = 0, line_space = 0, bound = 0;
    double value(GammaRule r) const {
        return r == GammaRule::Paper ? paper : r == GammaRule::LineSpace ? line_space : bound;
    }
};

struct MultiscaleResult {
    double F = 0;               ///< F_ij
    double error_bound = 0;     ///< claimed bound on |F - F_exact|
    /// Where the answer is bounds (error_bound > 0), an estimate of F
    /// within them better than F itself (their midpoint), or NaN when there
    /// is none: the direction bounds' midpoint rule (DirectionBounds::estimate).
    double estimate = std::numeric_limits<double>::quiet_NaN();
    double quadrature_error = 0;  ///< part of the bound from the direction integral
    long clusters_visited = 0;
    long clusters_approximated = 0;
    long exact_blockers = 0;
    long arcs = 0;         ///< intervals of directions integrated separately
    long evaluations = 0;  ///< integrand evaluations (cost of the direction integral)
};

/// Mean transmittance of the lines joining two clusters (for cluster-level
/// links of the hierarchical solver).
struct TransmittanceResult {
    double tau = 0;          ///< in [0, 1]
    double error_bound = 0;  ///< claimed bound on |tau - tau_exact|
    double estimate = std::numeric_limits<double>::quiet_NaN();  ///< as MultiscaleResult's, on tau
    long clusters_visited = 0;
    long clusters_approximated = 0;
};

class MultiscaleVisibility {
public:
    /// `tables` is built over `hierarchy`; both outlive this object.
    MultiscaleVisibility(const Hierarchy& hierarchy, const ClusterTables& tables);

    /// F_ij between lit-left segments i and j with absolute tolerance eps on
    /// F; every hierarchy segment other than skip_i and skip_j an occluder.
    MultiscaleResult form_factor(const Segment& i, const Segment& j, int skip_i, int skip_j, double eps,
                                 GammaRule rule, ExactWorkspace& ws, VisibilityStats& stats) const;

    /// Transmittance between hierarchy nodes a and b with tolerance eps on
    /// tau: the occluded over the unoccluded form factor between two
    /// stand-ins for their contents, facing each other (a lone segment
    /// itself; a cluster its cross-section: through the box centre,
    /// perpendicular to the line joining the centres, as wide as the box
    /// seen along it), the segments inside a and b not counted as
    /// blockers. The stand-ins sample the lines between the nodes: lines
    /// meeting both boxes but missing a stand-in are not sampled (an
    /// approximation of the link's geometry, not of visibility).
    TransmittanceResult transmittance(int node_a, int node_b, double eps, GammaRule rule, ExactWorkspace& ws,
                                      VisibilityStats& stats) const;
    /// The same with the segments of hierarchy nodes skip_a and skip_b (an
    /// ancestor of node_a, of node_b, or the node itself) not counted as
    /// blockers: the caller knows they cannot stand between the two (e.g.
    /// the rest of a convex closed object node_a is part of, whose outward
    /// faces see nothing of it).
    TransmittanceResult transmittance(int node_a, int node_b, int skip_a, int skip_b, double eps, GammaRule rule,
                                      ExactWorkspace& ws, VisibilityStats& stats) const;
    /// The same between a segment (oriented lit-left, e.g. an element of a
    /// patch, which is its own stand-in) and node_b; the segments of
    /// skip_a (its segment's leaf, or an ancestor) and skip_b not blockers.
    /// When the segment sees no stand-in of node_b (its centre behind the
    /// segment's line): tau 1 with error bound 1 (unknown).
    TransmittanceResult transmittance(const Segment& a, int skip_a, int node_b, int skip_b, double eps,
                                      GammaRule rule, ExactWorkspace& ws, VisibilityStats& stats) const;

    /// The criteria of `node` for the pair (i, j) (unclipped, lit-left).
    /// Infinite when the pair cannot see each other.
    ClusterCriteria criteria(int node, const Segment& i, const Segment& j) const;

    const ClusterTables& tables() const { return *m_tables; }

    /// Approximate nothing in a shaft holding fewer than `n` blocker pieces:
    /// the answer is then the exact one (within any eps), and costs what the
    /// exact walk costs. 0 (the default) considers every shaft. A cost
    /// choice, not an accuracy one: the criterion and the direction integral
    /// of an approximated shaft cost more than the exact sweep of a few
    /// hundred pieces (measured on the solver's scenes; see
    /// solver/hierarchical_solver.cpp, where it is set).
    void set_min_pieces_to_approximate(size_t n) { m_min_pieces = n; }
    /// Try direction bounds (see above) in shafts of at least `n` blocker
    /// pieces. Off by default (SIZE_MAX). A choice of what the caller
    /// values: the bounds' midpoint carries an error of the order of the
    /// tolerance, while the cluster approximation's real error is usually
    /// far below its bound. On data/soler95-fig5.json's sweep (one form
    /// factor, 384 pieces) the cluster approximation reaches 1% at eps 0.04,
    /// 110x faster than exact, the bounds at eps 0.006, 2x faster; in the
    /// hierarchical solver, where the exact integral is what the bounds
    /// replace (the cluster approximation is left to shafts of 512 pieces or
    /// more), they make a 1000-segment forest 14x faster at 1% error.
    /// `loose`: the same for loose queries (above; at most n).
    void set_min_pieces_to_bound(size_t n, size_t loose) {
        m_min_pieces_to_bound = n;
        m_min_pieces_to_bound_loose = std::min(n, loose);
    }
    void set_min_pieces_to_bound(size_t n) { set_min_pieces_to_bound(n, n); }
    /// Try bands of pieces across a shaft of at least `n` blocker pieces
    /// (opaque_band.h) before anything else: a proof that it is closed (an
    /// exact 0, stats.opaque, at any eps) or, with eps > 0, an upper bound U
    /// within 2 eps, answered as U / 2 with bound U / 2 (stats.banded).
    /// Off by default (SIZE_MAX): a failed attempt is wasted, and pays only
    /// where many crowded shafts are nearly or wholly closed (dense forests).
    /// A long shaft (long_shaft_layers of shadow between the patches by
    /// the scene's density) is first walked only in the slabs around the
    /// bands' depths. The density is taken from the hierarchy's blockers
    /// when this is called: call it after Hierarchy::set_blockers.
    void set_min_pieces_to_prove_closed(size_t n);
    /// The scene's mean layers of shadow per unit of depth (2 / pi times
    /// the blockers' length over the root box's area: a segment of length L
    /// at a random angle shadows 2 L / pi of a line on average), set by
    /// set_min_pieces_to_prove_closed; 0 before, or with nothing to block.
    double layers_per_depth() const { return m_layers_per_depth; }
    /// The depth from which a shaft is long (its slabs walked alone first,
    /// see set_min_pieces_to_prove_closed): long_shaft_layers over
    /// layers_per_depth; infinite while the density is unknown or the
    /// proofs are off.
    double long_shaft_depth() const;

    /// Whether every line from segment a (lit on its left) to segment t
    /// (facing a) is shown blocked by the hierarchy's blockers other than
    /// those of hierarchy node skip_a: a proof from the slabs of a long
    /// shaft alone (step 0 above), nothing else tried; the shaft need not
    /// be long, only deep enough for three slabs of a few layers each
    /// (thinner than a long shaft's when it is shorter). False when the
    /// proofs are off, the shaft is not that deep, or the slabs' bands
    /// leave a gap. For closure screens (closure_screen.h): counted in
    /// stats.queries and stats.slabs as any such proof, and in
    /// stats.screens when shown closed.
    bool shown_closed(const Segment& a, int skip_a, const Segment& t, ExactWorkspace& ws,
                      VisibilityStats& stats) const;

    /// Whether every line from segment a (lit on its left) to any point of
    /// hierarchy node node_b's box is shown blocked by the hierarchy's
    /// blockers other than those of skip_a and skip_b (skip_b: node_b or an
    /// ancestor): one slab proof (as shown_closed's) per side of the box
    /// that faces a (box_closure.h, which says why that suffices). False
    /// when a meets the box, when a faces none of its sides, when the
    /// proofs are off (as shown_closed), or when any side's proof leaves a
    /// gap. Counted in stats.queries and stats.slabs per side shown
    /// closed, as any such proof.
    ///
    /// first_pair: a pair to prove first, as a proof that failed left it
    /// (the proof fails on any pair, and a gap found between a link's ends
    /// is likely still there between their halves), or -1; when this proof
    /// fails it holds the pair that failed. Pairs are numbered 4 x (side of
    /// node_a's box; 0 for a segment) + (side of node_b's box), the sides
    /// as outward_sides gives them. Only the order of the pairs' proofs
    /// depends on it, never the answer.
    ///
    /// budget: with 0, a proof of closure. Above 0, also true when the
    /// lines are shown closed but for an exchange of at most `budget` (L F,
    /// the measure of the free lines over 2, summed over the pairs: an upper
    /// bound from the slabs' bands, opaque_band.h), which bounds the
    /// exchange between a (or node_a's box) and everything inside node_b's
    /// box (box_closure.h). For a caller that may leave that much out.
    bool box_shown_closed(const Segment& a, int skip_a, int node_b, int skip_b, ExactWorkspace& ws,
                          VisibilityStats& stats, int& first_pair, double budget = 0) const;
    /// The same from any point of node_a's box (disjoint from node_b's):
    /// one proof per pair of sides that face each other.
    bool boxes_shown_closed(int node_a, int skip_a, int node_b, int skip_b, ExactWorkspace& ws,
                            VisibilityStats& stats, int& first_pair, double budget = 0) const;

private:
    std::optional<TransmittanceResult> transmittance_between(const Segment& sa, const Segment& sb, int skip_a,
                                                             int skip_b, double eps, GammaRule rule,
                                                             ExactWorkspace& ws, VisibilityStats& stats) const;
    /// Positions [first, first + count) in the hierarchy's order.
    struct SkipRange {
        int32_t first = 0, count = 0;
    };
    /// With slabs_only, step 0 alone: a query it does not settle (or that
    /// is not long) returns an error bound of +infinity.
    MultiscaleResult form_factor_skipping(const Segment& i, const Segment& j, SkipRange skip_a, SkipRange skip_b,
                                          double eps, GammaRule rule, ExactWorkspace& ws, VisibilityStats& stats,
                                          bool slabs_only = false) const;

    /// box_closure.cpp: every line from one of `from` to the box `to`
    /// (widened already) shown closed, side by side (first_pair: as
    /// box_shown_closed's).
    bool sides_shown_closed(const Segment* from, int n_from, SkipRange skip_from, const Box& to, SkipRange skip_to,
                            ExactWorkspace& ws, VisibilityStats& stats, int& first_pair, double budget = 0) const;

    const Hierarchy* m_hierarchy;
    const ClusterTables* m_tables;
    std::vector<int32_t> m_position;  // segment number -> index in hierarchy order
    size_t m_min_pieces = 0;
    size_t m_min_pieces_to_bound = std::numeric_limits<size_t>::max();
    size_t m_min_pieces_to_bound_loose = std::numeric_limits<size_t>::max();
    size_t m_min_pieces_to_prove_closed = std::numeric_limits<size_t>::max();
    double m_layers_per_depth = 0;  // the scene's layers of shadow per unit of depth (0: unknown)
};

}  // namespace flatrad
