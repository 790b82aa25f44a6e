#pragma once
/// What a solve returns: per-patch radiosity (SPEC numbering), per-element
/// values, energy totals and what the run did. apps/ writes it as the result
/// file of SPEC.md.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "visibility/stats.h"

namespace flatrad {

struct ElementValue {
    double t0 = 0, t1 = 1;     ///< parameter along the patch, file order a (0) -> b (1)
    std::vector<double> B;     ///< radiosity per channel
};

struct PatchResult {
    std::vector<double> radiosity;      ///< length-weighted mean per channel
    std::vector<ElementValue> elements; ///< sorted by t0
};

struct Totals {
    std::vector<double> emitted, absorbed, escaped, balance;  ///< per channel (SPEC)

    /// Appends one channel: escaped within 1e-12 of the larger of emitted and
    /// absorbed is rounding (1 minus a sum that is 1) and reported as 0;
    /// balance = |emitted - absorbed - escaped| / emitted (0 when nothing emits).
    void add_channel(double em, double ab, double es) {
        if (std::abs(es) <= 1e-12 * std::max(em, ab)) es = 0;
        emitted.push_back(em);
        absorbed.push_back(ab);
        escaped.push_back(es);
        balance.push_back(em > 0 ? std::abs(em - ab - es) / em : 0.0);
    }
};

/// One stage of a run and its wall time.
struct Phase {
    std::string name;
    double time_s = 0;
};

struct SolveStats {
    double time_s = 0;
    /// The run's stages in order with their wall times, which add up to
    /// time_s but for bookkeeping between them. Hierarchical: "set-up"
    /// (hierarchy, connectivity, rooms), "tree" (nodes, tables), "self
    /// occlusion", then "refine 1", "solve 1", "refine 2", ... and "solve
    /// final" when the last solve is a separate one, and "result". Exact:
    /// "form factors", "solve", "result".
    std::vector<Phase> phases;
    double form_factor_time_s = 0;
    double linear_solve_time_s = 0;
    long elements = 0;
    long links = 0;          ///< non-zero element-pair form factors
    long iterations = 0;     ///< 0 for a direct solve
    long patches_left_out = 0;  ///< hierarchical: patches no emitter can reach (not solved; B = E = 0)
    long cluster_links = 0;     ///< hierarchical: links with a cluster at either end (part of `links`)
    long chain_links = 0;       ///< hierarchical: links between arcs of one convex loop, exact etendue, spread evenly (part of `links`)
    long independent_parts = 0; ///< hierarchical: sub-scenes no light passes between, solved apart
    long cluster_tables = 0;    ///< hierarchical: clusters with a directional model (solver/directional.h)
    long sampled_tables = 0;    ///< hierarchical: of those, the ones whose samples the final solve kept (the rest: linear part only)
    long unqueried_links = 0;   ///< hierarchical: links whose shaft may hold blockers, carried at the density's estimate of their transmittance, their visibility never asked (within eps whatever it is; part of `links`)
    long passes = 0;            ///< hierarchical: refine-solve rounds
    /// hierarchical: the last refinement round split no link, so every link
    /// is within eps; false when HierarchicalOptions::max_passes rounds ran
    /// out with links still splitting (the error may exceed what eps
    /// promises). Always true for the exact solver.
    bool refined_to_eps = true;
    long setups_kept = 0;       ///< hierarchical: solves that kept the last solve's set-up (no link changed in between)
    bool emission_first = false;  ///< hierarchical: the first round refined against the emission alone (else a closed room's guess)
    double residual = 0;     ///< max over channels of ||(I - rho F) B - E||_inf / ||E||_inf
    int threads = 1;
    VisibilityStats visibility;
};

struct Solution {
    std::string method;      ///< "exact" or "hierarchical"
    int subdivide = 1;
    double eps = 0, vis_eps = 0;
    int channels = 1;
    std::vector<PatchResult> patches;  ///< SPEC patch order
    Totals totals;
    SolveStats stats;
};

}  // namespace flatrad
