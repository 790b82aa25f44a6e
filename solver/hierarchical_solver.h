#pragma once
/// Hierarchical radiosity WITHOUT clustering (Hanrahan, Salzman, Aupperle,
/// "A rapid hierarchical radiosity algorithm", SIGGRAPH 1991; DESIGN.md §3):
/// a first slice of the solver DESIGN §3 describes. Clustering (links above
/// the patches) and directional cluster models are not done yet.
///
///  - Elements: each patch is the root of a binary tree of elements, a node
///    split at the middle of its parameter. Unlit sides of segments (sinks:
///    black, SPEC) get receive-only trees of their own, so that the power
///    they absorb is gathered like any other.
///  - Links: initially one per ordered pair of patches (and patch -> sink)
///    that can see each other's lit side (clip_to_lit_halfplanes). A link
///    (receiver r, sender s) carries F_rs from MultiscaleVisibility
///    (GammaRule::Bound, tolerance vis_eps on F; an empty shaft costs only
///    crossed strings, counted in stats.visibility.unoccluded), the element's
///    parent segment numbers skipped as blockers.
///  - Refinement oracle: a link is split when its estimated error in
///    transported power exceeds eps_abs (below); the side split is the
///    longer one (the other when that one is at max_depth). The estimate is
///      err = B_s * L_r * (kernel + occlusion + visibility),
///    (no reflectance factor: of what r receives, rho goes into B_r and
///    1 - rho into the absorbed totals, so an error matters either way;
///    weighting by rho left a black lamp's links coarse and lost 2.5% of
///    the absorbed power of data/default.json), B_s = the sender's largest
///    channel in the current solution (the initial patch-to-patch links are
///    solved first, so no a-priori bound on B is needed), and
///      kernel     = variation of the unoccluded F over quarters of r and of
///                   s (mean |F(r_k -> s) - F(r -> s)| and
///                   sum |F(r -> s_k) - F(r -> s) / 4|): catches ends-vs-
///                   middle variation that halves miss by symmetry;
///      occlusion  = min(F, F_unoccluded - F): a partly hidden sender may put
///                   a shadow boundary anywhere on the link;
///      visibility = the multiscale error bound on F;
///    plus L_r F_rs |B_s0 - B_s1| / 2 when the sender already has children
///    s0, s1 (split by other links): the link spreads the sender's mean.
///  - eps is RELATIVE: eps_abs = eps * W / N, W = sum over patches of
///    L_p * max-channel B_p (the scene's exitant power, current solution)
///    and N the number of patches: one link may misplace at most the
///    fraction eps of an average patch's exitant power. Refine, solve and
///    refine again until no link splits (at most max_passes passes).
///  - Solve: matrix-free operator on the leaf radiosities, per channel:
///    pull (length-weighted B up the trees), gather (each node collects
///    sum over its links F * B_sender), push (irradiance down to the leaves),
///    B = E + rho * H; the system (I - rho G) B = E is solved by restarted
///    GMRES (Saad & Schultz 1986) to a relative residual of 1e-12.
///    stats.iterations counts operator applications over all channels.
///  - Row sums: links at different levels make a leaf's sum of F over its
///    own and its ancestors' links differ from the true value by the
///    refinement error, and 1 / (1 - rho) amplifies that (1000x in a white
///    furnace at 0.999). For a patch whose root links to lit patches sum to
///    1 (within the visibility bounds + 1e-9) and that sees no sink, the true
///    row sum is 1 at every point. A leaf's own links are exact averages
///    over it; the error is in its ancestors' links, mostly in those whose
///    F varies over the receiver (near neighbours, shadows). So a leaf gets
///    its deficit d = 1 - (sum of F over its own and ancestors' links)
///    times the mean radiosity of its ancestors' senders weighted by each
///    link's receiver-side variation w = L_r (kernel + occlusion). (Scaling
///    the whole row, or all ancestor links evenly, puts the deficit on a
///    bright lamp: measured 5x worse on a shadowed box.) Other patches
///    (seeing a sink or an opening) are left as they are; as eps -> 0,
///    d -> 0.
///  - Pay for what is used: a scene that emits nothing gets no links (B = 0);
///    one-channel scenes carry one channel; an empty shaft costs crossed
///    strings only. Not done yet: skipping surfaces no emitter reaches.
///  - Refuses (InputError) a closed set of reflectance-1 patches without
///    absorber, as solve_exact does (checked with exact patch form factors,
///    only when some reflectance is 1).
///  - Totals: absorbed = sum over leaves of L (1 - rho) H plus the power
///    gathered by sinks; escaped = power sent minus power landing through
///    links (the links of a fully refined tree cover each pair of leaves
///    once), so balance measures the linear solve only. The real energy
///    error shows as `escaped` in a closed scene (the links spread a
///    sender's mean B, not its leaves' values): 1e-3 of the emitted power
///    on data/default.json at eps = 1e-3, 9e-3 at eps = 1e-2.
#include <functional>
#include <string>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

struct HierarchicalOptions {
    double eps = 3e-3;       ///< relative refinement tolerance (see above), > 0; 3e-3: ~1% error
    double vis_eps = -1;     ///< absolute tolerance on F for visibility; < 0: eps / 10
    int max_depth = 12;      ///< deepest element level (a patch is level 0)
    int max_passes = 8;      ///< refine-solve rounds at most
    int threads = 0;         ///< 0: all cores
    /// Called now and then from the solving thread with what is being done
    /// ("refine pass 2", "solve", ...) and a fraction in [0, 1] of the whole
    /// run when one is known (< 0 otherwise). Empty: no reports. The CLI
    /// draws it on stderr when that is a terminal (--quiet silences it).
    std::function<void(const std::string& stage, double fraction)> progress;
};

/// Solves `scene` hierarchically. Throws InputError for eps <= 0 or not
/// finite, max_depth < 0, and for a closed reflectance-1 enclosure.
Solution solve_hierarchical(const Scene& scene, const HierarchicalOptions& options = {});

}  // namespace flatrad
