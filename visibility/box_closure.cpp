#include "visibility/box_closure.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/formfactor.h"
#include "visibility/multiscale.h"

namespace flatrad {

double box_margin(const Box& b) {
    const double scale = std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.hi.x), std::abs(b.hi.y)});
    return 64 * std::numeric_limits<double>::epsilon() * scale + 1e-9 * b.diagonal();
}

Box widened_box(const Box& b) {
    const double m = box_margin(b);
    Box w = b;
    w.lo = {b.lo.x - m, b.lo.y - m};
    w.hi = {b.hi.x + m, b.hi.y + m};
    return w;
}

std::array<Segment, 4> outward_sides(const Box& b) {
    // Corners counter-clockwise; a side walked clockwise has the outside on
    // its left (rot90 turns counter-clockwise).
    const Vec2 c[4] = {b.lo, {b.hi.x, b.lo.y}, b.hi, {b.lo.x, b.hi.y}};
    return {Segment{c[1], c[0]}, Segment{c[2], c[1]}, Segment{c[3], c[2]}, Segment{c[0], c[3]}};
}

namespace {

bool boxes_meet(const Box& a, const Box& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y;
}

}  // namespace

// Every pair of a sender piece and a side of B that faces it must be shown
// closed (box_closure.h); a pair with no line from lit side to lit side
// has nothing to block. The pair first_pair first: on the 10^6 forest at
// eps 10 (`scripts/make-scene 1000000 --seed 1 --density 30`), 97 000
// proofs failed, a third of them at their second or third pair, after 3.8
// thread-seconds spent showing the pairs before them closed (11.5 on the
// pairs that failed); the pair that failed for a link mostly fails again
// for its children (their ends are halves of its ends).
// With a budget, each pair's slabs may leave free lines as long as the
// bands' upper bounds on them (opaque_band.h: at least the pair's exchange,
// L F) add up to at most the budget over the pairs; each pair is asked
// within what the pairs before it left.
bool MultiscaleVisibility::sides_shown_closed(const Segment* from, int n_from, SkipRange skip_from, const Box& to,
                                              SkipRange skip_to, ExactWorkspace& ws, VisibilityStats& stats,
                                              int& first_pair, double budget) const {
    const std::array<Segment, 4> sides = outward_sides(to);  // (to: widened already)
    const int pairs = 4 * n_from;
    const int first = first_pair >= 0 && first_pair < pairs ? first_pair : 0;
    bool any = false;
    for (int q = 0; q < pairs; ++q) {
        // first, then the others in order
        const int pair = q == 0 ? first : (q <= first ? q - 1 : q);
        const Segment& f = from[pair / 4];
        const Segment& t = sides[static_cast<size_t>(pair % 4)];
        if (!clip_to_lit_halfplanes(f, t)) continue;
        any = true;
        // (form_factor_skipping's F is per unit length of f; with a tolerance
        // eps its bands stop past an exchange of 2 eps L, and a bound
        // within that comes back as F = error_bound = half of it.)
        const double L = f.length();
        const double eps = budget > 0 ? budget / (2 * L) : 0.0;
        const MultiscaleResult r = form_factor_skipping(f, t, skip_from, skip_to, eps, GammaRule::Bound, ws, stats, true);
        if (r.F == 0 && r.error_bound == 0) continue;
        const double used = L * (r.F + r.error_bound);  // the bound on the pair's exchange
        if (!(budget > 0 && used <= budget)) {          // (NaN or infinity: not shown)
            first_pair = pair;
            return false;
        }
        budget -= used;
    }
    return any;
}

bool MultiscaleVisibility::box_shown_closed(const Segment& a, int skip_a, int node_b, int skip_b, ExactWorkspace& ws,
                                            VisibilityStats& stats, int& first_pair, double budget) const {
    if (!(m_layers_per_depth > 0) || m_min_pieces_to_prove_closed == std::numeric_limits<size_t>::max()) return false;
    const ClusterNode& B = m_hierarchy->node(node_b);
    if (B.box.empty()) return false;
    const Box to = widened_box(B.box);
    if (segment_meets_box(a.a, a.b, to)) return false;
    const ClusterNode& SA = m_hierarchy->node(skip_a);
    const ClusterNode& SB = m_hierarchy->node(skip_b);
    return sides_shown_closed(&a, 1, SkipRange{SA.first, SA.count}, to, SkipRange{SB.first, SB.count}, ws, stats,
                              first_pair, budget);
}

bool MultiscaleVisibility::boxes_shown_closed(int node_a, int skip_a, int node_b, int skip_b, ExactWorkspace& ws,
                                              VisibilityStats& stats, int& first_pair, double budget) const {
    if (!(m_layers_per_depth > 0) || m_min_pieces_to_prove_closed == std::numeric_limits<size_t>::max()) return false;
    const ClusterNode& A = m_hierarchy->node(node_a);
    const ClusterNode& B = m_hierarchy->node(node_b);
    if (A.box.empty() || B.box.empty()) return false;
    const Box from_box = widened_box(A.box), to = widened_box(B.box);
    if (boxes_meet(from_box, to)) return false;
    const std::array<Segment, 4> from = outward_sides(from_box);
    const ClusterNode& SA = m_hierarchy->node(skip_a);
    const ClusterNode& SB = m_hierarchy->node(skip_b);
    return sides_shown_closed(from.data(), 4, SkipRange{SA.first, SA.count}, to, SkipRange{SB.first, SB.count}, ws,
                              stats, first_pair, budget);
}

}  // namespace flatrad
