#pragma once
/// Hierarchical radiosity with clustering (DESIGN.md §3; Hanrahan, Salzman,
/// Aupperle 1991; Smits, Arvo, Greenberg 1994; Sillion 1995).
///
///  - One tree: the scene's cluster hierarchy (engine/hierarchy.h; leaves
///    below), under each leaf the two sides of each of its segments (a
///    patch, the root of a binary element tree, or a sink: an unlit side,
///    black, receive-only), elements split at their middle on demand.
///    Sinks that no patch can see get no node (solver/sink_visibility.h).
///    Leaves: one segment per hierarchy leaf serves visibility (queries
///    walk the hierarchy; a forest of 10^4 sticks with 8 per leaf made 4.4
///    times the links), so a segment that can block has a leaf of its
///    own. Segments that cannot (walls on the scene's hull,
///    engine/convex_scene.h) serve no query, and as small clusters they
///    only cost tables and nodes: they share leaves of up to 8 where links
///    are expected to stop well above the leaves (many walls, a loose eps:
///    HierarchicalOptions::unblocked_leaf_size). A round room of 10^6 walls
///    peaked at 2.6 GB with one per leaf, 1.3 GB with 8, for the same links
///    and solution to 5e-9 (this machine backs each run's fresh memory
///    afresh: 10.3 s from start to result against 7.3 s); with a lamp
///    inside, 3.4 GB and 16.7 s against 1.7 GB and 11.7 s (8.2 s once
///    links the lamp cannot reach ask nothing: clear_shaft_shortcut). But
///    a link that reaches a leaf splits into all its sides at once, so
///    where links go that deep wide leaves multiply them (1000 walls at
///    eps 3e-3: 30 615 links with one per leaf, 102 605 with 8).
///  - Links between any two nodes, created top-down: the root's self link
///    is split into its children's pairs and self links, and so on while a
///    cluster's members may exchange more than a share of the bar (a dark
///    cluster keeps its self link, carrying nothing: "Refinement oracle",
///    unresolved links); a link to a hierarchy leaf goes to its sides. A
///    link (receiver r, sender s):
///      element <- element: F_rs, the exact average over r, from
///        MultiscaleVisibility with --vis-eps (absolute on F; clusters are
///        approximated only in shafts of 512 blocker pieces or more, where
///        that is cheaper than the exact sweep: see the .cpp);
///      anything <- cluster, cluster <- element: point approximations at
///        the nodes' centres, times a transmittance from the visibility
///        module (MultiscaleVisibility::transmittance, --vis-eps on tau):
///        between two clusters' cross-sections, or between an element
///        itself and a cluster's (asked per element only when its patch's
///        shaft is partly blocked); a convex closed object's own segments
///        never count as blockers of its faces. Walls on the scene's hull
///        are never walked (engine/convex_scene.h), and a scene where no
///        segment can block calls visibility never;
///      nodes in different rooms (solver/rooms.h: a closed loop between
///        them) get no link.
///  - Directional model (solver/directional.h): a cluster's exitance
///    I(phi) = sum (B L / 2) cos+ and its irradiance arrivals J(psi) are
///    tables of 32 directions, read and written by linear interpolation; an
///    element under a cluster reads its cosine lobe from J. Each cluster
///    also has its sensitivity N(psi) = sum L cos+ (power received per unit
///    arrival density). Each table also holds its linear part, sum w n:
///    where every member of a cluster faces every point of the link's other
///    end (its normal cone, engine/normal_cone.h, against the corners of
///    the boxes along the segments, engine/oriented_box.h) the link reads
///    and writes that instead, exactly (a curved wall seen from along
///    itself); where none faces, the link is dropped.
///    Members hidden behind others of the same cluster (a forest's
///    clusters hold many layers of sticks): per table and direction, the
///    share of the members' lobes seen from outside the cluster
///    (solver/self_occlusion.h) scales its sensitivity, and level by level
///    what its children pull up into it and what it pushes down to them
///    (the same factor both ways: the operator keeps its adjoint). Such a
///    table's linear part is not read. Not where nothing can block, nor
///    for chains (arcs of a convex loop whose partners lie inside it).
///  - Refinement oracle: a link is split when its estimated error in
///    transported power exceeds eps_abs = eps x W / N (W the scene's exitant
///    power in the current solution, max over channels; N the patch count:
///    eps is RELATIVE, one link may misplace at most eps of an average
///    patch's power). Element links: as the first slice (kernel variation
///    over quarters, min(F, F_u - F) for a shadow boundary, the visibility
///    bound, the sender's unevenness). Cluster links: unoccluded power x
///    (point approximation 2 rho / d per clustered side, the tables'
///    interpolation error from their second differences, layers hidden
///    inside a cluster: sensitivity beyond the box's width, min(tau, 1 -
///    tau), the visibility bound; and where a table reads 0 at the centres'
///    direction, its highest value over the nodes' angular spread: a
///    grazing lobe; a linear read's own variation over the spread, to
///    second order; a cluster end whose box a blocker not its own, at
///    least as long as the box's diagonal, runs through for at least a
///    quarter of it, engine/box_intrusion.h: max(tau, 1 - tau) at a tenth
///    of the bar, as the cross-section's transmittance says nothing of
///    members on either side of that blocker); the side with the larger
///    share is split. A cluster
///    link's transmittance (an element link's occluded F) is asked only
///    when its geometric terms alone (which no visibility changes) do not
///    already exceed eps_abs: most links of an occluded scene are split on
///    geometry, and their queries were most of its time (a 1000-segment
///    forest: 59 s -> 20 s for cluster links, 18.6 -> 14.9 s more for
///    element links).
///    Overlapping nodes (d <= rho_r + rho_s, or an element whose line cuts
///    the cluster's box) carry nothing, and are split when what they may
///    leave out, B_max(s) min(L(s), L(r)) (the sender's highest leaf value,
///    the total length below either end), exceeds a thousandth of eps_abs
///    (unresolved_share in the .cpp: a one-signed loss): a forest's dark
///    part, lit at 1e-15 by the first solve, is no longer split down to its
///    segments (the 10^4 forest at eps 10: 60 785 links instead of 112 389,
///    the same error and balance). Except chain links: two arcs of one
///    convex loop lit on the room's side (neighbours along a curved wall)
///    whose hull no segment meets (in
///    rooms holding at most 64 segments that may block) exchange their
///    exact etendue (crossed strings on their chords; an arc with itself:
///    its length minus its chord), the sender's mean spread evenly on the
///    receiver, with the power they carry at the sender's highest value as
///    their error (stats.chain_links). Along a wall of N segments turning
///    by 2 pi / N each, arcs of n walls exchange ~n^3 (2 pi / N)^2 / 8 of a
///    wall's power, so at 10^6 walls and eps 3e-3 arcs of ~800 walls need
///    no finer links: a round room of 10^6 walls kept 8.8 M links without
///    them, 2.6 M with (the same error against exact on 1000 and 4000
///    walls, to 3 digits). The first round refines against a guess, then
///    refine, solve, refine until no link splits (at most max_passes
///    rounds; stats.passes). The guess, where nothing can block: every
///    patch at E + rho B_bar, B_bar the radiosity of a closed room with the
///    scene's emission and absorption (every patch that faces an emitter
///    sees it). Where blockers make at least 4 layers of shadow across the
///    scene (its density, MultiscaleVisibility::layers_per_depth, times
///    the root box's longer side), the emission alone (B = E), so
///    that light is paid for only where the solution puts it: the guess
///    put a 10^4-segment forest's every stick at 0.008, above the
///    radiosity that 18 000 of its 20 000 patches end with, and refinement
///    only splits. (eps_abs of that first round is the closed room's:
///    the emission alone would make it too fine near the emitters.)
///    stats.first_round says which start was taken. Either way a room
///    (solver/rooms.h) that holds no emitting side starts at 0: no light
///    can reach it, and its links are not refined for light it will never
///    get (a sealed box in a lit room was cut into 10 elements a side).
///  - Deferred visibility: a link's visibility is asked only when the link
///    survives its geometry and its error with the transmittance unknown
///    (an estimate tau_est, any truth in [0, 1]: a bound of max(tau_est,
///    1 - tau_est)) exceeds a tenth of eps_abs (deferred_share in the
///    .cpp: these estimates err the same way on every link of a scene, so
///    their errors add up); until then it carries tau_est, the
///    transmittance of blockers spread at the scene's mean density over
///    the gap between its nodes, exp(-kappa g) (kappa: layers of shadow
///    per unit of depth, MultiscaleVisibility::layers_per_depth), with a
///    cluster's box counting the blockers in it that are not its members. A
///    sender too dim for any transmittance to matter is never queried;
///    later rounds ask again against the new solution. With vis_eps 0
///    (exact visibility asked for) nothing is deferred: every link that
///    survives its geometry asks the visibility module.
///    stats.unqueried_links counts the links the final solve carried so.
///  - Closure screens (visibility/closure_screen.h): in a dense scene a
///    bright element's links to clusters many layers of shadow away are
///    nearly all closed, and each once cost its own proof. Now an element
///    has, per direction bin, one screen beyond the depth from which a
///    shaft is long (MultiscaleVisibility::long_shaft_depth), proven closed
///    once from the slabs near the element (shown_closed); a link from it
///    (to a cluster, or to an element: either end's screen) whose target
///    lies wholly behind a closed screen that every line to it crosses is
///    closed, exactly, with no query of its own. Made on first use, one
///    per element and bin, so the answer depends only on the link, not on
///    which thread asked first. stats.visibility.screens counts the screens
///    shown closed, .screened the links they answered.
///  - Whole-box closure (visibility/box_closure.h): a pending link with a
///    cluster at one end whose geometry alone asks for a split, and whose
///    density's estimate of the transmittance is tiny, is first tried with
///    one proof that every line between its ends' boxes is blocked (one
///    slab proof per pair of facing box sides, the ends' own segments left
///    out); shown so, the link is dropped whole, exactly, where its pieces
///    would each have been split and asked. A lamp's links to a forest
///    hundreds of layers deep were split on their geometry down to clusters
///    of a few sticks, each then shown closed on its own. The proof may
///    also leave free lines whose bound (the proof's bands) carries at most
///    a tenth of the bar (box_proof_share): the link is dropped with that
///    error, as a deferred link keeps its own.
///    stats.visibility.boxed counts the links dropped so.
///  - Solve: per channel, the matrix-free operator on the element leaves:
///    pull (means up the element trees, exitance tables up the clusters),
///    gather along the links (in parallel over receivers), push (tables
///    down the clusters, cosine lobes onto the sides, irradiance down the
///    elements); (I - rho G) B = E by restarted GMRES (solver/gmres.h) to
///    1e-12, the solves between refinement rounds (which only feed the
///    next round's error estimates) to 1e-3 (1 - rho_max) and the last
///    one on from there. Independent sub-scenes (solver/light_parts.h: no link and no
///    shared linked ancestor between them) are solved apart, each with its
///    own Krylov run on its own nodes; stats.independent_parts counts them,
///    stats.iterations the longest run's operator applications. The
///    residual is then checked on the whole operator.
///  - Row sums: a leaf whose light cannot leave the scene
///    (engine/connectivity.h) and that sees only link senders must gather
///    exactly 1 for B = 1 everywhere; its deficit (the refinement error of
///    its ancestors' links, amplified 1 / (1 - rho) in a white furnace) is
///    added in proportion to what its ancestors' links bring. Sides that
///    send nothing (visible sinks, patches that neither reflect nor emit)
///    keep the rows that may see them open, unless a closed loop keeps them
///    apart, or a stiff row (reflectance >= 0.95) may see them: then they
///    are made senders that carry 0 (a sink becomes an element of a patch
///    of its own, not in the result), their links count in the rows, and
///    the refinement takes their leaves at the scene's mean leaf value
///    (refinement_values; solver/closed_rows.h).
///  - Pay for what is used: light-flow reachability over the links
///    (solver/reachability.h, Boost.Graph BFS): links whose sender no
///    emitter's light reaches are dropped, patches none of whose leaves is
///    reached are counted in stats.patches_left_out; a scene that emits
///    nothing gets no links; one-channel scenes carry one channel.
///  - Totals: absorbed = sum over leaves of L (1 - rho) H plus what sinks
///    gather. Escaped: what the links do not deliver (the adjoint of pull
///    and gather gives each leaf's delivered fraction) of the power sent by
///    patches whose light can leave the scene. What escape-free patches
///    lose is the transport's own energy error: balance = |emitted -
///    absorbed - escaped| / emitted measures it (in a scene with no
///    escape-free patch, balance only checks the linear solve).
///    Measured on data/default.json: 2.3e-3 at eps 1e-2, 1.2e-3 at 3e-3,
///    4.2e-4 at 1e-3, 7.5e-5 at 1e-4, 3.7e-5 at 3e-5.
///  - Refuses (InputError) a closed set of reflectance-1 patches without
///    absorber, as solve_exact does.
#include <functional>
#include <string>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

struct HierarchicalOptions {
    double eps = 3e-3;       ///< relative refinement tolerance (see above), > 0; 3e-3: 0.06-0.2% L2 error on the data scenes, 0.1: 0.4-1.2%
    double vis_eps = -1;     ///< absolute tolerance on F for visibility; < 0: eps / 10; 0: exact, no link deferred
    int max_depth = 12;      ///< deepest element level (a patch is level 0)
    int max_passes = 16;     ///< refine-solve rounds at most (from the emission alone, light takes a round or two per bounce that matters)
    int threads = 0;         ///< 0: all cores
    /// Solve independent sub-scenes apart (solver/light_parts.h); off: one
    /// Krylov run over everything (the same solution, for tests).
    bool solve_parts_apart = true;
    /// A closed convex room whose patches all reflect or emit is one part
    /// with every patch reached, without the light-flow check (proof in
    /// solve()); off: checked like any scene (the same solution, for tests).
    bool convex_room_shortcut = true;
    /// Chain links: two arcs of one convex loop too close for the point
    /// approximation exchange their exact etendue, spread evenly, while that
    /// is within eps (see above); off: refined like any other pair (the same
    /// accuracy with more links, for tests).
    bool chain_links = true;
    /// Where blockers make 4 layers of shadow or more across the scene, the
    /// first refinement is against the emission alone (see above); off:
    /// against the closed-room guess everywhere (more links and queries in
    /// forests, for tests).
    bool emission_first = true;
    /// Deferred visibility (see above); off: every link that survives its
    /// geometry asks the visibility module (for tests: the oracle).
    bool defer_visibility = true;
    /// Closure screens (visibility/closure_screen.h): an element's links to
    /// clusters far across a dense scene are first checked against screens
    /// of that element shown closed once, each serving every target behind
    /// it (see "Closure screens" above); off: every such link asks its own
    /// query (for tests: the oracle).
    bool closure_screens = true;
    /// Whole-box closure (visibility/box_closure.h): a link with a cluster
    /// at one end, nearly surely closed by the density's estimate, is tried
    /// with one proof that every line between its ends is blocked before it
    /// is split on its geometry, and dropped whole when shown so; off: split
    /// and its pieces asked one by one (for tests: the oracle).
    bool box_closure = true;
    /// Solves between refinement rounds stop at a looser residual (see
    /// "Solve" above); off: every solve to the full 1e-12 (for tests: the
    /// same links whichever way the operator is split into parts, as the
    /// loose solves of parts apart and together stop at different points).
    bool loose_intermediate_solves = true;
    /// Links between overlapping nodes whose sender is faint, and a faint
    /// cluster's self link, stay unsplit, carrying nothing, while what they
    /// may leave out is within a share of the bar (see above); off: split
    /// whenever the sender sends anything, self links always (for tests:
    /// the oracle).
    bool faint_overlaps_kept = true;
    /// In scenes with at most 64 segments that may block, a link whose
    /// shaft none of them can reach (checked one by one against a capsule
    /// around the link) takes the unoccluded exchange without asking the
    /// visibility module, which would find the shaft empty (the same
    /// answer); off: every such link asks (for tests: the oracle).
    bool clear_shaft_shortcut = true;
    /// A solve after a refinement that changed no link (the final one,
    /// after a round that splits nothing) keeps the last solve's set-up:
    /// its leaves, receivers sorted, row sums and parts
    /// (stats.setups_kept); off: every solve sets up anew (for tests: the
    /// oracle, bit for bit).
    bool keep_unchanged_setup = true;
    /// Rooms holding no emitting side start the first round at 0 (see "The
    /// first round" above); off: at the closed room's guess like every
    /// other (for tests: the oracle).
    bool dark_rooms_start_dark = true;
    /// The links r <- s and s <- r between two elements share one
    /// visibility query (the shorter element its receiver, the other way's
    /// answer by reciprocity, L_r F_rs = L_s F_sr); off: each link asks its
    /// own (for tests: the oracle).
    bool share_element_pairs = true;
    /// Segments that cannot block (on the scene's hull: engine/
    /// convex_scene.h) may share the cluster hierarchy's leaves ("Leaves"
    /// above): up to this many (>= 1), or with 0 (the default) 8 where
    /// links are expected to stop far above the leaves (many walls, loose
    /// eps: the .cpp's leaf_size), else 1. A segment that can block always
    /// has a leaf of its own.
    int unblocked_leaf_size = 0;
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
