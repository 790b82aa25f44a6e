#include "solver/hierarchical_solver.h"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <shared_mutex>
#include <unordered_map>
#include <fmt/format.h>

#include "engine/box_intrusion.h"
#include "engine/compensated_sum.h"
#include "engine/connectivity.h"
#include "engine/convex_scene.h"
#include "engine/error.h"
#include "engine/formfactor.h"
#include "engine/hierarchy.h"
#include "engine/normal_cone.h"
#include "engine/oriented_box.h"
#include "solver/closed_enclosure.h"
#include "solver/directional.h"
#include "solver/gmres.h"
#include "solver/light_parts.h"
#include "solver/reachability.h"
#include "solver/rooms.h"
#include "solver/front_envelopes.h"
#include "solver/self_occlusion.h"
#include "solver/closed_rows.h"
#include "solver/sink_visibility.h"
#include "solver/table_array.h"
#include "solver/uninitialized_allocator.h"
#include "visibility/closure_screen.h"
#include "visibility/cluster_tables.h"
#include "visibility/exact_visibility.h"
#include "visibility/multiscale.h"

namespace flatrad {

namespace {

constexpr int K = directional_bins;
constexpr int TW = directional_table_width;  // samples, then the linear part

// Below this many links (each maybe a visibility query, up to ~1 ms: the
// refinement's decisions) a batch runs on one thread; geometry and gathers
// (~1 us each) need 16x more.
constexpr long parallel_min_work = 64;
// The operator's passes over the node tree (pull_tables, push_down) run on
// several threads from this many nodes on (OpSchedule): disjoint subtrees
// side by side, the few nodes above them on one thread. Measured with two
// threads against one for these passes (the solves' time, medians of 5, 3
// alternating runs each): a round room of 10^4 walls at eps 3e-3 19-21 ms
// against 30-31 ms; the 10^4 forest at eps 10 135-150 against 147-169 ms;
// the 10^5 forest 2.75 / 3.10 s against 3.01 / 3.82 s (one run each); the
// 1000-segment forest (4000 nodes) at eps 5 within the noise (8-13 ms);
// a round room of 10^5 walls the same (0.21 s: its solves are not in these
// passes). From 2048 nodes to 8192 (thirtieth session): that forest at eps
// 12, a pass of 0.07 ms split over two threads costs more in waking the
// second one than it saves (the solves 14-15 ms on one thread, 18-25 ms
// on two, phase timers; `flatrad_bench versus --eps-list 12 --repeat 15`
// twice, alternating: 0.054 / 0.059 s against 0.061 / 0.067 s).
constexpr size_t op_parallel_min_nodes = 8192;
// The gather runs on both cores only above this many links: below, one
// gather is tens of microseconds, of the order of waking the other thread
// (2 cores, medians of 10 / 5 runs, GMRES time: the 1000-segment forest at
// eps 5, 12 625 links, 0.0228 s in parallel against 0.0162 s serial; round
// rooms of 10^4 / 10^5 walls, 139 313 / 560 436 links, 0.0190 / 0.192 s in
// parallel against 0.0235 / 0.223 s serial).
constexpr size_t gather_min_links = 32768;
// Chain links are made in rooms holding at most this many segments that
// may block, each checked against each chain link (chain_clear).
constexpr long max_chain_blockers = 64;
// An element pair's answer is kept for the other way (element_exchange)
// when its shaft held at least this many blocker pieces, or when bands,
// bounds or sub-shafts answered it: below, a query takes a few
// microseconds, about what keeping and finding it costs.
constexpr long shared_pair_work = 16;

// Multi-scale visibility approximates clusters only in shafts holding at
// least this many blocker pieces: below it, the criterion's set-up and the
// direction integral cost more than the exact sweep they would replace.
// Measured (eps 0.5, the 1000-segment forest of `scripts/bench versus`):
// approximating wherever the criterion allowed took 16.3 s, from 32 pieces
// on 15.9 s, from 128 on 13.7 s, from 512 on 8.8 s, and exact visibility
// everywhere (--vis-eps 0) 8.5 s; on data/forest.json (3005 segments, the
// default eps) 274 s against 193 s exact. The exact sweep grows as the
// square of the pieces (1000 pieces: 0.2 s a query, `scripts/bench
// ffcost`), so very crowded shafts are left to the approximation.
constexpr size_t min_pieces_to_approximate = 512;
// Shafts of at least this many pieces are first tried with direction
// bounds (visibility/direction_bounds.h), which replace the exact integral
// there when they close within the visibility tolerance: the 1000-segment
// forest at 1% error in 0.40 s instead of 5.35 s (measurements of the
// choice in visibility/multiscale.cpp).
constexpr size_t min_pieces_to_bound = 32;
// The same for loose queries (visibility/multiscale.cpp, loose_tolerance),
// which start from fewer bins and come with an estimate within the bounds:
// on the 1000-segment forest, 1% error in 20% less time (figures there).
constexpr size_t min_pieces_to_bound_loose = 8;
// The same shafts are first tried with a proof that a band of their pieces
// closes them (visibility/opaque_band.h): an exact 0 where the bounds'
// midpoint would claim up to the tolerance. In a forest the many nearly
// opaque links each carried that bias, and it added up: the 10^4-segment
// forest at eps 1 absorbed 12% more than it emitted, now 0.2%, in the same
// time (10.9 s against 11.1 s) with 20% fewer links; at eps 0.1 18% faster
// (the 1000-segment forest: 1.4% more instructions, relative L2 8.94e-3
// -> 8.77e-3 at eps 4; tenth session's figures in the README). Since the
// eleventh session the bands also bound open shafts within the tolerance,
// and a long shaft is walked first only where its bands are (multiscale.h):
// the 10^4 forest 11.2 -> 8.8 s at eps 1, the 10^5 forest 102 -> 65 s at
// eps 10 (README).
constexpr size_t min_pieces_to_prove_closed = 32;

// Closure screens (visibility/closure_screen.h, behind_closure_screen): an
// element's screens lie in closure_screen_bins directions (absolute angles,
// bins of 1.875 degrees), the farthest at 1.05 times the depth from which
// a shaft is long (MultiscaleVisibility::long_shaft_depth: the proof then
// walks only the slabs near the element), each reaching
// closure_screen_spread times its depth to each side (the bin's half-width
// is 0.016 of it; the rest is room for the targets' own width and the
// element's). One screen per element and bin, asked for by the first target
// behind it and shown closed or not once: the answer for a target depends
// only on the element and the target, not on which thread asked first.
// Since the nineteenth session a bin has screens at several depths
// (closure_screen_depths, farthest first; the nearer ones' proofs use
// thinner slabs, multiscale.cpp's screen_min_slab_layers): a target too
// near for the far screen, or behind a far screen not shown closed, tries
// the next. On the 10^4 forest at eps 10 (one thread, callgrind) 12.37 G
// instructions with the one depth, 11.43 G with 1.05 / 0.7 / 0.47, 11.36 G
// with 0.37 as well (kept), 11.41 G with 1.05 / 0.84 / 0.63 / 0.47 / 0.37;
// at eps 1 31.2 G against 26.6 G; nearest first about the same (11.34 G).
// Measured on the 10^5 forest at eps 10 (`scripts/make-scene 100000 --seed
// 1 --density 30`; cluster visits, slab proofs and links answered by
// screens, one run each): none 359 M / 211 007 / 0; 16 bins, 0.41 (wide
// screens) 359 M / 211 007 / 0 (no screen shown closed: across a wide
// section a band nearly always leaves a gap); 64, 0.1 345 M / 192 444 / 18 859
// (element-to-cluster links only); then with element links too: 64, 0.05
// 328 M / 172 310 / 39 218; 128, 0.035 317 M; 128, 0.05 308 M / 147 966 /
// 64 056; 128, 0.08 332 M; 192, 0.04 303 M / 142 318 / 70 172; 192, 0.05
// 310 M; 256, 0.025 320 M; 256, 0.035 303 M. Proving the screens took
// about 0.4 s of the run's ~40 thread-seconds of visibility (128, 0.05).
// Tried and not kept: covering only the stand-ins a query would use (not
// the square around the target's circle) and asking the skipped segments
// only to lie behind the screen. At 10^5 the same cluster visits (304 M)
// from 13 000 screens instead of 1 500; at 10^6 2.0 million screens for
// 2.9 million links answered (each proven about once per use, dearer than
// the query it replaced): 700 s against 636 s with this rule (8 200
// screens answering 814 000 links).
constexpr int closure_screen_bins = 192;
constexpr std::array<double, 4> closure_screen_depths = {1.05, 0.7, 0.47, 0.37};
constexpr double closure_screen_spread = 0.04;

// Whole-box closure (visibility/box_closure.h, shown_closed_whole): a
// pending link with a cluster at one end at least, about to be split on its
// geometry, whose density's estimate of the transmittance is at most
// box_proof_below, is first tried with one proof that every line between
// its ends is blocked; shown so, it is dropped whole, exactly, instead of
// being split into pieces that are each asked (and found closed). A proof
// that leaves a gap is wasted (the link is split as before), and its
// shafts' slabs cost about a query each. The 10^6 forest at eps 10 (one
// run each): 6.76 M queries without, 2.25 M with the bar at 1e-6 (217 601
// links dropped whole), 2.30 M at 1e-10 (204 120), the same solution
// within 5e-7 relative L2. The 10^4 forest at eps 10 (one thread,
// callgrind): 10.32 G instructions without, 10.79 / 10.39 / 10.31 G at
// 1e-6 / 1e-10 / 1e-15 (736 / 295 / 6 links dropped whole): there the
// proofs mostly replace closure screens' answers, which cost less.
constexpr double box_proof_below = 1e-10;
// Such a proof may also leave free lines whose exchange, bounded by its
// bands (box_closure.h), carries at most this share of the bar (the
// deferred links' share, deferred_share, below): the link is dropped, and
// what it leaves out is within that bound. The proofs' narrow gaps (the
// drift of pieces within a bin, or a sliver of lines past a band's end)
// then no longer fail a proof and split the link into pieces, each proven
// again. On the 10^6 forest at eps 10 (two pairs of runs, interleaved):
// the form factors 31.1 / 31.9 -> 24.7 / 24.4 s, the solve 56.9 / 58.7 ->
// 49.2 / 49.8 s (with counters: the third round 15.1 -> 9.4 s, its box
// proofs of wall elements tens of units long to clusters 50-200 away
// 23 500 -> 14 400, 18.0 -> 9.9 thread-s); the solution within 9.7e-7
// relative L2 of the exact proofs', balance 1.37500e-2 (exact proofs:
// 1.37496e-2). With share 1e-3 (unresolved_share): the same solution to
// 1e-15, form factors 29.3 s against 30.6 s; with share 1, 23.96 s against
// 23.91 s at 0.1, the solution 1.4e-5 from the exact proofs'.
constexpr double box_proof_share = 0.1;
// A link not shown closed whole (its proof left a gap, or none was
// tried: two elements, or box_closure off) is split on its larger end, not on
// the end with the larger geometric error: through a dense forest that is
// a cluster's layered term (its members hiding each other), which split
// the receivers while a ceiling element 20-45 units long stayed whole, and
// every cluster of about a unit across anywhere in the room ended with its
// own link to it, each a query of a wide shaft (on the 10^6 forest at eps
// 10, 292 000 such queries, 58 of the run's 95 thread-seconds of queries).
// Split by size, the shafts narrow, and proofs close higher up the tree:
// the 10^6 forest's solve 151 -> 106 s (one run each, the same hour;
// 4.34 -> 3.21 G cluster visits), the 10^5 forest's form factors 8.4 ->
// 4.9 s; the solutions within 2.8e-3 / 4.7e-4 relative L2 of each other;
// the 10^4 forest 680 -> 645 ms (medians of 3, in-process, interleaved),
// the same error against eps 1 (6.72e-3); no data scene changes.

// GMRES stops at ||E - (I - rho G) B|| <= 1e-12 ||E||: the operator is
// applied in double with sums of at most a few thousand terms per node, so
// 1e-12 is reachable and keeps B to ~1e-9 relative even where
// 1 / (1 - rho) = 1000 (white furnace 0.999).
constexpr double gmres_tolerance = 1e-12;

// The solves between refinement rounds only feed the next round's error
// estimates (leaf values, and eps_abs from their power), which decide
// against the bar with a 3% hysteresis (split_margin). They stop at
// intermediate_accuracy (1 - rho_max) relative residual: with row sums
// at most 1, ||B - B*|| <= ||r|| / (1 - rho_max), so the values are known
// to about 1e-3, far inside that margin. The last solve, once a round
// splits nothing, goes on from there to gmres_tolerance (solve's warm
// start). On the 1000-segment forest of `scripts/bench versus` at eps 5:
// 29 operator applications in four solves instead of 49 in three (13 + 19
// + 17), the solves' instructions 138 M instead of 200 M (callgrind, one
// thread; 6.5% of the run), the same links to 4 in 12 900.
constexpr double intermediate_accuracy = 1e-3;

// Refinement hysteresis (refine): after the first solve, a round that
// splits splits every link above this share of eps_abs. Measured on round
// rooms of 10^6 walls: at 1 (none) 8.69M links in three solves, 16.2 s;
// at 0.97 8.77M links in two, 15.7 s; at 0.9 9.00M in two, 16.1 s.
constexpr double split_margin = 0.97;

// Deferred visibility (refine): a link whose error with its transmittance
// unknown is within this share of the bar carries the density's estimate
// (prior_transmittance) and asks nothing. A share, not the whole bar: that
// estimate errs the same way for every link of a scene (too open or too
// closed for its blockers), so the deferred links' errors add up where
// other errors partly cancel. On the 1000-segment forest of `scripts/bench
// versus` (medians of 3): at share 1 eps 5 gave a relative L2 error of
// 1.36e-2 and a balance of 6.4e-2 in 0.090 s, 0.3 9.4e-3 and 1.5e-2 in
// 0.104 s, 0.1 9.4e-3 and 5.2e-4 in 0.114 s; 1% error cost about the same
// at each (0.108 s at eps 3 for share 1). Without deferral 0.158 s.
constexpr double deferred_share = 0.1;

// Links between overlapping or touching nodes (Link::unresolved) have no
// point approximation: they carry nothing until split. What they leave out
// is at most all the sender's power that can reach the receiver, B_max(s)
// min(L(s), L(r)) with B_max the highest leaf value below and L the total
// length of the leaves below (an irradiance from s is at most B_max(s)
// anywhere; link_error). Such a link is split only when that bound exceeds
// this share of the bar: the light it leaves out is one-signed, a loss that
// adds up over links. Until the twenty-fifth session it was split whenever
// its sender sent anything at all (HierarchicalOptions::faint_overlaps_kept
// off), so the first solve's faint light (1e-15) split every link between
// neighbouring clusters down to their segments, all over a forest's dark
// part. With it, the 10^4 forest at eps 10 keeps 60 785 links instead of
// 112 389 (share 0.1: 43 031, 0.01: 51 081), the same relative L2 against
// eps 0.5 (7.08e-3) and balance (6.83e-3 against 6.78e-3; share 0.1: 9.2e-3,
// 0.01: 7.2e-3); the 1000-segment forest at eps 10 11 152 links instead of
// 12 476, balance 3.4e-3 against 3.2e-3 (share 0.1: 6 049 and 1.6e-2).
constexpr double unresolved_share = 1e-3;

// A cluster end whose box a long blocker not its own runs through
// (engine/box_intrusion.h): the transmittance to its cross-section says
// nothing of its members, which lie on either side of that blocker, so the
// link's transmittance may be anywhere in [0, 1] for them (link_error
// counts max(tau, 1 - tau) of its unoccluded power, on that end). A share
// of the bar, as for deferred links: the error has one sign on every link
// to that end (a blocker between the box's centre and the members that
// face the link hides them from every sender at once). A small
// shelf-and-book scene (docs/solver-history.md, "Forty-fourth session") at
// the default eps: the shelf's end face at 0.49 for 1.41 before; 1.39 with
// this, 1.16 with a share of 0.3, 0.99 with the whole bar (its ~30 links
// each under the bar, all too dark).
constexpr double intruded_box_share = 0.1;

// Which blockers intrude (box_intruded): at least as long as the box's
// diagonal, and through at least a quarter of it. One of the members' own
// scale is scattered among them as they are (a forest's sticks), which the
// cross-section's mean stands for; one longer runs through the box like a
// wall. Counting every blocker that cut a box in two cost the 10^4 forest
// at eps 10 7.6% more instructions (its queries through the split
// clusters' crowded shafts) for no change in its error; with the length,
// the forests' links are what they were (10^5: one more). Cuts alone
// missed a shelf's top ending inside the box (a piece straddling the
// shelf's end: its top at 0.56 for 2.14); any chord through the interior
// at all moved the 10^5 forest by 5.8e-4 (80 more links) for nothing
// measured; from a quarter of the diagonal, the straddling piece's top is
// 2.08 and the forests are as before.
constexpr double intruder_min_chord = 0.25;

// The first refinement is against the emission alone (run) where the scene
// holds at least this many layers of shadow across (its density times the
// root box's longer side): a line across it then meets a blocker with
// probability 1 - e^-4 = 98%, so most patches see little of the emitters
// and the closed room's guess would refine them as if lit. Below, the
// guess is near the truth and starting from the emission costs a round: a
// round room of 1000 walls with a lamp inside (0.13 layers) took 0.74 s
// instead of 0.34 s. The data scenes: default.json 1.9 layers,
// stiff_room 1.7, tube_bank 6.0, furnished_room 9.1 (7.4 -> 5.1 s at eps
// 1e-5), the forests of `scripts/make-scene N --density 30` 11 (10^3) to
// 35 (10^4).
constexpr double emission_first_layers = 4;

// The bound of an element link's kernel variation
// (HierarchicalSolver::kernel_variation): each |F_q - F / 4| <= F_q + F / 4,
// and the quarters' F_q sum to F (the same F from r; by reciprocity, 4 F
// over r's quarters), so both sums are at most 2 F
// (tests/engine/formfactor_test.cpp checks it). The margin covers the
// rounding of the crossed strings (1e-15 relative) with room to spare.
double kernel_variation_bound(double Fu) { return 2 * Fu * (1 + 1e-6); }

enum class Kind : uint8_t {
    Cluster,  // a node of the scene's cluster hierarchy
    Element,  // a patch (lit side of a segment) or a piece of one
    Sink,     // an unlit side: black, receives only (SPEC)
};

// What refinement reads of both ends of every link (kind, depth, table,
// hierarchy node, centre, radius, length) comes first, and a node starts
// on a cache line: one line per end instead of up to three (nodes are read
// at random, 3 million of them at 10^6 walls).
struct alignas(64) Node {
    Kind kind = Kind::Cluster;
    bool leaf_cluster = false;  // a hierarchy leaf: its children are its segments' sides
    bool can_send = false;      // some patch below reflects or emits
    // An arc of one convex loop (mark_chains): an element lit on the room's
    // side of a convex loop's wall, or a cluster whose sides are all such
    // elements, of contiguous walls of one loop (its length is then theirs).
    bool chain = false;
    int16_t depth = 0;          // elements: level below the patch
    int32_t table = -1;         // clusters: index of the directional tables
    int32_t hnode = -1;         // hierarchy node (clusters; elements: their segment's leaf)
    int32_t child = -1;         // first child; children are contiguous
    int32_t parent = -1;
    Vec2 center;
    double radius = 0;          // half the box diagonal (clusters), half the length (elements)
    double length = 0;          // elements and sinks
    int32_t nchild = 0;
    int32_t patch = -1;         // elements
    int32_t segment = -1;       // elements and sinks
    uint64_t send_rooms = 0;    // rooms its light can leave into (solver/rooms.h)
    uint64_t recv_rooms = 0;    // rooms it can receive from
    Segment seg;                // elements and sinks: oriented, lit (or receiving) side on the left
    Vec2 normal;                // elements and sinks: unit normal of that side
    double s0 = 0, s1 = 1;      // elements: parameter range along the oriented patch
    // Clusters: the normals of the elements that can send, and of every
    // side (elements and sinks: what receives), engine/normal_cone.h.
    NormalCone send_cone, recv_cone;
    bool cluster() const { return kind == Kind::Cluster; }
    bool sink() const { return kind == Kind::Sink; }
};
// A node's size for choosing which end of a link to split: a cluster's box
// diagonal, an element's length.
double size_of(const Node& n) { return n.cluster() ? 2 * n.radius : n.length; }
static_assert(offsetof(Node, length) + sizeof(double) <= 64, "the hot fields fill the first cache line");

// The operator's view of a node: the fields that pull_tables, push_down and
// the gather read, 56 bytes against Node's 192, so that their passes over
// millions of nodes (and the gather's scattered reads of senders) move a
// third of the memory. Rebuilt from m_nodes by collect_leaves.
struct OpNode {
    int32_t parent = -1;
    int32_t child = -1;     // elements: first half (-1: a leaf); leaf clusters: first side
    int32_t nchild = 0;
    int32_t table = -1;     // clusters that are not hierarchy leaves: their tables
    // The table a node's light goes up into (pull) or comes down from (push):
    // a cluster's parent's; a side's (an element or sink right under a leaf
    // cluster) its leaf cluster's parent's; -1 for pieces of elements.
    int32_t up_table = -1;
    int32_t leaf = -1;      // element leaves: index in m_leaves
    Kind kind = Kind::Cluster;
    bool leaf_cluster = false;
    bool side = false;      // an element or sink right under a leaf cluster
    bool chain = false;     // Node::chain (a chain cluster's length is its elements')
    uint32_t lobe = 0;      // sides with an up_table: lobe_bins(normal), the bins their cosine lobe reaches
    Vec2 normal;            // elements and sinks
    double length = 0;      // elements and sinks
};

// A link carries light from sender s to receiver r (DESIGN.md §3).
//   sender value v = I_s(phi) (cluster: exitance table read at the link's
//                    direction) or B_s (element);
//   contribution c = coef * v;
//   receiver: H_r += c (element or sink), or J_r += c spread on the two
//             samples around psi (cluster).
// coef by kind (tau = transmittance, d = distance between centres):
//   element <- element: F_rs (exact average over r; MultiscaleVisibility);
//   element <- cluster: tau * Delta_r / L_r, Delta_r the angle r subtends
//                       from the cluster's centre (point source);
//   cluster <- element: tau / d * (L_s / 2) cos+(n_s . u);
//   cluster <- cluster: tau / d.
struct Link {
    int32_t r = -1, s = -1;
    // Exitance direction at s, arrival direction at r (directional.h's
    // BinWeight, packed: a link is 64 bytes, and there are 10^7 of them at
    // 10^6 walls; a float weight rounds the interpolation by ~1e-7, the
    // same rounding for the operator and its adjoint).
    float st = 0;
    uint8_t sk = 0;
    bool unresolved = false;  // cluster links whose nodes overlap: must be split if they carry light
    // A chain link (see chain_etendue): both ends are arcs of one convex
    // loop; coef is the exact F_rs (crossed strings), the sender's value its
    // mean radiosity and the receiver gets it evenly (a scalar, no table);
    // vis_err bounds coef's rounding.
    bool uniform = false;
    bool clear = false;       // element links whose shaft held no blocker: nor do their children's
    // Visibility not asked yet: a cluster link's transmittance, an element
    // link's occluded F. Until it is, the link carries an estimate from the
    // scene's density (prior_transmittance, defer_visibility: coef, tau and
    // a vis_err that covers any truth), so that the solve, its error and
    // the energy totals read it like any other link; Fu holds the
    // unoccluded coefficient. The refinement asks only if the link is not
    // split on its geometry alone, and only if its error with the
    // transmittance unknown is above a share of the bar (refine,
    // deferred_share, resolve_visibility): a link from a sender too dim for
    // that to matter keeps it unknown.
    bool vis_pending = false;
    // Cluster ends read through the table's linear part (directional.h):
    // every member faces the link's direction u, where the linear part is
    // exact. *_back: where some member may stop facing over the directions
    // the link can take (its spread), a bound on how far the table leaves
    // its linear part there, relative to the linear part's norm (0 when
    // every member faces every direction of the spread).
    bool s_linear = false, r_linear = false;
    // Element links: kvar is kernel_variation itself, or (false) its bound
    // 2 Fu, until a decision needs the exact value (refine).
    bool kvar_exact = true;
    // Made by a split (children_links, self_links), its geometry not
    // computed yet: the next wave's decision computes it (make_link) first.
    bool fresh = false;
    // The pair of sides whose proof of closure last failed for this link or
    // the link it was split from (box_shown_closed's first_pair, + 1; 0:
    // none): proven first the next time (shown_closed_whole).
    uint8_t box_pair = 0;
    double coef = 0;
    float tau = 1;            // transmittance (cluster links), F / F_unoccluded (element links)
    float vis_err = 0;        // visibility bound: on tau (cluster links) or on F (element links)
    float ux = 0, uy = 0;     // cluster links: unit direction from s's centre to r's
    float Fu = 0;             // element links: unoccluded F; cluster links while vis_pending: the unoccluded coef
    float kvar = 0;           // element links: the kernel's variation over quarters (kernel_variation)
    float s_back = 0, r_back = 0;
    Vec2 u() const { return {ux, uy}; }
    BinWeight sbin() const { return {sk, st}; }
    BinWeight rbin() const { return opposite(sbin()); }  // arrival: the exitance bin half a table on
};
static_assert(sizeof(Link) == 64);

// Link vectors grow with resize(n) only where every new link is then
// written (sort_links): their pages are first touched by that write.
using LinkVector = std::vector<Link, UninitializedAllocator<Link>>;

// A convex loop's cycle (engine/connectivity.h's SceneLoop), and an arc of
// it: its ends, oriented with the room on the left (chain links).
struct ConvexLoop {
    std::vector<Vec2> polygon;  // SceneLoop::polygon
    int orientation = 0;
};
struct ChainEnds {
    Vec2 a, b;
    int32_t loop = -1;
};

// Chain links: the etendue L_r F_rs between two arcs of one convex loop,
// each given by its ends oriented with the room on the left (r: a0 -> a1,
// s: b0 -> b1). Inside a convex room every point of one arc sees every
// point of the other, and every line between them crosses both chords, so
// Hottel's crossed strings on the chords are exact (DESIGN.md §1; the
// chords are lit-left segments, each on the other's lit side):
//   L_r F_rs = (|a0 b0| + |a1 b1| - |a0 b1| - |a1 b0|) / 2,
// evaluated by engine/formfactor.h's stable form (a few ulps of the
// chords' lengths; `rounding` gets 16 of them). An arc with itself (r = s,
// length L): L F_rr = L - |a0 a1| (what leaves the arc and does not cross
// its chord); L is summed up the cluster tree (one rounding per level, and
// trees are far shallower than 64 levels), counted at 64 ulps.
// (tests/engine/formfactor_test.cpp checks both against the sum of every
// pair of walls' form factors.)
double chain_etendue(Vec2 a0, Vec2 a1, Vec2 b0, Vec2 b1, double& rounding) {
    rounding = 16 * std::numeric_limits<double>::epsilon() * (norm(a1 - a0) + norm(b1 - b0));
    return exchange_crossed_strings(Segment{a0, a1}, Segment{b0, b1});
}
double chain_self_etendue(Vec2 a0, Vec2 a1, double length, double& rounding) {
    const double chord = norm(a1 - a0);
    rounding = 64 * std::numeric_limits<double>::epsilon() * (length + chord);
    return std::max(0.0, length - chord);
}

// A link whose visibility is not known yet (its l.coef the unoccluded
// coefficient) carries an estimate tau_est of its transmittance, with the
// bound max(tau_est, 1 - tau_est) that covers any truth in [0, 1]. The
// unoccluded coefficient is kept in l.Fu (an element link's own; a cluster
// link's, which has no Fu, rounded to a float: only the error estimate
// reads it there, resolve_visibility computes it again).
void defer_visibility(Link& l, double tau_est, bool element) {
    if (!element) l.Fu = static_cast<float>(l.coef);
    l.vis_pending = true;
    l.coef *= tau_est;
    l.tau = static_cast<float>(tau_est);
    // On tau for a cluster link, on F for an element link (rounded up to a
    // float: a bound).
    const double bound = std::max(tau_est, 1 - tau_est) * (element ? static_cast<double>(l.Fu) : 1.0);
    float b = static_cast<float>(bound);
    if (b < bound) b = std::nextafter(b, std::numeric_limits<float>::infinity());
    l.vis_err = b;
}

// The value a link takes for a visibility answer known within +-bound (of
// [0, top]): an estimate where it lies in [answer - bound, answer + bound],
// else the nearer end, and the bound that keeps that interval (rounded up
// to a float). The estimate is the query's own where it has one (the
// direction bounds' midpoint rule on loose queries: MultiscaleResult::
// estimate), else the density's (prior_transmittance). Any value in the
// interval keeps the claim; the bound's midpoint (the bands', the
// direction bounds') sits halfway up an interval whose truth, through a
// dense forest, is usually near its foot. On the 1000-segment forest at
// eps 5 the shade (patches below 1e-3 of exact radiosity) went from 33%
// to 1.4e4% too bright to 7% to 4e3% (docs/solver-history.md,
// "Twenty-fourth session").
struct Estimate {
    double value;
    float bound;
};
// `own`: the query's estimate (NaN: none). (`prior` is called only when the
// bound is not 0 and there is none.)
template <class PriorFn>
Estimate within_bound(double answer, double bound, double own, double top, const PriorFn& prior) {
    if (!(bound > 0)) return {answer, static_cast<float>(bound)};
    const double lo = std::max(0.0, answer - bound), hi = std::min(top, answer + bound);
    const double v = std::clamp(std::isnan(own) ? prior() : own, lo, std::max(lo, hi));
    const double b = std::max(v - lo, hi - v);
    float f = static_cast<float>(b);
    if (f < b) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return {v, f};
}

// A query's answer is a clear shaft: exact (no bound) and the unoccluded
// F, rounding aside (4 ulps of it).
bool clear_answer(double F, double bound, double Fu) {
    return bound == 0 && std::abs(F - Fu) <= 4 * std::numeric_limits<double>::epsilon() * Fu;
}

Link link_between(int r, int s) {
    Link l;
    l.r = r;
    l.s = s;
    return l;
}

struct LinkError {
    double err = 0;       // estimated error in transported power
    bool split_r = true;  // the receiver's side makes most of it
};

// Whether material m emits in some channel.
bool emits(const Material& m) { return *std::max_element(m.emission.begin(), m.emission.end()) > 0; }

// Whether a patch of material m sends anything: it reflects or emits in
// some channel (an element's can_send; a patch that does not, inert, is no
// link's sender).
bool sends(const Material& m) {
    return *std::max_element(m.reflectance.begin(), m.reflectance.end()) > 0 || emits(m);
}

// What the scene's connectivity says (engine/connectivity.h, solver/rooms.h,
// solver/sink_visibility.h, solver/closed_rows.h): computed beside the
// hierarchy (see HierarchicalSolver's members).
struct SceneFacts {
    Connectivity conn;
    std::vector<char> escape_free;   // per patch
    std::vector<char> visible_sink;  // per segment side
    std::vector<char> inert;         // per patch: !sends
    ClosedRows rows;                 // per patch (solver/closed_rows.h)
    std::vector<int> side_room;      // per segment side
};

SceneFacts scene_facts(const Scene& scene) {
    SceneFacts f;
    f.conn = scene_connectivity(scene);
    f.escape_free = escape_free_patches(scene, f.conn);
    f.visible_sink = visible_sinks(scene, f.conn);
    f.inert.resize(scene.patches.size());
    for (size_t p = 0; p < scene.patches.size(); ++p)
        f.inert[p] = sends(scene.materials[static_cast<size_t>(scene.patches[p].material)]) ? 0 : 1;
    f.rows = closed_rows(scene, f.conn, f.escape_free, f.visible_sink, f.inert);
    f.side_room = side_rooms(scene, f.conn);
    return f;
}

// An independent sub-scene (solver/light_parts.h): the nodes its light
// moves through, ascending (parents first); its element leaves (indices
// into m_leaves); its receivers (indices into m_receivers).
struct Part {
    std::vector<int> nodes, leaves, receivers;
    // The whole scene as one part: every node, leaf and receiver, without
    // lists (the operator runs unrestricted; leaves lists every leaf).
    bool whole = false;
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The cluster hierarchy's leaf size for segments that cannot block (the
// header's "Leaves"; those that can have leaves of their own):
// options.unblocked_leaf_size, or when that is 0 wide_leaf_size where links
// are expected to stop well above the leaves. The expectation is a round
// room's: along a wall of N segments turning by 2 pi / N each, arcs of n
// walls exchange n^3 (2 pi / N)^2 / 8 of a wall's power (see chain links),
// and eps_abs is eps times a wall's mean power, so links stop at arcs of
// n* = (2 eps N^2 / pi^2)^(1/3) walls; wide leaves from n* >= 3 x 8 on.
// Measured on round rooms (links, seconds with 1 | 8 per leaf): 10^3
// walls eps 3e-3 (n* 8.5) 30 615 | 102 605; 10^4 eps 1e-4 (n* 12.7)
// 1.09 M, 1.12 s | 2.51 M, 1.61 s; 10^4 eps 1e-3 (n* 27) 0.36 | 0.30 s;
// 10^4 eps 3e-3 (n* 39) 0.24 | 0.20 s; 10^5 eps 1e-4 (n* 59) 4.96 | 4.53 s.
constexpr int wide_leaf_size = 8;
constexpr double wide_leaves_from_arc = 3.0 * wide_leaf_size;
int leaf_size(const std::vector<char>& blockers, const HierarchicalOptions& options) {
    if (options.unblocked_leaf_size > 0) return options.unblocked_leaf_size;
    const double N = static_cast<double>(blockers.size());
    const double arc = std::cbrt(2 * options.eps * N * N / (std::numbers::pi * std::numbers::pi));
    return arc >= wide_leaves_from_arc ? wide_leaf_size : 1;
}

class HierarchicalSolver {
public:
    HierarchicalSolver(const Scene& scene, const HierarchicalOptions& o)
        : m_scene(scene),
          m_opt(o),
          m_C(scene.channels),
          m_facts(std::async(std::launch::async, scene_facts, std::cref(scene))),
          m_blockers(possible_blockers(scene)),
          m_hierarchy(scene.segment_geometry(), leaf_size(m_blockers, o), m_blockers),
          m_tables(m_hierarchy),
          m_vis(m_hierarchy, m_tables),
          m_obox(oriented_boxes(m_hierarchy)) {
        m_threads = o.threads > 0 ? o.threads : omp_get_max_threads();
        m_vis_eps = o.vis_eps >= 0 ? o.vis_eps : o.eps / 10;
        // A visibility tolerance of 0 asks for exact visibility on every
        // link: none carries the density's estimate (see the header).
        if (m_vis_eps == 0) m_opt.defer_visibility = false;
        // Walls on the scene's hull block nothing (engine/convex_scene.h):
        // visibility skips them; with no blocker at all it is never asked.
        const std::vector<char>& blockers = m_blockers;
        m_hierarchy.set_blockers(blockers);
        m_vis.set_min_pieces_to_approximate(min_pieces_to_approximate);
        m_vis.set_min_pieces_to_bound(min_pieces_to_bound, min_pieces_to_bound_loose);
        m_vis.set_min_pieces_to_prove_closed(min_pieces_to_prove_closed);  // (after set_blockers: see there)
        if (o.closure_screens) m_screen_depth = m_vis.long_shaft_depth();
        m_unblockable = std::find(blockers.begin(), blockers.end(), 1) == blockers.end();
        m_kappa = m_vis.layers_per_depth();
        if (m_kappa > 0) {
            // Per hierarchy node: the layers of shadow per unit of depth of
            // the blockers inside its box that are not its members (boxes
            // overlap): the scene's density less the members' own, at
            // least 0 (prior_transmittance).
            const auto& order = m_hierarchy.order();
            std::vector<double> prefix(order.size() + 1, 0.0);
            for (size_t k = 0; k < order.size(); ++k) {
                const int sg = order[k];
                prefix[k + 1] = prefix[k] + (m_hierarchy.can_block(sg) ? m_scene.segments[static_cast<size_t>(sg)].seg.length() : 0.0);
            }
            m_foreign_kappa.assign(m_hierarchy.nodes().size(), 0.0);
            for (size_t h = 0; h < m_hierarchy.nodes().size(); ++h) {
                const ClusterNode& c = m_hierarchy.nodes()[h];
                const OrientedBox& b = m_obox[h];
                const double area = (b.hi_u - b.lo_u) * (b.hi_v - b.lo_v);
                const double own = prefix[static_cast<size_t>(c.first + c.count)] - prefix[static_cast<size_t>(c.first)];
                const double own_kappa = area > 0 ? 2 / std::numbers::pi * own / area : std::numeric_limits<double>::infinity();
                m_foreign_kappa[h] = std::max(0.0, m_kappa - own_kappa);
            }
        }
        if (m_opt.emission_first && !m_unblockable && m_hierarchy.root() >= 0) {
            const Vec2 e = m_hierarchy.node(m_hierarchy.root()).box.extent();
            m_emission_first = m_kappa * std::max(e.x, e.y) >= emission_first_layers;
        }
        // A few things inside a room (a lamp, a pillar): chain links check
        // them one by one (chain_clear); with more, none is made.
        // The same list serves nothing_between, with each one's place in
        // the hierarchy's order (the queries' skipped ranges are in it).
        if (std::count(blockers.begin(), blockers.end(), 1) <= max_chain_blockers) {
            m_few_blockers = true;
            const auto& order = m_hierarchy.order();
            for (size_t q = 0; q < order.size(); ++q)
                if (blockers[static_cast<size_t>(order[q])]) {
                    m_chain_blockers.push_back(scene.segments[static_cast<size_t>(order[q])].seg);
                    m_chain_blocker_pos.push_back(static_cast<int32_t>(q));
                }
        }
        SceneFacts facts = m_facts.get();
        m_escape_free = std::move(facts.escape_free);
        m_visible_sink = std::move(facts.visible_sink);
        m_side_room = std::move(facts.side_room);
        convex_object_skips(facts.conn);
        m_box_intruded = std::make_unique<std::atomic<int8_t>[]>(m_hierarchy.nodes().size());
        for (size_t h = 0; h < m_hierarchy.nodes().size(); ++h) m_box_intruded[h].store(-1, std::memory_order_relaxed);
        const bool sinks = std::find(m_visible_sink.begin(), m_visible_sink.end(), 1) != m_visible_sink.end();
        // A lit patch that neither reflects nor emits, in any channel, sends
        // nothing, so no link has it as its sender (gather_from_children's
        // can_send): a row that sees it misses what it absorbs, as with a
        // sink. (Closing such rows to 1 gave that light back to the walls:
        // a black plate in a white room was not there at all.) Rows close
        // where a closed loop keeps such sides out of sight, or where they
        // are made senders (solver/closed_rows.h; build_tree,
        // gather_from_children, refinement_values).
        const bool inert = std::find(facts.inert.begin(), facts.inert.end(), 1) != facts.inert.end();
        m_closed_patch = std::move(facts.rows.closed);
        m_inert_sends = std::move(facts.rows.inert_sends);
        m_sink_sends = std::move(facts.rows.sink_sends);
        m_made_senders = std::find(m_inert_sends.begin(), m_inert_sends.end(), 1) != m_inert_sends.end() ||
                            std::find(m_sink_sends.begin(), m_sink_sends.end(), 1) != m_sink_sends.end();
        m_black.reflectance.assign(static_cast<size_t>(m_C), 0.0);
        m_black.emission.assign(static_cast<size_t>(m_C), 0.0);
        m_convex_room = o.convex_room_shortcut && m_unblockable && !sinks && !inert &&
                        std::find(m_escape_free.begin(), m_escape_free.end(), 0) == m_escape_free.end();
    }

    Solution run();

private:
    const Material& material(int patch) const {
        if (static_cast<size_t>(patch) >= m_scene.patches.size()) return m_black;  // a sink made a sender
        return m_scene.materials[static_cast<size_t>(m_scene.patches[static_cast<size_t>(patch)].material)];
    }
    double rho(int node, int c) const {
        const Node& n = m_nodes[static_cast<size_t>(node)];
        return n.kind == Kind::Element ? material(n.patch).reflectance[static_cast<size_t>(c)] : 0.0;
    }
    double emission(int node, int c) const {
        const Node& n = m_nodes[static_cast<size_t>(node)];
        return n.kind == Kind::Element ? material(n.patch).emission[static_cast<size_t>(c)] : 0.0;
    }
    void progress(const std::string& stage, double fraction) const {
        if (m_opt.progress) m_opt.progress(stage, fraction);
    }
    void refuse_closed_white() const;
    void convex_object_skips(const Connectivity& conn);
    void build_tree();
    void mark_chains();
    void self_occlusion(const std::vector<size_t>& level_start);
    void sensitivity_with_gamma(size_t k);
    void gather_from_children(size_t k);
    // The levels of the node tree while the nodes are in breadth-first
    // order as build_tree lays them out (before any element is split):
    // level d is then the run of nodes [start[d], start[d + 1]).
    std::vector<size_t> level_starts() const {
        std::vector<size_t> start = {0};
        std::vector<int32_t> level(m_nodes.size(), 0);
        for (size_t k = 1; k < m_nodes.size(); ++k) {
            level[k] = level[static_cast<size_t>(m_nodes[k].parent)] + 1;
            FLATRAD_ASSERT(level[k] >= level[k - 1], "the nodes are in breadth-first order");
            if (level[k] != level[k - 1]) start.push_back(k);
        }
        start.push_back(m_nodes.size());
        return start;
    }
    // f(k) for every node k, children before parents: the levels
    // (level_starts, for the nodes as they are) from the deepest up, each
    // level's nodes on every thread. f(k) may read k's children and write
    // k only.
    template <class F>
    void bottom_up(const std::vector<size_t>& start, const F& f) {
        FLATRAD_ASSERT(!start.empty() && start.back() == m_nodes.size(), "levels of the nodes as they are");
        for (size_t d = start.size() - 1; d-- > 0;) {
            const long first = static_cast<long>(start[d]), last = static_cast<long>(start[d + 1]);
#pragma omp parallel for num_threads(m_threads) schedule(dynamic, 4096) if (last - first >= 8192)
            for (long k = first; k < last; ++k) f(static_cast<size_t>(k));
        }
    }
    // Node k's share seen from outside its parent (self_occlusion), per
    // direction bin; null where it is 1 in every bin.
    const float* gamma(size_t k) const {
        if (k >= m_gamma_slot.size() || m_gamma_slot[k] < 0) return nullptr;
        return &m_gamma[static_cast<size_t>(m_gamma_slot[k]) * directional_bins];
    }
    bool hidden_below(const Node& n) const { return !m_hidden_below.empty() && m_hidden_below[static_cast<size_t>(n.table)]; }
    bool chain_ends(const Node& n, ChainEnds& out) const;
    bool chain_clear(const ChainEnds& a, const ChainEnds& b) const;
    bool nothing_between(const Node& a, int skip_a, const Node& b, int skip_b) const;
    void endpoints(int node, std::vector<int>& out) const;
    void children_links(const Link& l, bool split_r, LinkVector& out) const;
    void self_links(int node, LinkVector& out) const;
    bool make_link(int r, int s, Link& l, VisibilityStats& st) const;
    double unoccluded_coef(const Node& r, const Node& s) const;
    double prior_transmittance(const Node& r, const Node& s) const;
    bool resolve_visibility(Link& l, ExactWorkspace& ws, VisibilityStats& st) const;
    MultiscaleResult element_exchange(int r, int s, double Fu, ExactWorkspace& ws, VisibilityStats& st) const;
    double kernel_variation(const Node& r, const Node& s, double Fu) const;
    TransmittanceResult link_transmittance(int r, int s, ExactWorkspace& ws, VisibilityStats& st) const;
    bool behind_closure_screen(int e, const Box& region, ExactWorkspace& ws, VisibilityStats& st) const;
    bool shown_closed_whole(Link& l, double bar, ExactWorkspace& ws, VisibilityStats& st) const;
    // Whether self link l (not a chain's) is split only when its error asks
    // (link_error), not always: with faint_overlaps_kept, but never a leaf
    // cluster's (the root's in a small scene), whose split goes to its
    // sides: no link ends at a leaf cluster, which has no table.
    bool self_link_kept_if_faint(const Link& l) const {
        return m_opt.faint_overlaps_kept && !m_nodes[static_cast<size_t>(l.r)].leaf_cluster;
    }
    Box cluster_target_region(int hnode, Vec2 from) const;
    int split_element(int node);
    void pull_tables(const double* leaf_value, std::vector<double>& Bn, TableArray& I,
                     const Part* part = nullptr) const;
    void pull_node(size_t k, const double* leaf_value, std::vector<double>& Bn, TableArray& I, const Part* part,
                   bool own, bool up) const;
    void build_op_schedule();
    LinkError link_error(const Link& l, const std::vector<double>& Bn, const TableArray& I,
                         bool geometry_only = false) const;
    bool refine(const std::vector<double>& leaf_bmax, double exitant_power = -1);
    std::vector<double> refinement_values(std::vector<double> leaf_values) const;
    void collect_leaves();
    std::vector<char> light_flow() const;
    void drop_dark(const std::vector<char>& reached2);
    void sort_links();
    void index_receivers();
    void apply_G(const Eigen::VectorXd& x, Eigen::VectorXd& out, bool correct, const Part* part = nullptr);
    void build_parts();
    void clear_scratch(std::vector<double>& per_node, TableArray& tables, const Part* part) const;
    void sample_slots();
    bool in_part(const Part* part, int node, int parent) const {
        return !part || m_part_of[static_cast<size_t>(parent)] == m_part_of[static_cast<size_t>(node)];
    }
    void solve(double tolerance = gmres_tolerance);
    void row_sums();
    std::vector<double> leaf_guess() const;
    std::vector<char> dark_patches() const;
    std::vector<double> landed_fraction() const;
    void push_down(TableArray& tables, const std::vector<double>& own, double lobe_scale,
                   std::vector<double>& above, const Part* part = nullptr) const;
    void push_node(size_t k, TableArray& tables, const std::vector<double>& own, double lobe_scale,
                   std::vector<double>& above, const Part* part) const;

    // First: stats.time_s counts the set-up below (hierarchy, connectivity,
    // rooms, sinks) as well as the run.
    Clock::time_point m_t_start = Clock::now();
    const Scene& m_scene;
    HierarchicalOptions m_opt;
    int m_C;
    // The connectivity's facts, computed on a second thread while the
    // hierarchy is built (declared before it, so started first): at 10^6
    // walls 1.5 s against the hierarchy's and the hull's 0.9 s.
    std::future<SceneFacts> m_facts;
    int m_threads = 1;
    double m_vis_eps = 0;
    bool m_unblockable = false;
    double m_kappa = 0;  // the scene's layers of shadow per unit of depth (prior_transmittance)
    std::vector<double> m_foreign_kappa;  // per hierarchy node (prior_transmittance)
    bool m_emission_first = false;  // the first round against the emission alone (run; emission_first_layers)
    // A closed convex room whose patches all reflect or emit: once anything
    // emits, every patch is reached and the scene is one part (solve()).
    bool m_convex_room = false;

    // Which segments can block (engine/convex_scene.h), before the
    // hierarchy: those have leaves of their own, the others may share
    // (leaf_size).
    std::vector<char> m_blockers;
    Hierarchy m_hierarchy;
    ClusterTables m_tables;
    MultiscaleVisibility m_vis;
    std::vector<OrientedBox> m_obox;  // per hierarchy node (engine/oriented_box.h)
    // Transmittance between two hierarchy nodes, per unordered pair
    // (symmetric: the lines joining the two cross-sections), with the
    // refinement wave that computed it (link_transmittance's patch
    // shortcut takes only answers of earlier waves: see there).
    struct TauEntry {
        double tau, error_bound, estimate;  // (TransmittanceResult's)
        uint32_t wave;
    };
    mutable std::unordered_map<uint64_t, TauEntry> m_tau_cache;
    mutable std::shared_mutex m_tau_mutex;
    // Element pairs' answers kept for the other way (element_exchange),
    // keyed by the query's receiver and sender; per node, whether one of
    // its pairs is kept (read and written as atomics; sized between waves).
    struct PairEntry {
        double F, error_bound, estimate;  // (MultiscaleResult's)
    };
    mutable std::unordered_map<uint64_t, PairEntry> m_pair_cache;
    mutable std::shared_mutex m_pair_mutex;
    mutable std::vector<uint8_t> m_pair_kept;
    uint32_t m_wave = 0;  // refinement waves so far (refine, one per wave)
    // Closure screens (behind_closure_screen): per element node and depth
    // (the key: node x the depths' count + the depth's index), per direction
    // bin, 0 not asked yet, 1 shown closed, 2 not shown closed or not
    // possible there. m_screen_depth: the unit of closure_screen_depths
    // (infinite: no screens are made).
    mutable std::unordered_map<int64_t, std::array<int8_t, closure_screen_bins>> m_screens;
    mutable std::shared_mutex m_screen_mutex;
    double m_screen_depth = std::numeric_limits<double>::infinity();
    // Per hierarchy node: the node whose segments a transmittance from it
    // does not count as blockers (itself, or its highest ancestor made of
    // the same convex closed loop: see convex_object_skips).
    std::vector<int32_t> m_tau_skip;
    // Per hierarchy node: whether a long blocker other than its m_tau_skip
    // node's segments runs through its box (engine/box_intrusion.h;
    // link_error's intruded_box_share); -1 until asked. Asked from the
    // refinement's threads: the same answer whichever asks first.
    mutable std::unique_ptr<std::atomic<int8_t>[]> m_box_intruded;
    bool box_intruded(int h) const;
    // Chain links (mark_chains, chain_etendue): the convex loops, and per
    // segment its loop and place in the loop's cycle (-1: none); per
    // cluster table the ends of its chain, oriented with the room on the
    // left (loop -1: not a chain).
    std::vector<ConvexLoop> m_convex_loops;
    std::vector<int32_t> m_seg_loop, m_seg_pos;
    std::vector<ChainEnds> m_chain_ends;
    bool m_chains = false;       // some cluster is a chain and few things can block: chain links are made
    bool m_few_blockers = false;  // at most max_chain_blockers segments may block
    std::vector<Segment> m_chain_blockers;  // those segments (chain_clear), in the hierarchy's order
    std::vector<int32_t> m_chain_blocker_pos;  // their positions in it
    std::vector<double> m_Bmax;  // refine: per node, the highest leaf value below (link_error)
    std::vector<double> m_Lsum;  // refine: per node, the total length of the leaves below (link_error)
    std::vector<int> m_patch_root;  // per patch: its element tree's root node

    std::vector<Node> m_nodes;
    int m_root = -1;
    int m_tables_count = 0;
    std::vector<double> m_sensitivity;  // per cluster table: sum L cos+(n . u(psi_k)), seen from outside
    // Occlusion inside clusters (self_occlusion): per node under a table
    // (a cluster or a leaf cluster), its slot in m_gamma (-1: none, the
    // factor is 1), where per direction bin the factor gamma by which what
    // it pulls up into its parent's table and what it gets from that table
    // are scaled (all empty: no occlusion anywhere); per table, whether
    // some gamma < 1 below it (its linear part is not read); the
    // sensitivity before the factors (the link error's `layered` term).
    // (Floats, and the faces below too: the same rounded factor in pull and
    // push, so the operator keeps its adjoint; the 10^5 forest's peak at
    // eps 10 went from 581 to 570 MB, its radiosity moved by 1.6e-10
    // relative L2.)
    std::vector<int32_t> m_gamma_slot;
    std::vector<float, UninitializedAllocator<float>> m_gamma;  // (self_occlusion writes every slot)
    // Per table and direction bin: how far along that direction, from the
    // node's centre, the lobes seen from far along it lie on average (its
    // visible face; 0 where not measured): the point a cluster link's
    // geometry is taken from (unoccluded_coef). Empty: 0 everywhere.
    std::vector<float, UninitializedAllocator<float>> m_face;  // (self_occlusion writes every row)
    double face_offset(const Node& n, Vec2 u) const {
        if (m_face.empty() || !n.cluster() || n.table < 0) return 0.0;
        return interpolate(&m_face[static_cast<size_t>(n.table) * directional_bins], bin_of(u));
    }
    std::vector<char> m_hidden_below;
    std::vector<double> m_sensitivity_all;
    LinkVector m_links;
    LinkVector m_links_sorted, m_fresh;  // scratch of sort_links and refine, kept for their pages
    size_t m_sorted_links = 0;  // how many of m_links, from the first, are sorted by receiver
    std::vector<char> m_refine_decision;  // refine's decisions on its tail of links
    std::vector<int32_t> m_link_start;   // CSR by receiver (after sort_links)
    std::vector<int32_t> m_receivers;
    std::vector<int> m_leaves;           // element leaves
    int m_element_leaves = 0;
    std::vector<int, UninitializedAllocator<int>> m_leaf_index;  // node -> index in m_leaves, -1 otherwise (collect_leaves)
    std::vector<OpNode, UninitializedAllocator<OpNode>> m_op;  // per node (collect_leaves, which writes each as it grows)
    // Per node, its table alone (OpNode::table): the gather reads it for
    // every link's sender, scattered, from an array a fourteenth of m_op's
    // size (the 10^5 forest at eps 10: the gathers 0.25 -> 0.17 s, the
    // same answers).
    std::vector<int32_t, UninitializedAllocator<int32_t>> m_table_of;
    // The operator's passes on several threads (build_op_schedule): disjoint
    // subtrees, each ascending from its top node (a frontier node), largest
    // first; and, ascending, the nodes above them with the frontier nodes.
    // Empty: one thread.
    struct OpSchedule {
        std::vector<std::vector<int>> subtrees;
        std::vector<int> top;
        std::vector<char> frontier;  // per node
    } m_sched;
    std::vector<char> m_reached;         // per node
    long m_left_out = 0;
    long m_dark_links = 0;               // links the last drop_dark() dropped
    // The last flow check (reach, parts) found nothing dark and one part (solve).
    bool m_flow_simple = false;
    // Row sums (see the header): per leaf, the deficit 1 - (sum of what its
    // own and its ancestors' links deliver for B = 1 everywhere), and the
    // ancestors' part of that sum; 0 for leaves not known to be closed.
    std::vector<double> m_deficit, m_anc_sum, m_own_sum;
    std::vector<char> m_closed_patch;
    // Sides that send nothing made senders (solver/closed_rows.h): inert
    // patches, per patch, and visible sinks, per segment side; such a sink
    // is an element of a patch of its own, numbered from the scene's patch
    // count on (m_black, never in the result's patches).
    std::vector<char> m_inert_sends, m_sink_sends;
    bool m_made_senders = false;
    Material m_black;
    int m_sink_patches = 0;
    std::vector<char> m_escape_free;   // per patch (engine/connectivity.h)
    std::vector<char> m_visible_sink;  // per segment side (solver/sink_visibility.h)
    std::vector<int> m_side_room;      // per segment side (solver/rooms.h)

    // Independent sub-scenes, solved apart (after each refinement).
    std::vector<Part> m_parts;
    std::vector<int> m_part_of;  // per node: its part, -1 when none
    long m_part_count = 0;
    // Scratch for the operator: per node, and the exitance (I) and
    // arrival (J) tables, with samples only where links use them
    // (solver/table_array.h; refinement pulls every table's samples).
    std::vector<double> m_Bn, m_Hn, m_Ha;
    TableArray m_I, m_J;
    std::vector<int32_t> m_I_slot, m_J_slot;  // per table: its samples' slot, -1 for none (sample_slots)
    int m_I_slotted = 0, m_J_slotted = 0;
    // Solution per channel, per node (B pulled, H pushed).
    std::vector<std::vector<double>> m_B, m_H;

    VisibilityStats m_stats;
    double m_ff_time = 0, m_solve_time = 0, m_residual = 0;
    long m_iterations = 0;
    int m_passes = 0;  // refine-solve rounds
    bool m_refined_to_eps = false;  // a round split nothing (run; stats.refined_to_eps)
    bool m_solved = false;  // m_B holds a solution (the next Krylov run starts from it)
    // The operator may differ from the last solve's: a link was made,
    // split, dropped or given its visibility since (refine). When not, the
    // next solve keeps that solve's set-up (solve).
    bool m_operator_changed = true;
    long m_setups_kept = 0;
    // stats.phases: the stages ended so far, and when the current one began.
    std::vector<Phase> m_phases;
    Clock::time_point m_phase_start = m_t_start;
    void end_phase(std::string name) {
        const auto now = Clock::now();
        m_phases.push_back({std::move(name), std::chrono::duration<double>(now - m_phase_start).count()});
        m_phase_start = now;
    }
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

// A convex closed loop (a pillar, a tube, a convex room) never stands
// between one of its own faces and anything that face can see: light
// leaving a lit side of a convex loop, outwards or inwards, does not meet
// the loop again. A cluster link's transmittance is measured between
// stand-ins that may lie inside the object (the cross-section of an arc of
// a pillar), whose lines would cross the rest of it; so for a hierarchy node
// made only of one convex loop's segments, the whole part of the hierarchy
// made of that loop is skipped as blockers. Convex: certified simple
// (engine/connectivity.h) and every turn of the polygon of the same sign
// beyond rounding (unsure: not convex, and nothing changes).
void HierarchicalSolver::convex_object_skips(const Connectivity& conn) {
    const auto& hn = m_hierarchy.nodes();
    m_tau_skip.resize(hn.size());
    for (size_t h = 0; h < hn.size(); ++h) m_tau_skip[h] = static_cast<int32_t>(h);
    std::vector<int> seg_loop(m_scene.segments.size(), -1);
    for (size_t L = 0; L < conn.loops.size(); ++L) {
        const SceneLoop& loop = conn.loops[L];
        if (!loop.simple || loop.orientation == 0) continue;
        const size_t n = loop.polygon.size();
        bool convex = n >= 3;
        for (size_t k = 0; k < n && convex; ++k) {
            const Vec2 a = loop.polygon[(k + n - 1) % n], b = loop.polygon[k], c = loop.polygon[(k + 1) % n];
            const double turn = orient(a, b, c);
            const double len = norm(b - a) + norm(c - b);
            convex = turn * loop.orientation > 1e-12 * len * len;
        }
        if (!convex) continue;
        for (int sgm : loop.segments) seg_loop[static_cast<size_t>(sgm)] = static_cast<int>(L);
        // For chain links: the loop's cycle (mark_chains).
        const int32_t id = static_cast<int32_t>(m_convex_loops.size());
        m_convex_loops.push_back({loop.polygon, loop.orientation});
        if (m_seg_loop.empty()) {
            m_seg_loop.assign(m_scene.segments.size(), -1);
            m_seg_pos.assign(m_scene.segments.size(), -1);
        }
        for (size_t k = 0; k < n; ++k) {
            m_seg_loop[static_cast<size_t>(loop.segments[k])] = id;
            m_seg_pos[static_cast<size_t>(loop.segments[k])] = static_cast<int32_t>(k);
        }
    }
    // Per node: the one convex loop all its segments are on, or -1.
    std::vector<int> node_loop(hn.size(), -1);
    for (size_t h = hn.size(); h-- > 0;) {  // children come after their parents
        const ClusterNode& c = hn[h];
        if (c.leaf()) {
            int L = seg_loop[static_cast<size_t>(m_hierarchy.order()[static_cast<size_t>(c.first)])];
            for (int32_t q = c.first + 1; q < c.first + c.count && L >= 0; ++q)
                if (seg_loop[static_cast<size_t>(m_hierarchy.order()[static_cast<size_t>(q)])] != L) L = -1;
            node_loop[h] = L;
        } else {
            const int a = node_loop[static_cast<size_t>(c.child[0])], b = node_loop[static_cast<size_t>(c.child[1])];
            node_loop[h] = a == b ? a : -1;
        }
    }
    for (size_t h = 0; h < hn.size(); ++h) {  // parents first
        const int p = hn[h].parent;
        if (node_loop[h] >= 0 && p >= 0 && node_loop[static_cast<size_t>(p)] == node_loop[h])
            m_tau_skip[h] = m_tau_skip[static_cast<size_t>(p)];
    }
}

bool HierarchicalSolver::box_intruded(int h) const {
    std::atomic<int8_t>& known = m_box_intruded[static_cast<size_t>(h)];
    const int8_t k = known.load(std::memory_order_relaxed);
    if (k >= 0) return k != 0;
    const ClusterNode& skip = m_hierarchy.node(m_tau_skip[static_cast<size_t>(h)]);
    thread_local std::vector<int32_t> stack;
    const Box& box = m_hierarchy.node(h).box;
    const double diagonal = box.diagonal();
    const bool intruded = box_intruded_by_blocker(m_hierarchy, box, skip.first, skip.count, diagonal,
                                                  intruder_min_chord * diagonal, stack);
    known.store(intruded ? 1 : 0, std::memory_order_relaxed);
    return intruded;
}

// One tree: hierarchy nodes (clusters), then under each hierarchy leaf the
// sides of its segments (patch roots and sinks). Parents come before their
// children, so pushes run forwards and pulls backwards over the array.
void HierarchicalSolver::build_tree() {
    const auto& hn = m_hierarchy.nodes();
    std::vector<int32_t> seg_leaf(m_scene.segments.size(), -1);
    // Patches per segment.
    std::vector<int> first_patch(m_scene.segments.size(), -1), second_patch(m_scene.segments.size(), -1);
    for (size_t p = 0; p < m_scene.patches.size(); ++p) {
        const size_t s = static_cast<size_t>(m_scene.patches[p].segment);
        (first_patch[s] < 0 ? first_patch[s] : second_patch[s]) = static_cast<int>(p);
    }
    if (hn.empty()) return;
    // Breadth-first over the hierarchy, children contiguous.
    struct Pending {
        int hnode, node;
    };
    std::vector<Pending> queue;
    queue.reserve(hn.size());
    // Room for every cluster and side, and as many element halves again:
    // reserved address space (pages count only once written), so that
    // millions of nodes are neither copied nor zeroed twice as they grow.
    size_t sides = 0;
    for (size_t s = 0; s < m_scene.segments.size(); ++s)
        for (int side = 0; side < 2; ++side)
            sides += (side == 0 ? m_scene.segments[s].lit_left : m_scene.segments[s].lit_right) ||
                     m_visible_sink[2 * s + static_cast<size_t>(side)];
    m_nodes.reserve(hn.size() + 2 * sides);
    {
        // The pages the breadth-first pass below fills (a node per cluster
        // and per side: 770 MB at 10^6 segments) are first touched here on
        // every thread, so that the kernel zeroes them side by side rather
        // than fault by fault on one thread. Raw storage, bytes only: the
        // pass constructs every node in it.
        unsigned char* const raw = reinterpret_cast<unsigned char*>(m_nodes.data());
        const size_t bytes = (hn.size() + sides) * sizeof(Node);
        const long T = m_threads;
        const auto cut = [&](long t) { return bytes * static_cast<size_t>(t) / static_cast<size_t>(T); };  // slice t's start
#pragma omp parallel for num_threads(m_threads) schedule(static) if (bytes >= (size_t{64} << 20))
        for (long t = 0; t < T; ++t) std::memset(raw + cut(t), 0, cut(t + 1) - cut(t));
    }
    m_nodes.push_back({});
    m_root = 0;
    queue.push_back({m_hierarchy.root(), 0});
    for (size_t q = 0; q < queue.size(); ++q) {
        const auto [h, id] = queue[q];
        const ClusterNode& c = hn[static_cast<size_t>(h)];
        {
            Node& n = m_nodes[static_cast<size_t>(id)];
            n.kind = Kind::Cluster;
            n.hnode = h;
            n.center = c.box.center();
            n.radius = 0.5 * c.box.diagonal();
        }
        if (!c.leaf()) {
            const int first = static_cast<int>(m_nodes.size());
            m_nodes[static_cast<size_t>(id)].child = first;
            m_nodes[static_cast<size_t>(id)].nchild = 2;
            for (int k = 0; k < 2; ++k) {
                Node child;
                child.parent = id;
                m_nodes.push_back(child);
                queue.push_back({c.child[k], first + k});
            }
            continue;
        }
        // A leaf: its segments' two sides each.
        m_nodes[static_cast<size_t>(id)].leaf_cluster = true;
        const int first = static_cast<int>(m_nodes.size());
        for (int32_t k = c.first; k < c.first + c.count; ++k) {
            const int s = m_hierarchy.order()[static_cast<size_t>(k)];
            seg_leaf[static_cast<size_t>(s)] = h;
            const SceneSegment& ss = m_scene.segments[static_cast<size_t>(s)];
            for (int side = 0; side < 2; ++side) {
                const bool lit = side == 0 ? ss.lit_left : ss.lit_right;
                const size_t x = 2 * static_cast<size_t>(s) + static_cast<size_t>(side);
                if (!lit && !m_visible_sink[x]) continue;
                Node n;
                n.parent = id;
                n.hnode = h;
                n.segment = s;
                n.seg = side == 0 ? ss.seg : ss.seg.reversed();
                n.normal = n.seg.left_normal();
                n.center = n.seg.midpoint();
                n.length = ss.seg.length();
                n.radius = 0.5 * n.length;
                n.recv_rooms = room_mask(m_side_room[2 * static_cast<size_t>(s) + static_cast<size_t>(side)]);
                if (lit) {
                    n.kind = Kind::Element;
                    const int p = (first_patch[static_cast<size_t>(s)] >= 0 &&
                                   m_scene.patches[static_cast<size_t>(first_patch[static_cast<size_t>(s)])].lit_left == (side == 0))
                                      ? first_patch[static_cast<size_t>(s)]
                                      : second_patch[static_cast<size_t>(s)];
                    n.patch = p;
                } else if (m_sink_sends[x]) {
                    n.kind = Kind::Element;
                    n.patch = static_cast<int>(m_scene.patches.size() + m_sink_patches++);
                } else {
                    n.kind = Kind::Sink;
                }
                m_nodes.push_back(n);
            }
        }
        m_nodes[static_cast<size_t>(id)].child = first;
        m_nodes[static_cast<size_t>(id)].nchild = static_cast<int>(m_nodes.size()) - first;
    }
    // The sinks made senders: patches of their own, whose light cannot be
    // closed (they carry 0) and that send.
    const size_t all_patches = m_scene.patches.size() + static_cast<size_t>(m_sink_patches);
    m_escape_free.resize(all_patches, 0);
    m_closed_patch.resize(all_patches, 0);
    m_inert_sends.resize(all_patches, 1);
    m_patch_root.assign(all_patches, -1);
    for (size_t k = 0; k < m_nodes.size(); ++k)
        if (m_nodes[k].kind == Kind::Element) m_patch_root[static_cast<size_t>(m_nodes[k].patch)] = static_cast<int>(k);
    // Directional tables for the clusters that are not hierarchy leaves
    // (links never end at a leaf cluster: at that level they go to the sides).
    for (Node& n : m_nodes)
        if (n.cluster() && !n.leaf_cluster) n.table = m_tables_count++;
    m_sensitivity.assign(static_cast<size_t>(m_tables_count) * TW, 0.0);
    m_I_slot.assign(static_cast<size_t>(m_tables_count), -1);  // no link yet: no samples
    m_J_slot = m_I_slot;
    // can_send, cones, rooms and sensitivity, children before parents: each
    // node gathers from its children (bottom_up).
    // (The levels serve self_occlusion too: no node is added in between.)
    const std::vector<size_t> level_start = level_starts();
    bottom_up(level_start, [this](size_t k) { gather_from_children(k); });
    mark_chains();
    end_phase("tree");
    self_occlusion(level_start);
    end_phase("self occlusion");
}

// Node k's can_send, cones, rooms and sensitivity from its own side (an
// element) and from its children's (build_tree).
void HierarchicalSolver::gather_from_children(size_t k) {
    Node& n = m_nodes[k];
    if (n.kind == Kind::Element) {
        n.can_send = sends(material(n.patch)) || m_inert_sends[static_cast<size_t>(n.patch)];
        n.send_rooms = n.can_send ? n.recv_rooms : 0;
    }
    double* dst = n.table >= 0 ? &m_sensitivity[static_cast<size_t>(n.table) * TW] : nullptr;
    for (int ch = n.child + n.nchild; ch-- > n.child;) {
        const Node& c = m_nodes[static_cast<size_t>(ch)];
        n.can_send = n.can_send || c.can_send;
        if (c.cluster()) {
            n.send_cone = NormalCone::merge(n.send_cone, c.send_cone);
            n.recv_cone = NormalCone::merge(n.recv_cone, c.recv_cone);
        } else {
            if (c.can_send) n.send_cone = NormalCone::merge(n.send_cone, NormalCone::of(c.normal));
            n.recv_cone = NormalCone::merge(n.recv_cone, NormalCone::of(c.normal));
        }
        n.send_rooms |= c.send_rooms;
        n.recv_rooms |= c.recv_rooms;
        if (!dst) continue;
        if (c.table >= 0) {
            const double* src = &m_sensitivity[static_cast<size_t>(c.table) * TW];
            for (int b = 0; b < TW; ++b) dst[b] += src[b];
        } else if (c.leaf_cluster) {
            for (int sd = c.child; sd < c.child + c.nchild; ++sd)
                add_cosine_lobe(dst, m_nodes[static_cast<size_t>(sd)].normal, m_nodes[static_cast<size_t>(sd)].length);
        }
    }
}

// Occlusion inside clusters (solver/self_occlusion.h). Per table cluster,
// per direction bin: A, the share of its members' lobes seen from outside
// it (visible_fraction's measure, for every cluster at once by merged
// front envelopes: solver/front_envelopes.h; exact, where measuring each
// cluster alone sampled those of more than exact_up_to members on lines:
// on the 1000-segment forest 5.3 ms against 12 ms on one thread, 4.5 ms
// against 6.2 ms on two, the same error against exact), so that its
// sensitivity is A x the lobes' sum;
// and, per child, the share of that child's lobes seen from outside the
// cluster (the same envelopes, by groups). The operator applies it edge
// by edge: a child's gamma is its share seen from outside its parent over
// its share seen from outside itself (what its own table already counts),
// and it scales the exitance the child pulls up into its parent's table
// and the arrivals it takes from there (pull_tables, push_down), the same
// factor both ways, so that the operator keeps its adjoint
// (landed_fraction) and a cluster delivers to its members what its
// sensitivity says it receives: sum over children of gamma x their
// sensitivity, A x the lobes' sum.
//
// Per child, not one factor per cluster: a cluster's arrivals go to the
// children in view along their direction, not evenly to all of them (one
// factor per cluster gave a forest's members behind others the same
// light as those in front, and its shade, lit through cluster links, far
// too much; docs/solver-history.md, "Twenty-fourth session"). What is
// still spread evenly is each child's share among its own members, down
// to the next level, where the next gamma sorts them again.
//
// Not where nothing can block (a convex room: the tables are exact) nor for
// chains (arcs of a convex loop, lit on the room's side, whose partners
// lie inside the loop: seen from there, no side hides another, while the
// view from far along a direction, from outside the loop, would).
void HierarchicalSolver::self_occlusion(const std::vector<size_t>& level_start) {
    m_gamma_slot.clear();
    m_gamma.clear();
    m_face.clear();
    m_hidden_below.clear();
    m_sensitivity_all.clear();
    if (m_unblockable || m_tables_count == 0) return;
    std::vector<int> clusters;
    for (size_t k = 0; k < m_nodes.size(); ++k) {
        const Node& n = m_nodes[k];
        if (n.table < 0 || n.chain) continue;
        const ClusterNode& c = m_hierarchy.node(n.hnode);
        if (c.count >= 2 && c.blockers >= 1) clusters.push_back(static_cast<int>(k));
    }
    // Every child of those clusters gets a slot; a cluster's children's
    // slots are consecutive.
    std::vector<int32_t> slot(m_nodes.size(), -1);
    int32_t slots = 0;
    for (int k : clusters) {
        const Node& n = m_nodes[static_cast<size_t>(k)];
        for (int ch = n.child; ch < n.child + n.nchild; ++ch) slot[static_cast<size_t>(ch)] = slots++;
    }
    // Every cluster at once, by merged front envelopes (solver/front_envelopes.h),
    // each with its children as the groups: their slots' order.
    std::vector<uint8_t> sides_at(m_hierarchy.order().size());
    for (size_t q = 0; q < sides_at.size(); ++q) {
        const size_t s = static_cast<size_t>(m_hierarchy.order()[q]);
        const SceneSegment& ss = m_scene.segments[s];
        uint8_t has = 0;
        if (ss.lit_left || m_visible_sink[2 * s]) has |= left_side;
        if (ss.lit_right || m_visible_sink[2 * s + 1]) has |= right_side;
        if (m_hierarchy.can_block(static_cast<int>(s))) has |= blocks;
        sides_at[q] = has;
    }
    EnvelopeClusters asked;
    asked.group_begin.push_back(0);
    for (int k : clusters) {
        const Node& n = m_nodes[static_cast<size_t>(k)];
        asked.node.push_back(n.hnode);
        for (int ch = n.child; ch < n.child + n.nchild; ++ch) {
            FLATRAD_ASSERT(m_nodes[static_cast<size_t>(ch)].cluster(), "a table cluster's children are clusters");
            asked.group_node.push_back(m_nodes[static_cast<size_t>(ch)].hnode);
        }
        asked.group_begin.push_back(static_cast<int32_t>(asked.group_node.size()));
    }
    const EnvelopeShares shares = cluster_visible_fractions(m_hierarchy, sides_at, asked, m_threads);
    FLATRAD_ASSERT(shares.groups == static_cast<size_t>(slots), "one group per slot");
    if (std::all_of(shares.whole_by_bin.begin(), shares.whole_by_bin.end(), [](double a) { return a == 1.0; })) return;
    // (The shares are held bin after bin, the clusters in this order: each
    // loop below reads K runs in step.)
    // Each table's face: the mean depth of what it shows along each bin,
    // from its centre, within its radius (0 where it shows nothing).
    const auto& dirs = bin_directions();
    std::vector<int32_t> measured(static_cast<size_t>(m_tables_count), -1);  // per table: its place in `clusters`
    for (size_t q = 0; q < clusters.size(); ++q)
        measured[static_cast<size_t>(m_nodes[static_cast<size_t>(clusters[q])].table)] = static_cast<int32_t>(q);
    m_face.resize(static_cast<size_t>(m_tables_count) * K);  // (every row written below)
    m_gamma.resize(static_cast<size_t>(slots) * K);
#pragma omp parallel num_threads(m_threads)
    {
#pragma omp for schedule(static)
        for (size_t q = 0; q < clusters.size(); ++q) {
            const Node& n = m_nodes[static_cast<size_t>(clusters[q])];
            float* face = &m_face[static_cast<size_t>(n.table) * K];
            for (int b = 0; b < K; ++b) {
                const double o = shares.front(q, b) - dot(n.center, dirs[static_cast<size_t>(b)]);
                face[b] = static_cast<float>(std::isfinite(o) ? std::clamp(o, -n.radius, n.radius) : 0.0);
            }
            // gamma = seen from outside the parent over seen from outside
            // itself (a leaf cluster has no table: its own share is 1; so
            // has a table cluster left unmeasured), at most 1 (the two are
            // measured on different lines, and what is seen from outside
            // the parent is seen from outside the child); 1 where the child
            // shows nothing along that bin anyway.
            for (int ch = n.child; ch < n.child + n.nchild; ++ch) {
                const Node& c = m_nodes[static_cast<size_t>(ch)];
                const size_t sl = static_cast<size_t>(slot[static_cast<size_t>(ch)]);
                float* g = &m_gamma[sl * K];
                const int32_t own = c.table >= 0 ? measured[static_cast<size_t>(c.table)] : -1;
                for (int b = 0; b < K; ++b) {
                    const double seen = shares.group(sl, b);
                    if (c.table < 0) {
                        g[b] = static_cast<float>(seen);
                        continue;
                    }
                    const double a = own >= 0 ? shares.whole(static_cast<size_t>(own), b) : 1.0;
                    g[b] = static_cast<float>(a > 0 ? std::min(1.0, seen / a) : 1.0);
                }
            }
        }
        // The tables left unmeasured face their centre.
#pragma omp for schedule(static)
        for (size_t t = 0; t < measured.size(); ++t)
            if (measured[t] < 0) std::fill_n(&m_face[t * K], K, 0.0f);
    }
    m_sensitivity_all = m_sensitivity;
    m_hidden_below.assign(static_cast<size_t>(m_tables_count), 0);
    m_gamma_slot = std::move(slot);
    // Children before parents: a table's sensitivity becomes the sum of
    // its children's (final) sensitivities, each times its gamma (at 10^6
    // segments 1.1 s on one thread).
    bottom_up(level_start, [this](size_t k) { sensitivity_with_gamma(k); });
}

// Node k's sensitivity (a table's) from its children's, each times its gamma,
// and whether some share below it is hidden (self_occlusion).
void HierarchicalSolver::sensitivity_with_gamma(size_t k) {
    const Node& n = m_nodes[k];
    if (n.table < 0) return;
    double sum[K];
    std::fill(sum, sum + K, 0.0);
    bool hidden = false;
    for (int ch = n.child; ch < n.child + n.nchild; ++ch) {
        const Node& c = m_nodes[static_cast<size_t>(ch)];
        const float* g = gamma(static_cast<size_t>(ch));
        if (g)
            for (int b = 0; b < K; ++b) hidden = hidden || g[b] < 1;
        if (c.table >= 0) {
            const double* sc = &m_sensitivity[static_cast<size_t>(c.table) * TW];
            for (int b = 0; b < K; ++b) sum[b] += (g ? g[b] : 1.0) * sc[b];
            hidden = hidden || m_hidden_below[static_cast<size_t>(c.table)];
        } else if (c.leaf_cluster) {
            double lobes[TW] = {};
            for (int sd = c.child; sd < c.child + c.nchild; ++sd)
                add_cosine_lobe(lobes, m_nodes[static_cast<size_t>(sd)].normal, m_nodes[static_cast<size_t>(sd)].length);
            for (int b = 0; b < K; ++b) sum[b] += (g ? g[b] : 1.0) * lobes[b];
        }
    }
    double* S = &m_sensitivity[static_cast<size_t>(n.table) * TW];
    for (int b = 0; b < K; ++b) S[b] = sum[b];
    m_hidden_below[static_cast<size_t>(n.table)] = hidden ? 1 : 0;
}

// Chains: which nodes are arcs of one convex loop, lit on the room's side
// (see Node::chain). Children first: an element is a chain when its wall is
// on a convex loop and it is lit on the room's side (oriented with the
// room on its left, it starts where its wall does in that direction); a
// cluster when every child is a chain of the same loop and their walls
// make one run of consecutive places in the loop's cycle (cyclic intervals
// that touch end to start, with at most one gap round the cycle).
// Only where few segments can block (a chain link carries its exact
// etendue unoccluded: chain_clear checks each of them).
void HierarchicalSolver::mark_chains() {
    m_chain_ends.assign(static_cast<size_t>(m_tables_count), ChainEnds{});
    m_chains = false;
    if (!m_opt.chain_links || !m_few_blockers || m_convex_loops.empty()) return;
    const size_t N = m_nodes.size();
    // Per node: its walls' run in the cycle, [start, start + count) modulo
    // the cycle's length.
    std::vector<int32_t> start(N, -1), count(N, 0), loop(N, -1);
    struct Run {
        int32_t start, count;
    };
    std::vector<Run> runs;
    for (size_t k = N; k-- > 0;) {
        Node& n = m_nodes[k];
        if (n.kind == Kind::Element) {
            const int32_t L = m_seg_loop[static_cast<size_t>(n.segment)];
            if (L < 0) continue;
            const ConvexLoop& cl = m_convex_loops[static_cast<size_t>(L)];
            const size_t m = cl.polygon.size(), p = static_cast<size_t>(m_seg_pos[static_cast<size_t>(n.segment)]);
            if (!(n.seg.a == (cl.orientation > 0 ? cl.polygon[p] : cl.polygon[(p + 1) % m]))) continue;  // lit outside
            n.chain = true;
            start[k] = static_cast<int32_t>(p);
            count[k] = 1;
            loop[k] = L;
            continue;
        }
        if (!n.cluster() || n.nchild <= 0) continue;
        const int32_t L = loop[static_cast<size_t>(n.child)];
        runs.clear();
        double length = 0;
        int64_t total = 0;
        bool chain = L >= 0;
        for (int c = n.child; c < n.child + n.nchild && chain; ++c) {
            const Node& child = m_nodes[static_cast<size_t>(c)];
            chain = child.chain && loop[static_cast<size_t>(c)] == L;
            runs.push_back({start[static_cast<size_t>(c)], count[static_cast<size_t>(c)]});
            total += count[static_cast<size_t>(c)];
            length += child.length;
        }
        if (!chain) continue;
        const int64_t m = static_cast<int64_t>(m_convex_loops[static_cast<size_t>(L)].polygon.size());
        if (total > m) continue;
        std::sort(runs.begin(), runs.end(), [](const Run& x, const Run& y) { return x.start < y.start; });
        int gaps = 0;
        int32_t first = runs[0].start;
        for (size_t i = 0; i < runs.size(); ++i) {
            const Run& next = runs[(i + 1) % runs.size()];
            if ((runs[i].start + runs[i].count) % m != next.start) {
                ++gaps;
                first = next.start;
            }
        }
        if (gaps > 1 || (gaps == 0 && total != m)) continue;
        n.chain = true;
        n.length = length;
        start[k] = first;
        count[k] = static_cast<int32_t>(total);
        loop[k] = L;
        if (n.table >= 0) {
            const ConvexLoop& cl = m_convex_loops[static_cast<size_t>(L)];
            const Vec2 from = cl.polygon[static_cast<size_t>(first)], to = cl.polygon[static_cast<size_t>((first + total) % m)];
            m_chain_ends[static_cast<size_t>(n.table)] = cl.orientation > 0 ? ChainEnds{from, to, L} : ChainEnds{to, from, L};
            m_chains = true;
        }
    }
}

// Whether no segment that may block meets a line between arcs a and b of
// one convex loop (a == b: an arc and itself). Such lines lie in the
// convex hull of the two arcs, which lies on the arc's side (the right) of
// the chord from a's start to b's end, and of the chord from b's start to
// a's end (each closes one of the two runs of the loop that hold both
// arcs): a segment strictly on the room's side of either chord (beyond
// orient's rounding) meets none of them.
bool HierarchicalSolver::chain_clear(const ChainEnds& a, const ChainEnds& b) const {
    auto left_of = [](Vec2 p, Vec2 q, const Segment& x) {
        const double chord = norm(q - p);
        auto strictly = [&](Vec2 v) {
            return orient(p, q, v) > 64 * std::numeric_limits<double>::epsilon() * chord * (norm(v - p) + chord);
        };
        return chord > 0 && strictly(x.a) && strictly(x.b);
    };
    for (const Segment& x : m_chain_blockers)
        if (!left_of(a.a, b.b, x) && !left_of(b.a, a.b, x)) return false;
    return true;
}

// Whether no segment that may block can lie in the shaft of a visibility
// query between nodes a and b, each query skipping its hierarchy node
// skip_* (its own segments): then the query would find its shaft empty and
// answer the unoccluded exchange, so it need not be asked (DESIGN.md §4:
// no visibility work where nothing can block). Only in scenes with few
// blockers (m_few_blockers), each checked against the capsule around the
// line between the centres with the larger radius: a query's stand-ins
// (multiscale.cpp's node_stand_in; an element is its own) are segments
// through a node's centre at most its radius long each way, so the shaft
// lies within it, and within the line's sweep by a square of that radius,
// which meets a blocker's box only where the line meets the box grown by
// the radius. A round room of 10^5 walls with a lamp inside asked 427 863
// queries, 387 569 of them finding nothing, each through the
// transmittance cache's lock and hash table.
bool HierarchicalSolver::nothing_between(const Node& a, int skip_a, const Node& b, int skip_b) const {
    if (!m_few_blockers || !m_opt.clear_shaft_shortcut) return false;
    auto skipped = [&](int h, int32_t pos) {
        if (h < 0) return false;
        const ClusterNode& c = m_hierarchy.node(h);
        return pos >= c.first && pos < c.first + c.count;
    };
    // The radius grown for rounding (the nodes' radii are computed from
    // their lengths and boxes, the stand-ins from their ends).
    const double R = std::max(a.radius, b.radius);
    const double scale = std::max({std::abs(a.center.x), std::abs(a.center.y), std::abs(b.center.x), std::abs(b.center.y), R});
    const double pad = R * (1 + 1e-9) + 1e-12 * scale;
    for (size_t k = 0; k < m_chain_blockers.size(); ++k) {
        const int32_t pos = m_chain_blocker_pos[k];
        if (skipped(skip_a, pos) || skipped(skip_b, pos)) continue;
        Box box;
        box.add(m_chain_blockers[k]);
        box.lo = box.lo - Vec2{pad, pad};
        box.hi = box.hi + Vec2{pad, pad};
        if (segment_meets_box(a.center, b.center, box)) return false;
    }
    return true;
}

// The ends of n's chain, oriented with the room on the left; false when n
// is not a chain (or a cluster without a table: no link ends there).
bool HierarchicalSolver::chain_ends(const Node& n, ChainEnds& out) const {
    if (!n.chain) return false;
    if (n.cluster()) {
        if (n.table < 0) return false;
        out = m_chain_ends[static_cast<size_t>(n.table)];
        return out.loop >= 0;
    }
    out = {n.seg.a, n.seg.b, m_seg_loop[static_cast<size_t>(n.segment)]};
    return true;
}

// The nodes a link to `node` really goes to: a hierarchy leaf stands for
// its sides.
void HierarchicalSolver::endpoints(int node, std::vector<int>& out) const {
    const Node& n = m_nodes[static_cast<size_t>(node)];
    if (n.leaf_cluster)
        for (int c = n.child; c < n.child + n.nchild; ++c) out.push_back(c);
    else
        out.push_back(node);
}

// The links that replace a cluster's self link: every ordered pair of its
// children's endpoints, and the self links of child clusters.
void HierarchicalSolver::self_links(int node, LinkVector& out) const {
    std::vector<int> ends;
    const Node& n = m_nodes[static_cast<size_t>(node)];
    if (n.leaf_cluster)
        endpoints(node, ends);
    else
        for (int c = n.child; c < n.child + n.nchild; ++c) endpoints(c, ends);
    for (int a : ends)
        for (int b : ends) {
            const Node& na = m_nodes[static_cast<size_t>(a)];
            const Node& nb = m_nodes[static_cast<size_t>(b)];
            if (a == b) {
                if (na.cluster()) {
                    out.push_back(link_between(a, a));
                    out.back().fresh = true;
                }
                continue;
            }
            if (!nb.can_send || (!na.cluster() && !nb.cluster() && na.segment == nb.segment)) continue;
            Link l;
            l.r = a;
            l.s = b;
            l.fresh = true;
            out.push_back(l);
        }
}

// Children links of l, splitting the receiver (split_r) or the sender.
void HierarchicalSolver::children_links(const Link& l, bool split_r, LinkVector& out) const {
    const int node = split_r ? l.r : l.s;
    const Node& n = m_nodes[static_cast<size_t>(node)];
    std::vector<int> ends;
    for (int c = n.child; c < n.child + n.nchild; ++c) endpoints(c, ends);
    for (int e : ends) {
        Link k;
        k.r = split_r ? e : l.r;
        k.s = split_r ? l.s : e;
        const Node& nr = m_nodes[static_cast<size_t>(k.r)];
        const Node& ns = m_nodes[static_cast<size_t>(k.s)];
        if (!ns.can_send || ns.sink()) continue;
        if (!nr.cluster() && !ns.cluster() && nr.segment == ns.segment) continue;
        // Halves of an element link lie in its shaft: an empty shaft stays empty.
        k.clear = l.clear && !nr.cluster() && !ns.cluster();
        k.fresh = true;
        k.box_pair = l.box_pair;  // (its ends are halves of l's: the same gap is likely)
        out.push_back(k);
    }
}

// Fills l's coefficient and estimates; false when r and s cannot exchange.
bool HierarchicalSolver::make_link(int r, int s, Link& l, VisibilityStats& st) const {
    const Node& nr = m_nodes[static_cast<size_t>(r)];
    const Node& ns = m_nodes[static_cast<size_t>(s)];
    if (r == s) {
        // A cluster's self link: carrying nothing itself, split when what
        // its members may exchange asks (link_error), unless the cluster is
        // a chain (an arc sees itself): a chain link, split only when its
        // error asks (refine).
        ChainEnds a;
        if (m_chains && nr.cluster() && chain_ends(nr, a) && chain_clear(a, a)) {
            double rounding = 0;
            const double et = chain_self_etendue(a.a, a.b, nr.length, rounding);
            l.uniform = true;
            l.coef = et / nr.length;
            l.vis_err = static_cast<float>(rounding / nr.length);
        }
        return true;
    }
    if ((ns.send_rooms & nr.recv_rooms) == 0) {  // a closed loop between them (solver/rooms.h)
        ++st.culled;
        return false;
    }
    if (!nr.cluster() && !ns.cluster()) {
        const double Fu = form_factor_unoccluded(nr.seg, ns.seg);
        if (!(Fu > 0)) {
            ++st.culled;
            return false;
        }
        l.coef = Fu;
        l.Fu = static_cast<float>(Fu);
        // The kernel's variation costs eight crossed strings; most element
        // links are kept whatever it is, so it starts as its bound
        // (kernel_variation) and is computed when a decision needs it.
        l.kvar = static_cast<float>(kernel_variation_bound(l.Fu));
        l.kvar_exact = false;
        if (!m_unblockable && !l.clear) {
            // Visibility is asked later, if the link survives its geometry
            // and its sender is bright enough (refine; resolve_visibility).
            defer_visibility(l, prior_transmittance(nr, ns), true);
            return true;
        }
        ++st.unoccluded;
        return true;
    }
    // Cluster links: point approximations at the centres.
    const Vec2 d = nr.center - ns.center;
    const double dist = norm(d);
    const double reach = nr.radius + ns.radius;
    // A side of an element whose line cuts the other node's box cannot be
    // treated as a point source or a point receiver; one with that box
    // wholly behind it exchanges nothing with it. The box is the one along
    // the cluster's segments (engine/oriented_box.h): an axis-aligned box
    // of a curved wall reaches past the tangents of the wall's elements
    // tens of segments away.
    auto straddles = [&](const Node& e, const Node& c) {
        if (e.cluster() || !c.cluster()) return false;
        const auto [lo, hi] = m_obox[static_cast<size_t>(c.hnode)].range_along(e.seg.a, e.normal);
        return lo < 0 && hi > 0;
    };
    auto in_front = [&](const Node& e, const Node& c) {
        if (e.cluster() || !c.cluster()) return true;
        return m_obox[static_cast<size_t>(c.hnode)].range_along(e.seg.a, e.normal).second > 0;
    };
    if (!in_front(nr, ns) || !in_front(ns, nr)) {
        ++st.culled;
        return false;
    }
    if (!(dist > reach) || straddles(nr, ns) || straddles(ns, nr)) {
        // Two arcs of one convex loop (neighbours along a curved wall,
        // where the point approximation never holds): a chain link, its
        // etendue exact, the sender's mean spread evenly on the receiver.
        ChainEnds a, b;
        if (m_chains && chain_ends(nr, a) && chain_ends(ns, b) && a.loop == b.loop && chain_clear(a, b)) {
            double rounding = 0;
            const double et = chain_etendue(a.a, a.b, b.a, b.b, rounding);
            l.uniform = true;
            l.coef = et / nr.length;
            l.vis_err = static_cast<float>(rounding / nr.length);
            ++st.unoccluded;
            return true;
        }
        l.unresolved = true;
        l.coef = 0;
        return true;
    }
    const Vec2 u = d / dist;  // from s to r
    const BinWeight sbin = bin_of(u);
    l.sk = static_cast<uint8_t>(sbin.k);
    l.st = static_cast<float>(sbin.t);
    l.ux = static_cast<float>(u.x);
    l.uy = static_cast<float>(u.y);
    // A cluster none of whose senders faces any point of r from where it
    // is sends nothing along the link; one none of whose sides faces back
    // receives nothing. Where every member faces every point of the other
    // end, the table's linear part is exact (directional.h).
    auto corners = [&](const Node& n) {
        if (n.cluster()) return m_obox[static_cast<size_t>(n.hnode)].corners();
        return std::array<Vec2, 4>{n.seg.a, n.seg.b, n.seg.a, n.seg.b};
    };
    const auto cs = corners(ns), cr = corners(nr);
    // Where every member faces u itself but not the whole spread (close
    // clusters: a wall's neighbour along a curve), the linear part is still
    // exact at u, and NormalCone::linear_departure bounds how far the table
    // leaves it over the spread of +-delta.
    const double delta = std::asin(std::min(1.0, reach / dist));
    if (ns.cluster()) {
        const NormalCone::Facing f = ns.send_cone.facing(cs, cr, u, delta);
        if (f.none) {
            ++st.culled;
            return false;
        }
        l.s_linear = (f.all || f.departure >= 0) && !hidden_below(ns);
        l.s_back = f.all ? 0.0f : static_cast<float>(std::max(0.0, f.departure));
    }
    if (nr.cluster()) {
        const NormalCone::Facing f = nr.recv_cone.facing(cr, cs, -u, delta);
        if (f.none) {
            ++st.culled;
            return false;
        }
        l.r_linear = (f.all || f.departure >= 0) && !hidden_below(nr);
        l.r_back = f.all ? 0.0f : static_cast<float>(std::max(0.0, f.departure));
    }
    l.coef = unoccluded_coef(nr, ns);
    if (m_unblockable) {
        ++st.unoccluded;
        return true;
    }
    // The transmittance is asked later, and only if the link survives its
    // geometry and its sender is bright enough (refine; resolve_visibility).
    defer_visibility(l, prior_transmittance(nr, ns), false);
    return true;
}

// The transmittance a link is given before the visibility module is asked
// (defer_visibility): blockers spread evenly at the scene's mean density
// kappa (layers of shadow per unit of depth, MultiscaleVisibility::
// layers_per_depth) let a line through a gap of length g with probability
// exp(-kappa g), g the free depth between the two nodes along the link
// (the nodes' own occlusion is their tables' visible shares). For an
// element, from its near end; for a cluster, from its box's mean half
// chord along the link on either side of its centre (the lines the query
// samples run between the stand-ins through the centres), plus, inside
// the box, the blockers that are not its members (boxes overlap):
// m_foreign_kappa over that half chord. An estimate, not a bound: the
// link's error counts any truth in [0, 1].
//
// On the 1000-segment forest at eps 5 the deferred cluster links'
// estimates, summed (weighted by the sender's highest value and the
// receiver's size), against their answers asked afterwards: from the
// boxes' extreme depths and no non-members, 42% above; with the
// non-members, 13-19% above; with the mean chords, 5% below. Element
// links' estimates matched their answers (0.154 against 0.155). Before
// each child took its own visible share (self_occlusion) the lit members
// were too dark and made up for the excess (docs/solver-history.md,
// "Twenty-fourth session"). Earlier, by kappa g, the deferred links' mean
// estimate against their truth: 0.84 / 0.78 below 0.4, 0.56 / 0.41 up to
// 1, 0.33 / 0.22 up to 1.8, 0.13 / 0.14 up to 3, 0.05 / 0.08 up to 4.7.
double HierarchicalSolver::prior_transmittance(const Node& r, const Node& s) const {
    if (!(m_kappa > 0)) return 1.0;
    const Vec2 d = r.center - s.center;
    const double dist = norm(d);
    if (!(dist > 0)) return 1.0;
    const Vec2 u = d / dist;
    // Each node's depth range along u from s's centre: a cluster's box
    // along its segments (engine/oriented_box.h), an element's ends.
    auto range = [&](const Node& n) {
        if (n.cluster()) return m_obox[static_cast<size_t>(n.hnode)].range_along(s.center, u);
        const double a = dot(n.seg.a - s.center, u), b = dot(n.seg.b - s.center, u);
        return std::make_pair(std::min(a, b), std::max(a, b));
    };
    const auto rr = range(r), rs = range(s);
    // A cluster's mean half chord along u: the box's area over twice its
    // width across u (the mean chord of a convex body over parallel lines
    // is its area over its width), at most half its depth along u. The
    // lines the query samples run through the centres, and most leave a
    // box slanted to u well before its far corner.
    auto half_chord = [&](const Node& n, std::pair<double, double> depths) {
        const OrientedBox& b = m_obox[static_cast<size_t>(n.hnode)];
        const auto [lo, hi] = b.range_along(n.center, rot90(u));
        const double area = (b.hi_u - b.lo_u) * (b.hi_v - b.lo_v), w = hi - lo;
        return w > 0 ? std::min(0.5 * (depths.second - depths.first), 0.5 * area / w) : 0.0;
    };
    const double hr = r.cluster() ? half_chord(r, rr) : 0.0, hs = s.cluster() ? half_chord(s, rs) : 0.0;
    const double near_r = r.cluster() ? dot(r.center - s.center, u) - hr : rr.first;
    const double near_s = s.cluster() ? hs : rs.second;
    const double gap = std::max(0.0, near_r - near_s);
    double depth = m_kappa * gap;
    if (!m_foreign_kappa.empty()) {
        if (r.cluster()) depth += m_foreign_kappa[static_cast<size_t>(r.hnode)] * hr;
        if (s.cluster()) depth += m_foreign_kappa[static_cast<size_t>(s.hnode)] * hs;
    }
    return std::exp(-depth);
}

// A cluster link's coefficient at tau = 1 (see Link). A cluster end is
// taken at its visible face along the link (face_offset, from
// self_occlusion), not at its centre: the members seen from the other end
// are those in front, and through a forest cluster several layers deep they
// lie well in front of the centre. (At the centres, the 1000-segment
// forest's lit trees, 1e-2 to 1 of exact radiosity, came out 0.3-4% low
// at eps 5, the error the relative L2 sees; at the faces within 0.5%.)
// The distance is kept to at least half the centres' (overlapping or
// touching nodes are split anyway: Link::unresolved).
double HierarchicalSolver::unoccluded_coef(const Node& nr, const Node& ns) const {
    const Vec2 d = nr.center - ns.center;
    const double dist = norm(d);
    const Vec2 u = d / dist;
    if (!nr.cluster()) {
        // Angle r subtends from the sender's centre.
        const Vec2 c = ns.center + u * face_offset(ns, u);
        const Vec2 a = nr.seg.a - c, b = nr.seg.b - c;
        return std::abs(std::atan2(cross(a, b), dot(a, b))) / nr.length;
    }
    if (!ns.cluster()) return 0.5 * ns.length * std::max(0.0, dot(ns.normal, u)) / std::max(0.5 * dist, dist - face_offset(nr, -u));
    return 1 / std::max(0.5 * dist, dist - face_offset(ns, u) - face_offset(nr, -u));
}

// The unoccluded kernel's variation over quarters of each side of an
// element link (relative to its F_u): catches ends-vs-middle variation
// that halves miss by symmetry. A sink receiver's own variation does not
// count (it absorbs all it gets, wherever on it). Eight crossed strings:
// computed once per link, not at every refinement round.
double HierarchicalSolver::kernel_variation(const Node& r, const Node& s, double Fu) const {
    double rv = 0, sv = 0;
    for (int q = 0; q < 4; ++q) {
        const Segment sq{lerp(s.seg.a, s.seg.b, q / 4.0), lerp(s.seg.a, s.seg.b, (q + 1) / 4.0)};
        sv += std::abs(form_factor_unoccluded(r.seg, sq) - 0.25 * Fu);
        if (!r.sink()) {
            const Segment rq{lerp(r.seg.a, r.seg.b, q / 4.0), lerp(r.seg.a, r.seg.b, (q + 1) / 4.0)};
            rv += 0.25 * std::abs(form_factor_unoccluded(rq, s.seg) - Fu);
        }
    }
    return std::max(rv, sv);
}

// Asks the visibility module for a pending link's visibility (an element
// link's occluded F, a cluster link's transmittance); false when nothing
// passes (the link is to be dropped).
bool HierarchicalSolver::resolve_visibility(Link& l, ExactWorkspace& ws, VisibilityStats& st) const {
    const Node& nr = m_nodes[static_cast<size_t>(l.r)];
    const Node& ns = m_nodes[static_cast<size_t>(l.s)];
    l.vis_pending = false;
    if (!nr.cluster() && !ns.cluster()) {
        // Nothing that may block near the shaft: the unoccluded F, as the
        // query would find (it skips the two ends' own segments, alone in
        // their leaves when they may block).
        if (nothing_between(nr, nr.hnode, ns, ns.hnode)) {
            ++st.unoccluded;
            l.coef = form_factor_unoccluded(nr.seg, ns.seg);
            l.tau = 1;
            l.vis_err = 0;
            l.clear = true;
            return l.coef > 0;
        }
        // Behind a closure screen of either end: closed. The region holds
        // the other end's whole segment (the query does not count it as a
        // blocker; the screen's proof did not count the one end's).
        auto segment_box = [&](const Node& n) {
            Box b;
            b.add(m_scene.segments[static_cast<size_t>(n.segment)].seg);
            return b;
        };
        if (behind_closure_screen(l.s, segment_box(nr), ws, st) || behind_closure_screen(l.r, segment_box(ns), ws, st)) {
            ++st.screened;
            l.coef = 0;
            return false;
        }
        const double Fu = form_factor_unoccluded(nr.seg, ns.seg);  // (make_link's)
        const MultiscaleResult m = element_exchange(l.r, l.s, Fu, ws, st);
        // Nothing in the shaft: nor in its halves'.
        l.clear = clear_answer(m.F, m.error_bound, Fu);
        if (!(m.F > 0) && m.error_bound == 0) {
            l.coef = 0;
            return false;
        }
        const Estimate F =
            within_bound(m.F, m.error_bound, m.estimate, Fu, [&] { return prior_transmittance(nr, ns) * Fu; });
        l.coef = F.value;
        l.tau = static_cast<float>(F.value / Fu);
        l.vis_err = F.bound;
        return true;
    }
    const TransmittanceResult t = link_transmittance(l.r, l.s, ws, st);
    const double tau_answer = t.tau, terr = t.error_bound;
    if (!(tau_answer > 0) && terr == 0) {
        l.coef = 0;
        l.tau = 0;
        return false;
    }
    const Estimate tau = within_bound(tau_answer, terr, t.estimate, 1.0, [&] { return prior_transmittance(nr, ns); });
    l.tau = static_cast<float>(tau.value);
    l.vis_err = tau.bound;
    l.Fu = 0;
    l.coef = unoccluded_coef(nr, ns) * tau.value;
    return true;
}

// F_rs between two elements with its bound (MultiscaleVisibility::
// form_factor at the visibility tolerance). The links r <- s and s <- r
// may share one query by reciprocity, L_r F_rs = L_s F_sr (on the
// 1000-segment forest at eps 12, 44 of the 432 element pairs asked were
// asked both ways, the room's facing walls among them at 1.4-2 ms a
// query). A pair is asked in one order whichever link asks (the answers
// must not depend on the threads' timing): the shorter element as the
// receiver (on a tie, the lower node), so that the tolerance on F holds
// both ways, the other way's F and bound being these times L_r / L_s <= 1.
// Only answers that cost work are kept for the other way (shared_pair_work):
// most pairs are asked once, and in a room of furniture most queries take
// microseconds, of the order of the map and its lock (kept for all: the
// room's 88 000 queries, 12% fewer, took 11% longer). A node's flag says
// that one of its pairs is kept; the map is read only when both ends have
// one. A flag or an entry not there yet (the other way asked at the same
// moment on another thread) costs the query again, the same answer; only
// the first kept answer's work is counted.
// Fu: F_rs unoccluded (the caller's).
MultiscaleResult HierarchicalSolver::element_exchange(int r, int s, double Fu, ExactWorkspace& ws,
                                                      VisibilityStats& st) const {
    const Node& nr = m_nodes[static_cast<size_t>(r)];
    const Node& ns = m_nodes[static_cast<size_t>(s)];
    if (!m_opt.share_element_pairs)
        return m_vis.form_factor(nr.seg, ns.seg, nr.segment, ns.segment, m_vis_eps, GammaRule::Bound, ws, st);
    const double Lr = nr.seg.length(), Ls = ns.seg.length();
    const bool as_asked = Lr < Ls || (Lr == Ls && r < s);
    const Node& ni = as_asked ? nr : ns;  // the query's receiver
    const Node& nj = as_asked ? ns : nr;
    const size_t i = static_cast<size_t>(as_asked ? r : s), j = static_cast<size_t>(as_asked ? s : r);
    const uint64_t key = (static_cast<uint64_t>(i) << 32) | static_cast<uint32_t>(j);
    auto flag = [&](size_t node) { return std::atomic_ref<uint8_t>(m_pair_kept[node]); };
    MultiscaleResult m;
    bool known = false;
    if (flag(i).load(std::memory_order_acquire) && flag(j).load(std::memory_order_acquire)) {
        std::shared_lock lock(m_pair_mutex);
        const auto it = m_pair_cache.find(key);
        if (it != m_pair_cache.end()) {
            m.F = it->second.F;
            m.error_bound = it->second.error_bound;
            m.estimate = it->second.estimate;
            known = true;
        }
    }
    if (!known) {
        VisibilityStats mine;
        m = m_vis.form_factor(ni.seg, nj.seg, ni.segment, nj.segment, m_vis_eps, GammaRule::Bound, ws, mine);
        const bool worth = mine.blockers >= shared_pair_work ||
                           mine.bounded + mine.banded + mine.opaque + mine.subshafts > 0;
        if (!worth) {
            st += mine;
        } else {
            bool first;
            {
                std::unique_lock lock(m_pair_mutex);
                first = m_pair_cache.emplace(key, PairEntry{m.F, m.error_bound, m.estimate}).second;
            }
            if (first) {
                st += mine;
                flag(i).store(1, std::memory_order_release);
                flag(j).store(1, std::memory_order_release);
            }
        }
    }
    if (as_asked) return m;
    // A clear shaft is clear both ways: the unoccluded F of this way, as
    // its own query would give it.
    if (m.error_bound == 0 && clear_answer(m.F, 0, form_factor_unoccluded(ni.seg, nj.seg))) {
        m.F = Fu;
        return m;
    }
    const double scale = ni.seg.length() / nj.seg.length();  // L_s / L_r, at most 1
    m.F *= scale;
    m.error_bound *= scale;
    m.estimate *= scale;
    return m;
}

// Transmittance (and its bound) for a cluster link between nodes r and s,
// cached: one query per pair of hierarchy nodes when both are clusters;
// with an element (or sink) at one end, per element and hierarchy node, the
// element being its own stand-in (multiscale.h), so that the halves of a
// patch each get their own shadow. A part of a patch takes its patch's
// answer when an earlier refinement wave found it (cached) and it is
// settled (see the shortcut below for why earlier): a clear (or closed) shaft
// from the whole patch is clear (closed) from any piece of it. It does not
// ask for the patch's answer only to learn that: in a crowded shaft the
// answer is partial, and asking cost a room's long walls a second query
// for each of their elements (the 1000-segment forest at eps 2: 24% of the
// visibility time, for the same links and errors; data/tube_bank.json 35%).
TransmittanceResult HierarchicalSolver::link_transmittance(int r, int s, ExactWorkspace& ws,
                                                           VisibilityStats& st) const {
    const Node& nr = m_nodes[static_cast<size_t>(r)];
    const Node& ns = m_nodes[static_cast<size_t>(s)];
    const auto skip = [&](int h) { return m_tau_skip[static_cast<size_t>(h)]; };
    // Nothing that may block near the shaft (the queries below skip the
    // same nodes): clear, without the cache.
    if (nothing_between(nr, skip(nr.hnode), ns, skip(ns.hnode))) {
        ++st.unoccluded;
        TransmittanceResult clear;
        clear.tau = 1;
        return clear;
    }
    auto answer = [](const TauEntry& t) {
        TransmittanceResult out;
        out.tau = t.tau;
        out.error_bound = t.error_bound;
        out.estimate = t.estimate;
        return out;
    };
    auto lookup = [&](uint64_t key) -> std::optional<TauEntry> {
        std::shared_lock lock(m_tau_mutex);
        const auto it = m_tau_cache.find(key);
        if (it == m_tau_cache.end()) return std::nullopt;
        return it->second;
    };
    // Two threads may compute one key at once: the same answer, the query
    // being a function of its arguments. The first stays, and only its
    // work is counted, so that the stats are those of one thread.
    auto cached = [&](uint64_t key, const auto& compute) {
        if (const auto known = lookup(key)) return answer(*known);
        VisibilityStats mine;
        const TransmittanceResult t = compute(mine);
        const TauEntry entry{t.tau, t.error_bound, t.estimate, m_wave};
        std::unique_lock lock(m_tau_mutex);
        if (m_tau_cache.emplace(key, entry).second) st += mine;
        return answer(entry);
    };
    if (nr.cluster() && ns.cluster()) {
        // Keyed and asked in one order, whichever link asks first: the two
        // orders may differ in the last bits, and the links must not
        // depend on which thread got there first.
        const int a = std::min(nr.hnode, ns.hnode), b = std::max(nr.hnode, ns.hnode);
        const uint64_t key = (static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b);
        return cached(key, [&](VisibilityStats& mine) {
            return m_vis.transmittance(a, b, skip(a), skip(b), m_vis_eps, GammaRule::Bound, ws, mine);
        });
    }
    const int e = nr.cluster() ? s : r;
    const Node& other = nr.cluster() ? nr : ns;
    auto key_of = [&](int node) {
        return (static_cast<uint64_t>(static_cast<uint32_t>(node) | 0x80000000u) << 32) |
               static_cast<uint32_t>(other.hnode);
    };
    const Node& ne = m_nodes[static_cast<size_t>(e)];
    const int root = ne.kind == Kind::Element ? m_patch_root[static_cast<size_t>(ne.patch)] : e;
    // Only an answer of an earlier wave: whether one of this wave is there
    // yet depends on the threads' timing, and the part's own query may
    // differ from it (a closed patch's piece may get a partial bound), so
    // taking it would make the links depend on that timing. Waves are
    // decided in order, so which earlier answers exist does not.
    if (root != e)
        if (const auto whole = lookup(key_of(root)))
            if (whole->wave < m_wave && whole->error_bound == 0 && (whole->tau == 0 || whole->tau >= 1 - 1e-12))
                return answer(*whole);
    return cached(key_of(e), [&](VisibilityStats& mine) {
        if (behind_closure_screen(e, cluster_target_region(other.hnode, ne.seg.midpoint()), ws, st)) {
            ++mine.screened;
            return TransmittanceResult{};  // closed, exactly
        }
        return m_vis.transmittance(ne.seg, skip(ne.hnode), other.hnode, skip(other.hnode), m_vis_eps, GammaRule::Bound,
                                   ws, mine);
    });
}

// The region a closure screen must cover for a link to hierarchy node h:
// the square around h's box centre circumscribing the circle through its
// corners (every stand-in of h lies in that circle: multiscale.cpp's
// node_stand_in, a cross-section through the centre no wider than the
// box's diagonal), with the box of h's skipped node (its segments are not
// blockers for the link, so none may stand on the near side of the
// screen).
Box HierarchicalSolver::cluster_target_region(int h, Vec2 from) const {
    const Box& box = m_hierarchy.node(h).box;
    const Vec2 c = box.center();
    // (node_stand_in keeps a cross-section at least 1e-12 of the distance
    // wide: a box smaller than that still gets a circle holding it.)
    const double r = std::max(0.5 * box.diagonal(), 2e-12 * distance(c, from));
    Box region;
    region.add(c - Vec2{r, r});
    region.add(c + Vec2{r, r});
    region.add(m_hierarchy.node(m_tau_skip[static_cast<size_t>(h)]).box);
    return region;
}

// Whether a closure screen of element e (visibility/closure_screen.h) shows
// every line from e to `region` blocked (region: every point the link's
// lines may reach, and every segment the link does not count as a
// blocker). The screen: e's own, in the direction bin of the region's
// centre (closure_screen_bins), made and proven on first use. A region the
// screen does not cover (too near, or too wide for it) is left to the
// link's own query.
bool HierarchicalSolver::behind_closure_screen(int e, const Box& region, ExactWorkspace& ws,
                                               VisibilityStats& st) const {
    const Node& ne = m_nodes[static_cast<size_t>(e)];
    if (ne.kind != Kind::Element || !std::isfinite(m_screen_depth) || region.empty()) return false;
    const Vec2 m = ne.seg.midpoint(), c = region.center();
    const Vec2 near{std::clamp(m.x, region.lo.x, region.hi.x), std::clamp(m.y, region.lo.y, region.hi.y)};
    const double bin = 2 * std::numbers::pi / closure_screen_bins;
    const double angle = std::atan2(c.y - m.y, c.x - m.x);  // in [-pi, pi]
    const int k = std::clamp(static_cast<int>(std::floor((angle + std::numbers::pi) / bin)), 0, closure_screen_bins - 1);
    const double centre = -std::numbers::pi + (k + 0.5) * bin;
    const Vec2 toward = m + Vec2{std::cos(centre), std::sin(centre)};  // the bin's middle direction
    for (size_t level = 0; level < closure_screen_depths.size(); ++level) {
        const double depth = closure_screen_depths[level] * m_screen_depth;
        // The region's nearest point to m is nearer than the screen: no use.
        if (!(distance(near, m) > depth)) continue;
        const auto screen = closure_screen(ne.seg, toward, depth, closure_screen_spread * depth);
        if (!screen || !screen_covers(*screen, ne.seg, region)) continue;
        const int64_t key = static_cast<int64_t>(e) * static_cast<int64_t>(closure_screen_depths.size()) +
                            static_cast<int64_t>(level);
        {
            std::shared_lock lock(m_screen_mutex);
            const auto it = m_screens.find(key);
            if (it != m_screens.end() && it->second[static_cast<size_t>(k)] != 0) {
                if (it->second[static_cast<size_t>(k)] == 1) return true;
                continue;  // not shown closed: a nearer screen may be
            }
        }
        // (Another thread may be proving the same screen: the same answer;
        // the first to store it counts its work, as link_transmittance does.)
        VisibilityStats mine;
        const bool closed = m_vis.shown_closed(ne.seg, m_tau_skip[static_cast<size_t>(ne.hnode)], *screen, ws, mine);
        std::unique_lock lock(m_screen_mutex);
        int8_t& known = m_screens[key][static_cast<size_t>(k)];
        if (known == 0) {
            known = closed ? 1 : 2;
            st += mine;
        }
        if (closed) return true;
    }
    return false;
}

// Whether every line between a link's two ends is shown blocked at once
// (visibility/box_closure.h), or all but lines carrying at most
// box_proof_share of `bar` (the link may then be dropped): from an
// element's lit side, or from anywhere in a cluster's box, to anywhere in
// the other end's cluster box, the segments of either end's skipped node
// not counted (link_transmittance's skips). Element pairs are left to
// their own query. The pair of sides whose proof failed for the link, or
// for the link it was split from, is proven first (Link::box_pair), and a
// failure leaves its own there.
bool HierarchicalSolver::shown_closed_whole(Link& l, double bar, ExactWorkspace& ws, VisibilityStats& st) const {
    const Node& nr = m_nodes[static_cast<size_t>(l.r)];
    const Node& ns = m_nodes[static_cast<size_t>(l.s)];
    const auto skip = [&](int h) { return m_tau_skip[static_cast<size_t>(h)]; };
    int pair = l.box_pair - 1;
    bool closed = false;
    // What the link may leave out (see box_proof_share): an exchange of
    // at most `budget` carries at most B_max(s) times it (no point of the
    // sender is brighter; a cluster's members' shares seen from outside,
    // self_occlusion, only lower that).
    const double bmax = m_Bmax[static_cast<size_t>(l.s)];
    const double budget = bmax > 0 ? box_proof_share * bar / bmax : 0.0;
    if (nr.cluster() && ns.cluster()) {
        closed = m_vis.boxes_shown_closed(ns.hnode, skip(ns.hnode), nr.hnode, skip(nr.hnode), ws, st, pair, budget);
    } else if (nr.cluster() || ns.cluster()) {
        const Node& e = nr.cluster() ? ns : nr;
        const Node& c = nr.cluster() ? nr : ns;
        closed = m_vis.box_shown_closed(e.seg, skip(e.hnode), c.hnode, skip(c.hnode), ws, st, pair, budget);
    }
    l.box_pair = static_cast<uint8_t>(pair + 1);  // (pairs are 0..15)
    return closed;
}

// Creates the two halves of element `node` if it has none; returns the first.
int HierarchicalSolver::split_element(int node) {
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
        c.radius = 0.5 * c.length;
        c.center = c.seg.midpoint();
        c.child = -1;
        c.nchild = 0;
        c.parent = node;
        c.depth = static_cast<int16_t>(parent.depth + 1);
        m_nodes.push_back(c);
        for (auto& B : m_B) B.push_back(B[static_cast<size_t>(node)]);
        for (auto& H : m_H) H.push_back(H[static_cast<size_t>(node)]);
    }
    m_nodes[static_cast<size_t>(node)].child = first;
    m_nodes[static_cast<size_t>(node)].nchild = 2;
    return first;
}

// Pull: per node the length-weighted mean of `leaf_value` over element
// leaves (Bn), per cluster table the exitance I(phi_k).
// Zeroes a per-node array and the per-table array that goes with it: all
// of them, or only a part's nodes and their tables (the rest left as it
// was, so that a small part costs what it holds).
void HierarchicalSolver::clear_scratch(std::vector<double>& per_node, TableArray& tables,
                                       const Part* part) const {
    const size_t N = m_nodes.size();
    FLATRAD_ASSERT(tables.tables() == m_tables_count, "tables laid out before use");
    if (!part || per_node.size() != N) {
        per_node.assign(N, 0.0);
        tables.clear();
    }
    if (part)
        for (int k : part->nodes) {
            per_node[static_cast<size_t>(k)] = 0;
            if (m_nodes[static_cast<size_t>(k)].table >= 0) tables.clear(m_nodes[static_cast<size_t>(k)].table);
        }
}

// With a part, only its nodes are zeroed and visited (the rest of Bn and I
// is left as it was).
void HierarchicalSolver::pull_tables(const double* leaf_value, std::vector<double>& Bn,
                                     TableArray& I, const Part* part) const {
    const size_t N = m_nodes.size();
    FLATRAD_ASSERT(m_op.size() == N, "nodes indexed for the operator (collect_leaves)");
    clear_scratch(Bn, I, part);
    if (!part && !m_sched.subtrees.empty()) {
        // The subtrees side by side, each bottom-up as below but for its
        // top node's share of the table above; then, bottom-up, the nodes
        // above them and those shares. Every table gets the same sums in
        // the same order as on one thread: a table's adds come from its
        // node's children, all in one subtree, or all above the subtrees
        // or frontier nodes, in descending order either way.
        const long S = static_cast<long>(m_sched.subtrees.size());
#pragma omp parallel for num_threads(m_threads) schedule(dynamic, 1)
        for (long t = 0; t < S; ++t) {
            const std::vector<int>& nodes = m_sched.subtrees[static_cast<size_t>(t)];
            for (size_t q = nodes.size(); q-- > 0;)
                pull_node(static_cast<size_t>(nodes[q]), leaf_value, Bn, I, nullptr, true, q != 0);
        }
        for (size_t q = m_sched.top.size(); q-- > 0;) {
            const size_t k = static_cast<size_t>(m_sched.top[q]);
            pull_node(k, leaf_value, Bn, I, nullptr, !m_sched.frontier[k], true);
        }
        return;
    }
    const size_t count = part ? part->nodes.size() : N;
    for (size_t q = count; q-- > 0;) pull_node(part ? static_cast<size_t>(part->nodes[q]) : q, leaf_value, Bn, I, part, true, true);
}

// pull_tables' work at node k: its own value and table (own), and its share
// of the table above (up).
void HierarchicalSolver::pull_node(size_t k, const double* leaf_value, std::vector<double>& Bn, TableArray& I,
                                   const Part* part, bool own, bool up) const {
    const OpNode& n = m_op[k];
    if (own) {
        if (n.kind == Kind::Element) {
            if (n.child < 0) {
                Bn[k] = n.leaf >= 0 ? leaf_value[static_cast<size_t>(n.leaf)] : 0.0;
            } else {
                const size_t a = static_cast<size_t>(n.child);
                Bn[k] = 0.5 * (Bn[a] + Bn[a + 1]);  // halves of equal length
            }
        }
        if (n.chain && n.kind == Kind::Cluster && m_chains) {
            // A chain's mean (chain links send it): its length is its elements'.
            double power = 0;
            for (int c = n.child; c < n.child + n.nchild; ++c)
                power += m_op[static_cast<size_t>(c)].length * Bn[static_cast<size_t>(c)];
            Bn[k] = power / n.length;
        }
    }
    if (!up || n.kind != Kind::Cluster || n.up_table < 0 || !in_part(part, static_cast<int>(k), n.parent)) return;
    // What leaves the parent from this node: its share seen from outside
    // the parent (gamma, self_occlusion).
    const float* g = gamma(k);
    if (n.table >= 0) {
        I.sum_child(n.up_table, n.table, g);
    } else if (n.leaf_cluster) {
        double* samples = I.samples(n.up_table);
        double* linear = I.linear(n.up_table);
        for (int c = n.child; c < n.child + n.nchild; ++c) {
            const OpNode& side = m_op[static_cast<size_t>(c)];
            if (side.kind != Kind::Element) continue;
            const double w = 0.5 * side.length * Bn[static_cast<size_t>(c)];
            if (w == 0) continue;
            if (g)
                add_cosine_lobe(samples, linear, side.normal, w, g);
            else
                add_cosine_lobe(samples, linear, side.normal, w);
        }
    }
}

// Estimated error in the power the link transports, with the sender values
// of the current solution (Bn per node, I per cluster table), and which
// side's approximations make most of it (split_r: the receiver's).
LinkError HierarchicalSolver::link_error(const Link& l, const std::vector<double>& Bn, const TableArray& I,
                                         bool geometry_only) const {
    const Node& r = m_nodes[static_cast<size_t>(l.r)];
    const Node& s = m_nodes[static_cast<size_t>(l.s)];
    const double size_r = size_of(r);
    const double size_s = size_of(s);
    if (l.uniform) {
        // A chain link carries the sender's mean at the exact etendue: the
        // power it moves is right for an even sender, and at most all of it
        // (the etendue times the sender's highest value, rounding included)
        // lands in the wrong place on the receiver or is missed.
        return {(l.coef + l.vis_err) * r.length * m_Bmax[static_cast<size_t>(l.s)], size_r >= size_s};
    }
    if (l.r == l.s) {
        // A cluster's self link (not a chain's): the light its members
        // exchange, of which it carries none until split; at most all the
        // power they send, B_max(s) L(s): an unresolved link's bound (below)
        // with both ends the same node, and kept unsplit on the same terms.
        // (Until the fortieth session every self link was split, whatever
        // its light: a forest's dark clusters each left their children's
        // links, carrying nothing, two per cluster down to the segments.
        // The 10^6 forest at eps 10 keeps 1.14 M links instead of 3.51 M.)
        if (!self_link_kept_if_faint(l)) return {std::numeric_limits<double>::infinity(), true};
        const double lost = m_Bmax[static_cast<size_t>(l.s)] * m_Lsum[static_cast<size_t>(l.s)];
        if (!(lost > 0)) return {};
        return {lost / unresolved_share, true};
    }
    if (!r.cluster() && !s.cluster()) {
        const double power = Bn[static_cast<size_t>(l.s)] * r.length;
        if (!(power > 0)) return {};
        // Kernel variation over quarters of each side: catches ends-vs-
        // middle variation that halves miss by symmetry (kernel_variation,
        // or its bound until refine needs it exact).
        const double kvar = l.kvar;
        // Geometry alone (visibility not asked yet): a lower bound (with
        // the kernel variation exact).
        if (geometry_only) return {power * kvar, size_r >= size_s};
        // A partly hidden sender may put a shadow boundary anywhere on the
        // receiver; a sink absorbs all it gets, wherever on it, so there
        // only the accuracy of F itself counts. The shadow boundary may
        // also cross the sender, which sends its mean: its brightest part
        // may be the one in view (a shelf's top lit beside a book standing
        // on it, dark underneath), so that share is counted at the
        // sender's highest leaf value. On data/furnished_room.json the
        // solution's energy balance at eps 1e-3 went from 1.3e-3 to 1.0e-3
        // for 0.5% more links; forests did not change.
        const double occlusion = r.sink() ? 0.0 : std::max(0.0, std::min<double>(l.coef, l.Fu - l.coef));
        double err = power * (kvar + l.vis_err) + m_Bmax[static_cast<size_t>(l.s)] * r.length * occlusion;
        // The link spreads the sender's mean, not its halves' values (at
        // most F_u of them where the visibility is not known yet).
        if (s.child >= 0) {
            const size_t a = static_cast<size_t>(s.child);
            err += r.length * (l.vis_pending ? static_cast<double>(l.Fu) : l.coef) * 0.5 * std::abs(Bn[a] - Bn[a + 1]);
        }
        return {err, size_r >= size_s};
    }
    if (l.unresolved) {
        // Overlapping nodes (a cluster at one end at least): no point
        // approximation holds; the link carries nothing, and is split (the
        // larger side) when what it may leave out is above its share of the
        // bar (see unresolved_share). Nothing below is read for it.
        const double lost = m_Bmax[static_cast<size_t>(l.s)] *
                            std::min(m_Lsum[static_cast<size_t>(l.s)], m_Lsum[static_cast<size_t>(l.r)]);
        if (!(lost > 0)) return {};
        return {m_opt.faint_overlaps_kept ? lost / unresolved_share : std::numeric_limits<double>::infinity(),
                size_r >= size_s};
    }
    // Cluster links: the power carried, unoccluded, and its uncertainty.
    // A linear read (every member faces u) is exact at the centres'
    // direction u. Where members may turn away over the spread below, the
    // link's *_back bounds what that adds (make_link). Over the nodes'
    // extent the directions spread by +-delta, where f . u' = (f . u) cos t + (f .
    // u_perp) sin t. The link reads it at the centres, a midpoint rule: the
    // first-order term cancels over a node symmetric about its centre, and
    // what asymmetry leaves is of the order of the point approximation's
    // own rho / d (counted below). What remains is the second order,
    // (f . u) delta^2 / 2 + |f . u_perp| delta^3 / 6. (Counting the first
    // order |f . u_perp| delta as well made a round room of 1000 walls and
    // a lamp keep 62 000 links instead of 39 000, for the same error
    // against exact: relative L2 1.17e-3 and 1.23e-3; default.json 8.3e-4
    // and 9.1e-4.)
    const double delta_lin = l.s_linear || l.r_linear ? std::asin(std::min(1.0, (r.radius + s.radius) / norm(r.center - s.center))) : 0.0;
    auto linear_variation = [&](const double* linear, Vec2 dir) {
        return std::abs(read_linear_part(linear, rot90(dir))) * delta_lin * delta_lin * delta_lin / 6 +
               read_linear_part(linear, dir) * 0.5 * delta_lin * delta_lin;
    };
    double v = 0, v_err = 0;
    if (s.cluster()) {
        if (l.s_linear) {
            const double* lin = I.linear(s.table);
            v = read_linear_part(lin, l.u());
            v_err = linear_variation(lin, l.u()) + std::hypot(lin[0], lin[1]) * l.s_back;
        } else {
            const double* t = I.samples(s.table);
            v = interpolate(t, l.sbin());
            v_err = interpolation_error(t, l.sbin());
        }
    } else {
        v = Bn[static_cast<size_t>(l.s)];
    }
    const double dist = norm(r.center - s.center);
    // The point approximation reads each table at one direction; over the
    // nodes' extent the directions spread by +-delta, where a grazing lobe
    // may be 0 at the centre's direction and not next to it: the table's
    // highest value over the spread (and the two samples around it).
    const double delta = std::min(std::numbers::pi, (r.radius + s.radius) / dist);
    auto highest = [&](const double* t, BinWeight b) {
        const double h = 2 * std::numbers::pi / K, x = b.k + b.t;
        int k0 = static_cast<int>(std::floor(x - delta / h)), k1 = static_cast<int>(std::ceil(x + delta / h));
        if (k1 - k0 >= K) k1 = k0 + K - 1;
        double hi = 0;
        for (int k = k0; k <= k1; ++k) hi = std::max(hi, t[((k % K) + K) % K]);
        return hi;
    };
    const double v_hi = !s.cluster() ? v : l.s_linear ? v + v_err : highest(I.samples(s.table), l.sbin());
    if (!(v_hi > 0)) return {};
    double sens = r.length, sens_err = 0, sens_hi = r.length;
    if (r.cluster()) {
        const double* t = &m_sensitivity[static_cast<size_t>(r.table) * TW];
        if (l.r_linear) {
            sens = read_linear(t, -l.u());
            sens_err = linear_variation(t + K, -l.u()) + std::hypot(t[K], t[K + 1]) * l.r_back;
            sens_hi = sens + sens_err;
        } else {
            sens = interpolate(t, l.rbin());
            sens_err = interpolation_error(t, l.rbin());
            sens_hi = highest(t, l.rbin());
        }
    }
    const double tau = l.tau;
    // The unoccluded coefficient (kept in Fu while the visibility is not known).
    const double coef_u = l.vis_pending ? static_cast<double>(l.Fu) : tau > 0 ? l.coef / tau : 0;
    // The coefficient's own geometry at the highest reading (a cluster
    // receiver or sender: 1 / d; an element's angle or cosine: its value
    // when positive, else the bound L / d).
    const double coef_hi = coef_u > 0 ? coef_u : (r.cluster() ? 1 / dist : r.length / dist);
    const double unocc = coef_hi * v * sens;
    // A reading of 0 at the centre's direction (a grazing lobe, just past
    // its kink) says the link carries nothing, while over the spread it
    // may not: then the highest value over the spread is what may be
    // missed, in power at full transmittance. (Nonzero readings vary
    // smoothly enough that the relative terms below cover them; counting
    // the spread for every link as well tripled the links in a round room
    // for no gain in error against time.)
    const double spread_s = v > 0 ? 0.0 : coef_hi * v_hi * std::max(sens, sens_hi);
    const double spread_r = sens > 0 ? 0.0 : coef_hi * std::max(v, v_hi) * sens_hi;
    // Relative errors by side:
    //  - point approximation: a node of radius rho seen from distance d
    //    changes direction and distance by ~rho / d over its extent (twice
    //    that for the cosines at both ends); an element receiver's angle is
    //    exact, only the sender's exitance varies over it (rho_r / d);
    //  - the tables' interpolation (directional model);
    //  - occlusion inside a cluster: the tables scale the members' lobes by
    //    the share seen from outside (self_occlusion), a mean over the
    //    cluster that assumes its hidden members send like its visible
    //    ones, and that sees them from far along the link's direction, not
    //    from its other end. What that may misplace grows with the layers:
    //    the lobes' sum N(psi) = sum L cos+ beyond the box's own width
    //    across psi is surely hidden (more than one layer deep), and that
    //    share of the power is counted (an estimate, not a bound). Counting
    //    half of it, or none, gave more error for the time on the
    //    1000-segment forest (eps 4: 1.0e-2 / 1.3e-2 against 8.9e-3, at the
    //    same time); counting twice as much gave no less.
    const Vec2 u = (r.center - s.center) / dist;
    auto layered = [&](const Node& c, BinWeight b) {
        const std::vector<double>& all = m_sensitivity_all.empty() ? m_sensitivity : m_sensitivity_all;
        const double n = interpolate(&all[static_cast<size_t>(c.table) * TW], b);
        const Vec2 e = m_hierarchy.node(c.hnode).box.extent();
        const double width = std::abs(e.x * u.y) + std::abs(e.y * u.x);
        return n > 0 ? std::max(0.0, 1 - width / n) : 0.0;
    };
    double rel_r = 0, rel_s = 0;
    if (r.cluster())
        rel_r = 2 * r.radius / dist + layered(r, l.rbin()) + (sens > 0 ? sens_err / sens : 0);
    else
        rel_r = r.radius / dist;
    if (s.cluster())
        // (A sender read 0 at the centres' direction carries nothing at
        // it: its reading over the spread is spread_s, and v_err / v would
        // be 0 / 0.)
        rel_s = 2 * s.radius / dist + layered(s, l.sbin()) + (v > 0 ? v_err / v : 0);
    else
        rel_s = 2 * s.radius / dist;
    // The part no transmittance changes (unocc and the relative terms do
    // not depend on tau): a lower bound of the error below, for a link
    // whose transmittance is not known yet.
    if (geometry_only) return {unocc * (rel_r + rel_s), rel_r >= rel_s};
    // Visibility: a partly hidden link may put a shadow boundary anywhere,
    // and the transmittance is known to its bound. Splitting the larger
    // side narrows the shaft most.
    const double vis = std::min(tau, 1 - tau) + l.vis_err;
    const double seen = std::min(1.0, tau + l.vis_err);
    // A cluster end that a long blocker not its own runs through: its
    // members may see anything of the other end (intruded_box_share),
    // counted on its side.
    if (r.cluster() && box_intruded(r.hnode)) rel_r += std::max(tau, 1 - tau) / intruded_box_share;
    if (s.cluster() && box_intruded(s.hnode)) rel_s += std::max(tau, 1 - tau) / intruded_box_share;
    const double err = unocc * (rel_r + rel_s + vis) + seen * (spread_r + spread_s);
    // (A NaN here is compared false against every bar: such a link was
    // neither split nor deferred, but asked, whatever its error.)
    FLATRAD_ASSERT(!std::isnan(err), "a cluster link's error is a number");
    const bool split_r = unocc * rel_r + seen * spread_r + (size_r >= size_s ? unocc * vis : 0) >=
                         unocc * rel_s + seen * spread_s + (size_r < size_s ? unocc * vis : 0);
    return {err, split_r};
}

std::vector<double> HierarchicalSolver::leaf_guess() const {
    // Before any solve: every patch at E + rho B_bar, B_bar the radiosity of
    // a closed room with the scene's emission and absorption (a guess that
    // errs high in open scenes, so refinement errs fine).
    // (Over the rooms that may hold light: a dark room's absorption would
    // lower the lit rooms' B_bar.)
    const std::vector<char> dark = dark_patches();
    auto in_dark_room = [&](int node) {
        const int patch = m_nodes[static_cast<size_t>(node)].patch;
        return static_cast<size_t>(patch) < dark.size() && dark[static_cast<size_t>(patch)];
    };
    CompensatedSum em, ab;
    for (size_t i = 0; i < static_cast<size_t>(m_element_leaves); ++i) {
        const int node = m_leaves[i];
        if (in_dark_room(node)) continue;
        double e = 0, a = 0;
        for (int c = 0; c < m_C; ++c) {
            e = std::max(e, emission(node, c));
            a = std::max(a, 1 - rho(node, c));
        }
        em.add(m_nodes[static_cast<size_t>(node)].length * e);
        ab.add(m_nodes[static_cast<size_t>(node)].length * a);
    }
    const double bbar = ab.value() > 0 ? em.value() / ab.value() : 0;
    std::vector<double> g(static_cast<size_t>(m_element_leaves));
    for (size_t i = 0; i < g.size(); ++i) {
        const int node = m_leaves[i];
        const bool dark_leaf = in_dark_room(node);
        double b = 0;
        for (int c = 0; c < m_C; ++c) b = std::max(b, emission(node, c) + (dark_leaf ? 0.0 : rho(node, c) * bbar));
        g[i] = b;
    }
    return g;
}

// Per scene patch, whether its room (solver/rooms.h) holds no emitting
// side: light cannot cross a room's walls, so no light reaches it. Where an
// emitting side's room is unknown, any room may hold it: none is dark.
std::vector<char> HierarchicalSolver::dark_patches() const {
    const size_t P = m_scene.patches.size();
    std::vector<char> dark;
    if (!m_opt.dark_rooms_start_dark) return dark;
    auto side_of = [&](const Patch& p) { return 2 * static_cast<size_t>(p.segment) + (p.lit_left ? 0 : 1); };
    std::vector<int> lit_rooms;
    for (const Patch& p : m_scene.patches) {
        if (!emits(m_scene.materials[static_cast<size_t>(p.material)])) continue;
        const int room = m_side_room[side_of(p)];
        if (room == room_unknown) return dark;
        lit_rooms.push_back(room);
    }
    std::sort(lit_rooms.begin(), lit_rooms.end());
    dark.assign(P, 0);
    for (size_t q = 0; q < P; ++q) {
        const int room = m_side_room[side_of(m_scene.patches[q])];
        dark[q] = room != room_unknown && !std::binary_search(lit_rooms.begin(), lit_rooms.end(), room);
    }
    return dark;
}

// Leaf values for the refinement's error estimates. A side that sends
// nothing made a sender (an inert patch, or a sink as a patch of its own:
// m_inert_sends) carries 0 in the solve, but its links are part of the
// closed rows it is seen from: an error in their F moves the deficit given
// back to a row, and with it light of about the row's surroundings'
// radiosity. So its leaves take the scene's mean leaf value (by length)
// here, and its links are refined as if it shone at that. (Refined at its
// own 0, a black plate's links stayed as coarse as its first link, and the
// rows closed to their errors: in a room at reflectance 0.99, 8.8e-2
// relative L2 against exact at the default eps, against 1.2e-2 with those
// rows open and 1.1e-3 so.)
std::vector<double> HierarchicalSolver::refinement_values(std::vector<double> b) const {
    if (!m_made_senders) return b;
    CompensatedSum num, den;
    for (size_t i = 0; i < b.size(); ++i) {
        const Node& n = m_nodes[static_cast<size_t>(m_leaves[i])];
        if (m_inert_sends[static_cast<size_t>(n.patch)]) continue;
        num.add(n.length * b[i]);
        den.add(n.length);
    }
    const double mean = den.value() > 0 ? num.value() / den.value() : 0.0;
    for (size_t i = 0; i < b.size(); ++i)
        if (m_inert_sends[static_cast<size_t>(m_nodes[static_cast<size_t>(m_leaves[i])].patch)]) b[i] = mean;
    return b;
}

// One refinement round against leaf values `leaf_bmax` (max over channels),
// with eps_abs from `exitant_power` where that is >= 0 (else from the
// leaf values); returns whether a link split.
bool HierarchicalSolver::refine(const std::vector<double>& leaf_bmax, double exitant_power) {
    // The operator's scratch (no solve runs during a refinement): a fresh
    // table array per round was hundreds of MB of new pages at 10^6 walls.
    std::vector<double>& Bn = m_Bn;
    TableArray& I = m_I;
    I.reset_full(m_tables_count);  // new links may read any table's samples (pull_tables zeroes them)
    pull_tables(leaf_bmax.data(), Bn, I);
    {
        // The highest leaf value below each node (chain links' error, an
        // element sender's bright part behind a shadow boundary).
        // The total length of the leaves below (unresolved links' bound).
        m_Bmax.assign(m_nodes.size(), 0.0);
        m_Lsum.assign(m_nodes.size(), 0.0);
        for (size_t k = m_nodes.size(); k-- > 0;) {
            const OpNode& n = m_op[k];
            if (n.kind == Kind::Element && n.child < 0) m_Bmax[k] = Bn[k];
            if (n.kind != Kind::Cluster && n.child < 0) m_Lsum[k] = n.length;
            if (n.parent >= 0) {
                const size_t p = static_cast<size_t>(n.parent);
                m_Bmax[p] = std::max(m_Bmax[p], m_Bmax[k]);
                m_Lsum[p] += m_Lsum[k];
            }
        }
    }
    // eps_abs = eps * W / N (see the header).
    CompensatedSum W;
    long patches = 0;
    for (size_t k = 0; k < m_nodes.size(); ++k) {
        const Node& n = m_nodes[k];
        // (The scene's patches: not the sinks made senders.)
        if (n.kind == Kind::Element && n.depth == 0 && static_cast<size_t>(n.patch) < m_scene.patches.size()) {
            W.add(n.length * Bn[k]);
            ++patches;
        }
    }
    const double eps_abs = m_opt.eps * (exitant_power >= 0 ? exitant_power : W.value()) / std::max(1L, patches);
    if (!(eps_abs > 0)) return false;
    // Hysteresis: a round splits only if some link's error exceeds eps_abs
    // (so that every link ends within it), and then, after the first solve,
    // it splits every link above split_margin x eps_abs. Links just under
    // the bar are not left to cross it when the next solve changes B by a
    // percent, which cost a whole extra round (a solve and a refinement,
    // 2.4 s of 16 at 10^6 walls) for 3 links of 8.7 million.
    const double split_at = (m_solved ? split_margin : 1.0) * eps_abs;

    // The first round starts from one link: room for 16 per segment (round
    // rooms keep 9 to 14), reserved address space as for the nodes
    // (build_tree); beyond it the links grow as usual. (Later rounds keep
    // the capacity sort_links left.)
    const size_t expected = 16 * m_scene.segments.size() + 1024;
    if (m_links.size() <= 1 && m_links.capacity() < expected) m_links.reserve(expected);
    // The links still to decide are always the tail m_links[tail, end):
    // every link at first, then the children made by the last wave. After
    // each wave the tail drops what was split or dropped (in order, so the
    // survivors of sort_links' sorted prefix stay sorted) before the
    // children are appended: links never pile up dead (a round room of 10^6
    // walls makes twice as many links as it keeps).
    std::vector<char>& decision = m_refine_decision;  // kept between rounds: its pages are written once
    size_t tail = 0;
    bool exceeded = false;  // some link's error is above eps_abs (this round splits)
    const size_t prefix = std::min(m_sorted_links, m_links.size());
    m_sorted_links = 0;  // set by the first wave, which holds the whole prefix
    bool first_wave = true, any = false;
    while (tail < m_links.size()) {
        // 1. Decide, in parallel.
        // A link whose visibility is pending is split on its geometry alone
        // when that exceeds eps_abs (a lower bound of its error whatever the
        // visibility is); only the others ask the visibility module (most
        // links of an occluded scene are split anyway).
        const long nw = static_cast<long>(m_links.size() - tail);
        decision.assign(static_cast<size_t>(nw), 0);
        const auto t_decide = Clock::now();
        long resolved = 0, computed = 0;
        ++m_wave;  // (link_transmittance: answers of this wave are not shortcuts within it)
        m_pair_kept.resize(m_nodes.size(), 0);  // (element_exchange: the nodes split since)
#pragma omp parallel num_threads(m_threads) if (nw > parallel_min_work)
        {
            ExactWorkspace ws;
            VisibilityStats local;
            long asked = 0, made = 0;
            bool above = false;
            // Small chunks: a wave's queries cluster (the children of one
            // split link sit side by side, often all in one crowded shaft),
            // and late waves hold a few hundred links, a few dozen of them
            // queries of 0.1-0.2 ms. With chunks of 64 one thread took most
            // of them while the other waited: the 1000-segment forest at eps
            // 5 took 0.104 / 0.118 / 0.104 s (medians of 11) against 0.094 /
            // 0.098 / 0.099 s with chunks of 4 (1: the same as 4).
#pragma omp for schedule(dynamic, 4)
            for (long k = 0; k < nw; ++k) {
                Link& l = m_links[tail + static_cast<size_t>(k)];
                const Node& r = m_nodes[static_cast<size_t>(l.r)];
                const Node& s = m_nodes[static_cast<size_t>(l.s)];
                // A link made by the last wave's splits: its geometry first
                // (~1 us; here rather than in a pass of its own between the
                // waves, so that it runs on the team with the decisions,
                // where most waves were too small to be worth waking it).
                if (l.fresh) {
                    l.fresh = false;
                    ++made;
                    if (!make_link(l.r, l.s, l, local)) {
                        decision[static_cast<size_t>(k)] = 4;  // cannot exchange: dropped
                        continue;
                    }
                }
                if (l.r == l.s && !l.uniform) {
                    if (self_link_kept_if_faint(l)) {
                        const LinkError e = link_error(l, Bn, I, false);
                        if (e.err > eps_abs) above = true;
                        if (e.err > split_at) decision[static_cast<size_t>(k)] = 3;
                    } else {
                        decision[static_cast<size_t>(k)] = 3;
                    }
                    continue;
                }
                const bool can_r = r.cluster() || (r.kind == Kind::Element && r.depth < m_opt.max_depth);
                const bool can_s = s.cluster() || (s.kind == Kind::Element && s.depth < m_opt.max_depth);
                // The error with an element link's kernel variation still at
                // its bound is an upper bound of the error with it exact:
                // the exact one is computed only where the bound would split
                // (the same decisions as computing it with the link).
                auto error = [&](bool geometry_only) {
                    LinkError e = link_error(l, Bn, I, geometry_only);
                    if (e.err > split_at && !l.kvar_exact) {
                        l.kvar = static_cast<float>(kernel_variation(r, s, l.Fu));
                        l.kvar_exact = true;
                        e = link_error(l, Bn, I, geometry_only);
                    }
                    return e;
                };
                // (Split on geometry alone only above eps_abs itself: then the
                // round surely splits, and no link keeps a pending
                // visibility if it turns out not to.)
                if (l.vis_pending) {
                    double geometric = 0;
                    if (can_r || can_s) {
                        const LinkError g = error(true);
                        if (g.err > eps_abs) {
                            if (m_opt.box_closure && l.tau <= box_proof_below && (r.cluster() || s.cluster()) &&
                                shown_closed_whole(l, split_at, ws, local)) {
                                ++local.boxed;
                                decision[static_cast<size_t>(k)] = 4;  // closed whole: dropped
                                continue;
                            }
                            // A link nearly surely closed (the density's
                            // estimate at most box_proof_below) and not
                            // shown so whole is split on its larger end,
                            // not where the geometric error lies: what it
                            // needs is a proof of closure, which a narrower
                            // shaft gives more often and for less (see
                            // box_proof_below).
                            const bool split_r = l.tau <= box_proof_below ? size_of(r) >= size_of(s) : g.split_r;
                            decision[static_cast<size_t>(k)] = can_r && (!can_s || split_r) ? 1 : 2;
                            above = true;
                            continue;
                        }
                        geometric = g.err;
                    }
                    // Within its share of the bar with the visibility
                    // unknown (the density's estimate, any truth in [0, 1]):
                    // kept so, no query (a dim sender's links; asked again
                    // in later rounds, against the new solution). The
                    // geometric terms are part of that error: above the
                    // share already, it need not be computed.
                    const double deferred_bar = deferred_share * split_at;
                    if (m_opt.defer_visibility && geometric <= deferred_bar && error(false).err <= deferred_bar) continue;
                    ++asked;
                    if (!resolve_visibility(l, ws, local)) {
                        decision[static_cast<size_t>(k)] = 4;  // nothing passes: dropped
                        continue;
                    }
                }
                if (!can_r && !can_s) continue;
                const LinkError e = error(false);
                if (e.err > eps_abs) above = true;
                if (e.err <= split_at) continue;
                const bool split_r = can_r && (!can_s || e.split_r);
                decision[static_cast<size_t>(k)] = l.r == l.s ? 3 : split_r ? 1 : 2;  // (a chain's self link)
            }
#pragma omp critical
            {
                m_stats += local;
                resolved += asked;
                computed += made;
                exceeded = exceeded || above;
            }
        }
        // (The form factors' time: the waves that computed coefficients,
        // geometry or visibility.)
        if (resolved > 0 || computed > 0) m_ff_time += seconds_since(t_decide);
        if (resolved > 0) m_operator_changed = true;  // (a queried link's coefficient is new)
        // The first wave holds every link: if none exceeds eps_abs, the
        // round splits nothing (links that nothing passes are still dropped).
        if (first_wave && !exceeded)
            for (size_t k = 0; k < decision.size(); ++k) {
                char& d = decision[k];
                if (d == 1 || d == 2 || (d == 3 && (m_links[tail + k].uniform || self_link_kept_if_faint(m_links[tail + k])))) d = 0;
            }
        // 2. Split (serially: creates nodes), collecting the children links,
        // and keep the tail's survivors in place.
        LinkVector& fresh = m_fresh;
        fresh.clear();
        size_t w = tail;
        for (size_t k = 0; k < static_cast<size_t>(nw); ++k) {
            const size_t at = tail + k;
            if (first_wave && at == prefix) m_sorted_links = w;
            if (!decision[k]) {
                m_links[w++] = m_links[at];
                continue;
            }
            const Link l = m_links[at];
            m_operator_changed = true;
            if (decision[k] == 4) continue;  // dropped, not split
            any = true;
            if (decision[k] == 3) {
                self_links(l.r, fresh);
                continue;
            }
            const bool split_r = decision[k] == 1;
            const int node = split_r ? l.r : l.s;
            if (m_nodes[static_cast<size_t>(node)].kind == Kind::Element) {
                split_element(node);
                while (Bn.size() < m_nodes.size()) Bn.push_back(Bn[static_cast<size_t>(node)]);  // halves start at the mean
                while (m_Bmax.size() < m_nodes.size()) m_Bmax.push_back(m_Bmax[static_cast<size_t>(node)]);
                while (m_Lsum.size() < m_nodes.size()) m_Lsum.push_back(m_nodes[m_Lsum.size()].length);
            }
            children_links(l, split_r, fresh);
        }
        if (first_wave && prefix >= static_cast<size_t>(nw)) m_sorted_links = w;  // the whole prefix survived in order
        first_wave = false;
        m_links.resize(w);
        tail = w;
        // 3. The new links, to be decided by the next wave (which computes
        // their geometry first: Link::fresh).
        m_links.insert(m_links.end(), fresh.begin(), fresh.end());
        if (!fresh.empty()) progress(fmt::format("refining: {} links", m_links.size()), -1);
    }
    return any;
}

void HierarchicalSolver::collect_leaves() {
    // In slices side by side (the serial loop's result, leaf indices in node
    // order): each slice counts its element leaves, then fills its own
    // OpNodes and leaf indices from where the slices before it end. Both
    // passes read millions of 192-byte nodes (10^6 forest: 0.3 s a solve on
    // one thread).
    const size_t N = m_nodes.size();
    m_leaf_index.resize(N);
    m_op.resize(N);
    m_table_of.resize(N);
    std::vector<size_t> before;  // element leaves in the slices before each
    const auto is_leaf = [](const Node& n) { return n.kind == Kind::Element && n.child < 0; };
#pragma omp parallel num_threads(m_threads) if (N >= op_parallel_min_nodes)
    {
#pragma omp single
        before.assign(static_cast<size_t>(omp_get_num_threads()) + 1, 0);  // (the team may be smaller than asked)
        const size_t T = before.size() - 1, t = static_cast<size_t>(omp_get_thread_num());
        const size_t lo = N * t / T, hi = N * (t + 1) / T;
        size_t count = 0;
        for (size_t k = lo; k < hi; ++k) count += is_leaf(m_nodes[k]) ? 1 : 0;
        before[t + 1] = count;
#pragma omp barrier
#pragma omp single
        {
            for (size_t u = 0; u < T; ++u) before[u + 1] += before[u];
            m_leaves.resize(before[T]);
        }
        size_t next = before[t];
        for (size_t k = lo; k < hi; ++k) {
            const Node& n = m_nodes[k];
            m_leaf_index[k] = -1;
            if (is_leaf(n)) {
                m_leaf_index[k] = static_cast<int>(next);
                m_leaves[next++] = static_cast<int>(k);
            }
            OpNode& o = m_op[k];
            o.parent = n.parent;
            o.child = n.child;
            o.nchild = n.nchild;
            o.table = n.table;
            m_table_of[k] = n.table;
            o.leaf = m_leaf_index[k];
            o.kind = n.kind;
            o.leaf_cluster = n.leaf_cluster;
            o.normal = n.normal;
            o.length = n.length;
            o.chain = n.chain;
            const Node* p = n.parent >= 0 ? &m_nodes[static_cast<size_t>(n.parent)] : nullptr;
            o.side = !n.cluster() && p && p->cluster();
            o.up_table = -1;
            if (n.cluster() && p)
                o.up_table = p->table;
            else if (o.side && p->parent >= 0)
                o.up_table = m_nodes[static_cast<size_t>(p->parent)].table;
            o.lobe = o.side && o.up_table >= 0 ? lobe_bins(n.normal) : 0;  // (push_node reads it there alone)
        }
    }
    m_element_leaves = static_cast<int>(m_leaves.size());
    build_op_schedule();
}

// Splits the node tree for the operator's passes on several threads
// (OpSchedule): from the roots down, the largest subtree is replaced by its
// children until none holds more than 1 / (8 x threads) of the nodes, so
// that dynamic scheduling keeps the threads evenly busy; the nodes split
// on the way are the ones above. Parents come before their children in the
// node order (pull_tables and push_down rely on it too), so each list is
// ascending when filled in node order.
void HierarchicalSolver::build_op_schedule() {
    m_sched.subtrees.clear();
    m_sched.top.clear();
    m_sched.frontier.clear();
    const size_t N = m_op.size();
    if (m_threads < 2 || N < op_parallel_min_nodes) return;
    std::vector<int32_t> size(N, 1);
    for (size_t k = N; k-- > 0;) {
        FLATRAD_ASSERT(m_op[k].parent < static_cast<int32_t>(k), "parents come before their children");
        if (m_op[k].parent >= 0) size[static_cast<size_t>(m_op[k].parent)] += size[k];
    }
    const int32_t most = static_cast<int32_t>(std::max<size_t>(64, N / (8 * static_cast<size_t>(m_threads))));
    auto smaller = [&](int a, int b) { return size[static_cast<size_t>(a)] < size[static_cast<size_t>(b)]; };
    std::vector<int> heap;
    for (size_t k = 0; k < N; ++k)
        if (m_op[k].parent < 0) heap.push_back(static_cast<int>(k));
    std::make_heap(heap.begin(), heap.end(), smaller);
    std::vector<char> above(N, 0);
    while (!heap.empty() && size[static_cast<size_t>(heap.front())] > most) {
        std::pop_heap(heap.begin(), heap.end(), smaller);
        const int k = heap.back();
        heap.pop_back();
        above[static_cast<size_t>(k)] = 1;
        const OpNode& n = m_op[static_cast<size_t>(k)];
        for (int c = n.child; c >= 0 && c < n.child + n.nchild; ++c) {
            FLATRAD_ASSERT(m_op[static_cast<size_t>(c)].parent == k, "children are contiguous");
            heap.push_back(c);
            std::push_heap(heap.begin(), heap.end(), smaller);
        }
    }
    if (heap.size() < 2) return;  // nothing to share
    std::sort(heap.begin(), heap.end(), [&](int a, int b) { return smaller(b, a) || (!smaller(a, b) && a < b); });
    std::vector<int32_t> subtree(N, -1);
    m_sched.frontier.assign(N, 0);
    for (size_t t = 0; t < heap.size(); ++t) {
        subtree[static_cast<size_t>(heap[t])] = static_cast<int32_t>(t);
        m_sched.frontier[static_cast<size_t>(heap[t])] = 1;
    }
    m_sched.subtrees.resize(heap.size());
    for (size_t t = 0; t < heap.size(); ++t) m_sched.subtrees[t].reserve(static_cast<size_t>(size[static_cast<size_t>(heap[t])]));
    for (size_t k = 0; k < N; ++k) {
        const int32_t p = m_op[k].parent;
        if (subtree[k] < 0 && p >= 0 && !above[static_cast<size_t>(p)]) subtree[k] = subtree[static_cast<size_t>(p)];
        if (subtree[k] >= 0) m_sched.subtrees[static_cast<size_t>(subtree[k])].push_back(static_cast<int>(k));
        if (subtree[k] < 0 || m_sched.frontier[k]) m_sched.top.push_back(static_cast<int>(k));
    }
}

// Groups links by receiver (CSR) so that the gather runs in parallel over
// receivers without races.
void HierarchicalSolver::sort_links() {
    // The first m_sorted_links links are sorted by receiver already (the
    // survivors of the last sort, in order): only the rest is sorted, by
    // counting (stable: a receiver's links keep their order, which is
    // deterministic; O(links + nodes), where a comparison sort of tens of
    // millions of links took a tenth of a large solve), and then merged in,
    // both into buffers kept between calls (a fresh one per call was
    // gigabytes of new pages to zero at 10^6 walls). After the first
    // round, a refinement adds a few percent of the links, and the merge
    // reads and writes the rest in order.
    const size_t n = m_links.size(), sorted = std::min(m_sorted_links, n);
    if (sorted < n) {
        // Room to grow: the next refinement appends to these links. (Its
        // contents are scratch: cleared first, so that growing copies nothing.)
        if (m_links_sorted.capacity() < n) {
            m_links_sorted.clear();
            m_links_sorted.reserve(n + n / 4);
        }
        m_links_sorted.resize(n);
        LinkVector& rest = sorted == 0 ? m_links_sorted : m_fresh;  // nothing to merge: straight in
        rest.resize(n - sorted);
        // Counting sort on m_threads threads: each counts its own slice of
        // the links per receiver, a receiver's slots go to the slices in
        // order (so the result is the serial sort's), and each slice
        // scatters its links into its slots. The buffer's pages are first
        // touched by that scatter (LinkVector), so both are split: at 10^6
        // walls the first round's sort took 0.72 s on one thread (0.62 s of
        // it resize() writing default links), 0.33 s so.
        const size_t N = m_nodes.size(), m = n - sorted;
        std::vector<std::vector<int32_t>> start;
#pragma omp parallel num_threads(m_threads) if (m > static_cast<size_t>(64 * parallel_min_work))
        {
#pragma omp single
            start.resize(static_cast<size_t>(omp_get_num_threads()));  // (the team may be smaller than asked)
            const size_t T = start.size(), t = static_cast<size_t>(omp_get_thread_num());
            auto slice = [&](size_t i) { return sorted + m * i / T; };
            std::vector<int32_t>& count = start[t];
            count.assign(N, 0);
            for (size_t k = slice(t); k < slice(t + 1); ++k) ++count[static_cast<size_t>(m_links[k].r)];
#pragma omp barrier
#pragma omp single
            {
                int32_t at = 0;
                for (size_t r = 0; r < N; ++r)
                    for (size_t u = 0; u < T; ++u) {
                        int32_t& c = start[u][r];
                        const int32_t here = c;
                        c = at;
                        at += here;
                    }
            }
            for (size_t k = slice(t); k < slice(t + 1); ++k)
                rest[static_cast<size_t>(count[static_cast<size_t>(m_links[k].r)]++)] = m_links[k];
        }
        if (sorted > 0)
            std::merge(m_links.begin(), m_links.begin() + static_cast<std::ptrdiff_t>(sorted), m_fresh.begin(),
                       m_fresh.end(), m_links_sorted.begin(), [](const Link& a, const Link& b) { return a.r < b.r; });
        m_links.swap(m_links_sorted);
    }
    m_sorted_links = n;
    FLATRAD_ASSERT(std::is_sorted(m_links.begin(), m_links.end(), [](const Link& a, const Link& b) { return a.r < b.r; }),
                   "links sorted by receiver");
    index_receivers();
}

// The CSR of links sorted by receiver: each receiver and where its links
// start.
void HierarchicalSolver::index_receivers() {
    m_receivers.clear();
    m_link_start.clear();
    for (size_t k = 0; k < m_links.size(); ++k)
        if (k == 0 || m_links[k].r != m_links[k - 1].r) {
            m_receivers.push_back(m_links[k].r);
            m_link_start.push_back(static_cast<int32_t>(k));
        }
    m_link_start.push_back(static_cast<int32_t>(m_links.size()));
}

// Which tables the operator keeps samples for (solver/table_array.h): an
// exitance table read through its samples by some link, an arrival table
// written through them, and every table below those (a parent's exitance
// is the sum of its children's; a child's arrivals include its parent's).
// Lays out m_I and m_J accordingly.
void HierarchicalSolver::sample_slots() {
    const size_t T = static_cast<size_t>(m_tables_count);
    std::vector<char> need_I(T, 0), need_J(T, 0);
    for (const Link& l : m_links) {
        if (l.uniform) continue;  // chain links read means and spread evenly: no table
        const int32_t rt = m_table_of[static_cast<size_t>(l.r)], st = m_table_of[static_cast<size_t>(l.s)];
        if (st >= 0 && !l.s_linear) need_I[static_cast<size_t>(st)] = 1;
        if (rt >= 0 && !l.r_linear) need_J[static_cast<size_t>(rt)] = 1;
    }
    for (const OpNode& n : m_op)  // parents first
        if (n.table >= 0 && n.up_table >= 0) {
            const size_t p = static_cast<size_t>(n.up_table);
            need_I[static_cast<size_t>(n.table)] |= need_I[p];
            need_J[static_cast<size_t>(n.table)] |= need_J[p];
        }
    auto slots = [&](const std::vector<char>& need, std::vector<int32_t>& slot) {
        int32_t count = 0;
        slot.assign(T, -1);
        for (size_t t = 0; t < T; ++t)
            if (need[t]) slot[t] = count++;
        return count;
    };
    m_I_slotted = slots(need_I, m_I_slot);
    m_J_slotted = slots(need_J, m_J_slot);
    m_I.reset(m_I_slot, m_I_slotted);
    m_J.reset(m_J_slot, m_J_slotted);
    m_I.clear();  // a part's operator zeroes only its own tables
    m_J.clear();
}

// Light flow (solver/reachability.h): which element leaves and sinks any
// emitter's light can reach along pulls (leaf -> ancestors), links (sender
// -> receiver) and pushes (node -> descendants). Links whose sender is not
// reached carry nothing and are dropped.
// light_flow() only reads (the links, the nodes), so that the solve can
// find the independent parts meanwhile; drop_dark() then applies it.
std::vector<char> HierarchicalSolver::light_flow() const {
    const int N = static_cast<int>(m_nodes.size());
    std::vector<char> sources(static_cast<size_t>(N), 0);
    for (int k = 0; k < N; ++k)
        for (int c = 0; c < m_C; ++c) sources[static_cast<size_t>(k)] = sources[static_cast<size_t>(k)] || emission(k, c) > 0;
    // Light climbs (pull) only into a sender, and comes down (push) only
    // from what a receiver got, so every node has two vertices: k receiving
    // (reached by a link or a push) and N + k sending (reached by a pull);
    // only links lead from a sending vertex to a receiving one.
    std::vector<DirectedEdge> flow;
    flow.reserve(3 * m_nodes.size() + m_links.size());
    auto edge = [](int a, int b) { return DirectedEdge{static_cast<uint32_t>(a), static_cast<uint32_t>(b)}; };
    for (int k = 0; k < N; ++k) {
        const OpNode& n = m_op[static_cast<size_t>(k)];
        if (n.kind == Kind::Element) flow.push_back(edge(k, N + k));  // a lit element sends what it holds
        if (n.parent >= 0) {
            flow.push_back(edge(n.parent, k));  // push down
            if (n.kind != Kind::Sink) flow.push_back(edge(N + k, N + n.parent));  // pull up
        }
    }
    for (const Link& l : m_links) flow.push_back(edge(N + l.s, l.r));
    std::vector<char> src2(2 * static_cast<size_t>(N), 0);
    for (int k = 0; k < N; ++k) src2[static_cast<size_t>(k)] = sources[static_cast<size_t>(k)];
    return reachable_directed(2 * N, flow, src2);
}

void HierarchicalSolver::drop_dark(const std::vector<char>& reached2) {
    const int N = static_cast<int>(m_nodes.size());
    m_reached.assign(static_cast<size_t>(N), 0);
    for (int k = 0; k < N; ++k) m_reached[static_cast<size_t>(k)] = reached2[static_cast<size_t>(k)];
    // Patches none of whose leaves is reached.
    std::vector<char> lit_patch(m_scene.patches.size() + static_cast<size_t>(m_sink_patches), 0);
    for (int leaf : m_leaves)
        if (m_reached[static_cast<size_t>(leaf)]) lit_patch[static_cast<size_t>(m_nodes[static_cast<size_t>(leaf)].patch)] = 1;
    lit_patch.resize(m_scene.patches.size());  // (the sinks made senders are no patches of the scene)
    m_left_out = 0;
    for (char c : lit_patch) m_left_out += c ? 0 : 1;
    const size_t before = m_links.size();
    m_links.erase(std::remove_if(m_links.begin(), m_links.end(),
                                 [&](const Link& l) { return !reached2[static_cast<size_t>(N + l.s)]; }),
                  m_links.end());
    m_dark_links = static_cast<long>(before - m_links.size());
    // This runs right after sort_links, and remove_if keeps the order.
    m_sorted_links = std::min(m_sorted_links, m_links.size());
}

// Top-down push, shared by the operator and its adjoint (landed_fraction):
// cluster tables add their parent's (in place; parents come first), each
// side reads its leaf cluster's parent table through its cosine lobe
// (times lobe_scale), each element below gets its parent's own value plus
// what reached the parent. Returns, per node, what reached it from above.
// With a part, only its nodes are visited and written (a part's top node
// gets nothing from above: no link ends above it).
void HierarchicalSolver::push_down(TableArray& tables, const std::vector<double>& own, double lobe_scale,
                                   std::vector<double>& above, const Part* part) const {
    const size_t N = m_nodes.size();
    FLATRAD_ASSERT(m_op.size() == N, "nodes indexed for the operator (collect_leaves)");
    if (!part || above.size() != N) above.assign(N, 0.0);
    if (!part && !m_sched.subtrees.empty()) {
        // The nodes above the subtrees, then the subtrees side by side: a
        // node reads only its parent's values and the tables above it, and
        // writes only its own.
        for (int k : m_sched.top)
            if (!m_sched.frontier[static_cast<size_t>(k)]) push_node(static_cast<size_t>(k), tables, own, lobe_scale, above, nullptr);
        const long S = static_cast<long>(m_sched.subtrees.size());
#pragma omp parallel for num_threads(m_threads) schedule(dynamic, 1)
        for (long t = 0; t < S; ++t)
            for (int k : m_sched.subtrees[static_cast<size_t>(t)]) push_node(static_cast<size_t>(k), tables, own, lobe_scale, above, nullptr);
        return;
    }
    const size_t count = part ? part->nodes.size() : N;
    for (size_t q = 0; q < count; ++q) push_node(part ? static_cast<size_t>(part->nodes[q]) : q, tables, own, lobe_scale, above, part);
}

// push_down's work at node k.
void HierarchicalSolver::push_node(size_t k, TableArray& tables, const std::vector<double>& own, double lobe_scale,
                                   std::vector<double>& above, const Part* part) const {
    const OpNode& n = m_op[k];
    above[k] = 0;
    if (n.parent < 0 || !in_part(part, static_cast<int>(k), n.parent)) return;
    // What reached the parent evenly (an element's own links, chain
    // links to clusters above) reaches every node below.
    above[k] = own[static_cast<size_t>(n.parent)] + above[static_cast<size_t>(n.parent)];
    if (n.kind == Kind::Cluster) {
        // The parent's arrivals, at this node's share seen from outside it.
        if (n.table >= 0 && n.up_table >= 0) tables.add_parent(n.table, n.up_table, gamma(k));
    } else if (n.side && n.up_table >= 0) {
        // Its leaf cluster: no link ends there, its table is its parent's,
        // read at the leaf cluster's share seen from outside that parent.
        const float* g = gamma(static_cast<size_t>(n.parent));
        const double* samples = tables.samples(n.up_table);
        const double* linear = tables.linear(n.up_table);
        above[k] += lobe_scale * (g ? read_cosine_lobe(samples, linear, n.normal, g, n.lobe) : read_cosine_lobe(samples, linear, n.normal, n.lobe));
    }
}

// G(x): pull the leaf radiosities x up (means and exitance tables), gather
// along the links, push irradiance down to the leaves. With `correct`, a
// closed leaf adds its row-sum deficit times its ancestors' mean arrival.
// With a part, x and out are still indexed by all element leaves, but only
// the part's are read and written.
void HierarchicalSolver::apply_G(const Eigen::VectorXd& x, Eigen::VectorXd& out, bool correct, const Part* part) {
    pull_tables(x.data(), m_Bn, m_I, part);
    clear_scratch(m_Hn, m_J, part);
    // Gather, in parallel over receivers.
    const long R = static_cast<long>(part ? part->receivers.size() : m_receivers.size());
#pragma omp parallel for num_threads(m_threads) schedule(dynamic, 256) if (R > 16 * parallel_min_work && m_links.size() > gather_min_links)
    for (long qq = 0; qq < R; ++qq) {
        const long q = part ? part->receivers[static_cast<size_t>(qq)] : qq;
        const int r = m_receivers[static_cast<size_t>(q)];
        const OpNode& nr = m_op[static_cast<size_t>(r)];  // (receivers ascend: m_op in order, not 192-byte nodes)
        double h = 0;
        const bool to_table = nr.kind == Kind::Cluster;
        double* J = to_table ? m_J.samples(nr.table) : nullptr;
        double* J_linear = to_table ? m_J.linear(nr.table) : nullptr;
        for (int32_t k = m_link_start[static_cast<size_t>(q)]; k < m_link_start[static_cast<size_t>(q) + 1]; ++k) {
            const Link& l = m_links[static_cast<size_t>(k)];
            // A link that carries nothing adds +0 (no sender read): the
            // overlapping faint neighbours' unresolved links and links
            // shown closed, 41% of the 10^6 forest's.
            if (l.coef == 0) continue;
            const int32_t t = m_table_of[static_cast<size_t>(l.s)];  // -1: an element sends its mean
            const double v = t < 0 || l.uniform ? m_Bn[static_cast<size_t>(l.s)]
                             : l.s_linear       ? read_linear_part(m_I.linear(t), l.u())
                                                : interpolate(m_I.samples(t), l.sbin());
            const double c = l.coef * v;
            if (!to_table || l.uniform) {
                h += c;  // an element's irradiance, or what a chain spreads evenly below
            } else if (l.r_linear) {
                add_linear_part(J_linear, -l.u(), c);  // arrives from the sender's direction
            } else {
                const BinWeight b = l.rbin();
                J[b.k] += (1 - b.t) * c;
                J[b.next()] += b.t * c;
            }
        }
        m_Hn[static_cast<size_t>(r)] = h;
    }
    // Push: tables down the clusters, then onto sides, then down elements.
    push_down(m_J, m_Hn, 1.0, m_Ha, part);  // m_Ha: what arrived at ancestors (row-sum correction)
    if (out.size() != static_cast<Eigen::Index>(m_element_leaves)) out.setZero(static_cast<Eigen::Index>(m_element_leaves));
    const size_t leaves = part ? part->leaves.size() : static_cast<size_t>(m_element_leaves);
    for (size_t j = 0; j < leaves; ++j) {
        const size_t i = part ? static_cast<size_t>(part->leaves[j]) : j;
        const size_t k = static_cast<size_t>(m_leaves[i]);
        double h = m_Hn[k] + m_Ha[k];
        // The deficit goes with the ancestors' arrivals (where the
        // refinement error is); a leaf with none scales its own links.
        if (correct && !m_deficit.empty() && m_deficit[i] != 0) {
            if (m_anc_sum[i] > 0)
                h += m_deficit[i] * m_Ha[k] / m_anc_sum[i];
            else if (m_own_sum[i] > 0)
                h += m_deficit[i] * m_Hn[k] / m_own_sum[i];
        }
        out(static_cast<Eigen::Index>(i)) = h;
    }
}

// Row sums (see the header), per element leaf, for the current links
// (m_deficit, m_anc_sum, m_own_sum): a leaf of a patch whose light cannot
// leave the scene and that sees no sink must gather exactly 1 for B = 1
// everywhere. Probed with every link, before drop_dark() drops those from
// dark senders (they are part of the leaf's geometry, and carry 0 in the
// solve).
void HierarchicalSolver::row_sums() {
    const Eigen::Index n = static_cast<Eigen::Index>(m_element_leaves);
    m_deficit.assign(static_cast<size_t>(n), 0.0);
    m_anc_sum.assign(static_cast<size_t>(n), 0.0);
    m_own_sum.assign(static_cast<size_t>(n), 0.0);
    if (!m_closed_patch.empty()) {
        Eigen::VectorXd ones = Eigen::VectorXd::Ones(n), g;
        apply_G(ones, g, false);
        for (Eigen::Index i = 0; i < n; ++i) {
            const int node = m_leaves[static_cast<size_t>(i)];
            if (!m_closed_patch[static_cast<size_t>(m_nodes[static_cast<size_t>(node)].patch)]) continue;
            m_deficit[static_cast<size_t>(i)] = 1 - g(i);
            m_anc_sum[static_cast<size_t>(i)] = m_Ha[static_cast<size_t>(node)];
            m_own_sum[static_cast<size_t>(i)] = m_Hn[static_cast<size_t>(node)];
        }
    }
}

// Solves to `tolerance` (relative residual, per part and channel) from
// the previous solve's values; stats.residual is the last solve's.
void HierarchicalSolver::solve(double tolerance) {
    const auto t0 = Clock::now();
    m_residual = 0;
    // The same operator as the last solve's (the last refinement changed
    // no link: the final solve after a round that splits nothing): its
    // leaves, receivers, row sums and parts stand; only the table layout
    // is laid out again (the refinement pulled every table). Only when that
    // solve's flow check dropped no link (m_flow_simple): its row sums were
    // probed with the links it then had, which are these.
    const bool same_operator = m_opt.keep_unchanged_setup && m_solved && !m_operator_changed && m_flow_simple;
    m_setups_kept += same_operator ? 1 : 0;
    m_operator_changed = false;
    if (!same_operator) {
        collect_leaves();
        sort_links();
    }
    sample_slots();
    const Eigen::Index n = static_cast<Eigen::Index>(m_element_leaves);
    if (!same_operator) row_sums();
    // Light flow and independent parts. Refinement only splits links
    // (each child joins nodes below the ends of its parent), so what light
    // reaches can only shrink and parts only come apart: when the last
    // check found every patch reached, no link dark and one part, the next
    // solves skip the check: a link it would now drop carries no light, and
    // one part solves everything together. The stats then say what the
    // solve did (every patch solved, every link used, one part). A round
    // room of 10^6 walls spent ~1.1 s per solve here.
    // The flow's search runs on a second thread while the parts are found
    // over the same links; if it finds dark links, they are dropped and the
    // parts found again (1.2 -> 0.7 s at 10^6 walls). The second thread is
    // the OpenMP team's, not a thread of its own: right after a refinement
    // round the team's idle thread still spins on the other core, and a new
    // thread waited for it (the 1000-segment forest at eps 12: 4-5.8 ms for
    // the first solve's flow and parts, 0.8-0.9 ms now; `flatrad solve`,
    // alternating, medians of 15: 77.9 ms against 82.1 ms).
    // A convex room (m_convex_room) needs no check at all. Every segment
    // lies on the hull's boundary and every patch is escape-free, so the
    // patches are the inner sides of a convex polygon's walls, and two
    // walls on different lines see each other whole (F > 0, no blocker).
    // The emitter's light reaches every wall off its line directly; a wall
    // W on its line sees any wall off that line, which is reached and
    // reflects. The links cover every pair with F > 0 (refinement drops
    // only links that carry nothing), so the check would find every patch
    // reached, no dark link, and one part. (The test compares with the
    // check run.) A round room of 10^6 walls saves ~0.8 s.
    if (same_operator) {
        // (The parts and the flow's counts are the last solve's.)
    } else if (!m_solved && m_convex_room) {
        m_left_out = 0;
        m_dark_links = 0;
        m_part_count = 1;
        m_flow_simple = true;
    } else if (!m_solved || !m_flow_simple) {
        std::vector<char> flow;
#pragma omp parallel sections num_threads(std::min(m_threads, 2))
        {
#pragma omp section
            flow = light_flow();
#pragma omp section
            build_parts();
        }
        drop_dark(flow);  // drops links, keeping the order: still sorted by receiver
        if (m_dark_links > 0) {
            index_receivers();  // (the slots above still hold every table a link uses)
            build_parts();
        }
        m_flow_simple = m_left_out == 0 && m_dark_links == 0 && m_parts.size() == 1;
    }
    if (m_flow_simple) {
        // One part: the operator unrestricted (no lists to walk).
        m_parts.assign(1, Part{});
        Part& all = m_parts[0];
        all.whole = true;
        all.leaves.resize(static_cast<size_t>(n));
        for (Eigen::Index i = 0; i < n; ++i) all.leaves[static_cast<size_t>(i)] = static_cast<int>(i);
    }
    // Krylov runs start from the previous round's solution (a new half
    // from the element it halves): a refinement round changes few links,
    // so the next solve has little left to do. The first starts from E.
    // (split_element gives halves their parent's values.)
    const std::vector<std::vector<double>> previous = std::move(m_B);
    auto start_value = [&](int c, int node) {
        return m_solved ? previous[static_cast<size_t>(c)][static_cast<size_t>(node)] : emission(node, c);
    };
    m_B.assign(static_cast<size_t>(m_C), std::vector<double>(m_nodes.size(), 0.0));
    m_H = m_B;
    for (int c = 0; c < m_C; ++c) {
        Eigen::VectorXd E(n), rho_l(n), x(n), g = Eigen::VectorXd::Zero(n);
        for (Eigen::Index i = 0; i < n; ++i) {
            const int node = m_leaves[static_cast<size_t>(i)];
            E(i) = emission(node, c);
            rho_l(i) = rho(node, c);
            x(i) = E(i);  // a leaf in no part gathers nothing: B = E
        }
        // Each part apart: its own Krylov run on its own leaves, the
        // operator restricted to its nodes and receivers. stats.iterations
        // counts the longest run (the applications of the whole operator
        // had the parts run side by side).
        long longest = 0;
        Eigen::VectorXd full = x;  // scratch: the whole leaf vector
        bool applied_at_x = false;  // the last application was the whole operator's at x (below)
        for (const Part& part : m_parts) {
            const Eigen::Index m = static_cast<Eigen::Index>(part.leaves.size());
            if (m == 0) continue;
            Eigen::VectorXd Ep(m), xp(m);
            for (Eigen::Index j = 0; j < m; ++j) {
                Ep(j) = E(part.leaves[static_cast<size_t>(j)]);
                xp(j) = start_value(c, m_leaves[static_cast<size_t>(part.leaves[static_cast<size_t>(j)])]);
            }
            auto apply = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
                for (Eigen::Index j = 0; j < m; ++j) full(part.leaves[static_cast<size_t>(j)]) = v(j);
                apply_G(full, g, true, part.whole ? nullptr : &part);
                Eigen::VectorXd out(m);
                for (Eigen::Index j = 0; j < m; ++j) {
                    const Eigen::Index i = part.leaves[static_cast<size_t>(j)];
                    out(j) = v(j) - rho_l(i) * g(i);
                }
                return out;
            };
            GmresOptions go;
            go.tolerance = tolerance;
            go.restart = m > 200000 ? 20 : 60;  // the Krylov basis is m x restart doubles
            double rel = 0;
            const long applications = gmres(apply, Ep, xp, rel, go);
            longest = std::max(longest, applications);
            for (Eigen::Index j = 0; j < m; ++j) x(part.leaves[static_cast<size_t>(j)]) = xp(j);
            // gmres's last application is at the x it returns (its final
            // residual), unless it made none (E = 0 on the part).
            applied_at_x = part.whole && m_parts.size() == 1 && applications > 0;
        }
        m_iterations += longest;
        // The whole operator once more: the residual of all parts together,
        // and every node's values. One whole part: gmres's last application
        // was that already, at this x, and left g and every node's values
        // for it (the same sums in the same order: 5 of the 37 applications
        // of the 10^6 forest at eps 10).
        if (!applied_at_x) apply_G(x, g, true);
        const Eigen::VectorXd r = E - (x - rho_l.cwiseProduct(g));
        const double scale = std::max(E.cwiseAbs().maxCoeff(), x.cwiseAbs().maxCoeff());
        if (scale > 0) m_residual = std::max(m_residual, r.cwiseAbs().maxCoeff() / scale);
        // Per-node values of the final x (the last apply left m_Bn, m_Hn, m_Ha for it).
        auto& B = m_B[static_cast<size_t>(c)];
        auto& H = m_H[static_cast<size_t>(c)];
        for (size_t k = 0; k < m_nodes.size(); ++k) {
            B[k] = m_Bn[k];
            H[k] = m_Hn[k] + m_Ha[k];
        }
        for (Eigen::Index i = 0; i < n; ++i) H[static_cast<size_t>(m_leaves[static_cast<size_t>(i)])] = g(i);
        progress(fmt::format("solved channel {} of {}", c + 1, m_C), -1);
    }
    m_solved = true;
    m_solve_time += seconds_since(t0);
}

// Independent sub-scenes (solver/light_parts.h) over the current links: a
// leaf is coupled to its ancestors that end a link and a link couples its
// ends. Each part that holds a link gets its nodes (every leaf's path up to
// its highest linked ancestor), element leaves and receivers. With
// solve_parts_apart off, one part holds everything (the test's oracle).
void HierarchicalSolver::build_parts() {
    const int N = static_cast<int>(m_nodes.size());
    m_parts.clear();
    m_part_of.assign(static_cast<size_t>(N), -1);
    m_part_count = 0;
    if (m_links.empty()) return;
    std::vector<char> linked(static_cast<size_t>(N), 0);
    std::vector<std::pair<int, int>> edges;
    edges.reserve(m_links.size() + m_nodes.size());
    for (const Link& l : m_links) {
        linked[static_cast<size_t>(l.r)] = linked[static_cast<size_t>(l.s)] = 1;
        if (l.r != l.s) edges.push_back({l.r, l.s});
    }
    // Per node, its nearest and its highest linked ancestor (-1: none), in
    // one pass: parents come before their children.
    std::vector<int> nearest(static_cast<size_t>(N), -1), highest(static_cast<size_t>(N), -1);
    for (int k = 0; k < N; ++k) {
        const int p = m_nodes[static_cast<size_t>(k)].parent;
        if (p < 0) continue;
        nearest[static_cast<size_t>(k)] = linked[static_cast<size_t>(p)] ? p : nearest[static_cast<size_t>(p)];
        highest[static_cast<size_t>(k)] = highest[static_cast<size_t>(p)] >= 0 ? highest[static_cast<size_t>(p)]
                                          : linked[static_cast<size_t>(p)] ? p
                                                                           : -1;
    }
    // An element leaf is coupled to every linked ancestor. Chaining each
    // element leaf, and each linked node with an element leaf below, to its
    // nearest linked ancestor couples the same nodes with O(N) edges (a
    // leaf below a linked node is coupled to it and to everything above).
    std::vector<char> leaf_below(static_cast<size_t>(N), 0);
    for (int k = N; k-- > 0;) {
        if (m_leaf_index[static_cast<size_t>(k)] >= 0) leaf_below[static_cast<size_t>(k)] = 1;
        const int p = m_nodes[static_cast<size_t>(k)].parent;
        if (p >= 0 && leaf_below[static_cast<size_t>(k)]) leaf_below[static_cast<size_t>(p)] = 1;
    }
    for (int k = 0; k < N; ++k) {
        const bool chained = m_leaf_index[static_cast<size_t>(k)] >= 0 ||
                             (linked[static_cast<size_t>(k)] && leaf_below[static_cast<size_t>(k)]);
        if (chained && nearest[static_cast<size_t>(k)] >= 0) edges.push_back({k, nearest[static_cast<size_t>(k)]});
    }
    LightParts lp;
    if (m_opt.solve_parts_apart) {
        lp = connected_parts(N, edges);
    } else {
        lp.part.assign(static_cast<size_t>(N), 0);
        lp.count = 1;
    }
    edges = {};
    // Parts that hold a link, numbered in order of their first receiver.
    std::vector<int> index(static_cast<size_t>(lp.count), -1);
    for (size_t q = 0; q < m_receivers.size(); ++q) {
        const int comp = lp.part[static_cast<size_t>(m_receivers[q])];
        int& id = index[static_cast<size_t>(comp)];
        if (id < 0) {
            id = static_cast<int>(m_parts.size());
            m_parts.emplace_back();
        }
        m_parts[static_cast<size_t>(id)].receivers.push_back(static_cast<int>(q));
    }
    m_part_count = static_cast<long>(m_parts.size());
    for (size_t i = 0; i < m_leaves.size(); ++i) {
        const int leaf = m_leaves[i];
        const int id = index[static_cast<size_t>(lp.part[static_cast<size_t>(leaf)])];
        if (id < 0) continue;  // gathers nothing, sends to no one
        Part& part = m_parts[static_cast<size_t>(id)];
        if (static_cast<int>(i) < m_element_leaves) part.leaves.push_back(static_cast<int>(i));
        // Its path up to its highest linked ancestor; a node already taken
        // has its path above taken too.
        const int top = highest[static_cast<size_t>(leaf)] >= 0 ? highest[static_cast<size_t>(leaf)] : leaf;
        for (int k = leaf;; k = m_nodes[static_cast<size_t>(k)].parent) {
            if (m_part_of[static_cast<size_t>(k)] >= 0) break;
            m_part_of[static_cast<size_t>(k)] = id;
            part.nodes.push_back(k);
            if (k == top) break;
        }
    }
    // A linked node with no leaf below in the part (a receiver whose leaves
    // all lie elsewhere cannot be: pushes reach them) is still an end of a
    // gather: keep it.
    for (int k = 0; k < N; ++k)
        if (linked[static_cast<size_t>(k)] && m_part_of[static_cast<size_t>(k)] < 0) {
            const int id = index[static_cast<size_t>(lp.part[static_cast<size_t>(k)])];
            if (id < 0) continue;
            m_part_of[static_cast<size_t>(k)] = id;
            m_parts[static_cast<size_t>(id)].nodes.push_back(k);
        }
    for (Part& part : m_parts) std::sort(part.nodes.begin(), part.nodes.end());
}

// Per node: the fraction of the power its element leaves send that the
// links deliver anywhere (to patches or sinks): the adjoint of pull and
// gather (DESIGN.md §3). A link delivers lambda = coef x (receiver length,
// or the receiver cluster's sensitivity at the arrival direction) per unit
// of its sender value; an element sender's value is its length-weighted mean
// B (so lambda / L_s per unit of power sent below it), a cluster sender's is
// its exitance table read at the link's direction (so the table's adjoint,
// pushed down the clusters and read through each side's cosine lobe, / 2).
std::vector<double> HierarchicalSolver::landed_fraction() const {
    const size_t N = m_nodes.size();
    std::vector<double> own(N, 0.0);
    TableArray lam;  // the adjoint has samples where the links read I's (the same slots)
    lam.reset(m_I_slot, m_I_slotted);
    lam.clear();
    for (const Link& l : m_links) {
        if (l.coef == 0) continue;  // delivers nothing (as in apply_G)
        const Node& r = m_nodes[static_cast<size_t>(l.r)];
        const Node& s = m_nodes[static_cast<size_t>(l.s)];
        const double* S = r.cluster() ? &m_sensitivity[static_cast<size_t>(r.table) * TW] : nullptr;
        const double d =
            l.coef * (!S || l.uniform ? r.length : l.r_linear ? read_linear(S, -l.u()) : interpolate(S, l.rbin()));
        if (s.cluster() && !l.uniform) {
            if (l.s_linear) {
                add_linear_part(lam.linear(s.table), l.u(), d);
            } else {
                double* t = lam.samples(s.table);
                const BinWeight b = l.sbin();
                t[b.k] += (1 - b.t) * d;
                t[b.next()] += b.t * d;
            }
        } else {
            own[static_cast<size_t>(l.s)] += d / s.length;
        }
    }
    std::vector<double> above;
    push_down(lam, own, 0.5, above);
    std::vector<double> omega(N, 0.0);
    for (size_t k = 0; k < N; ++k) omega[k] = above[k] + own[k];
    return omega;
}

Solution HierarchicalSolver::run() {
    end_phase("set-up");
    refuse_closed_white();
    build_tree();
    collect_leaves();
    bool lit = false;
    for (int leaf : m_leaves)
        for (int c = 0; c < m_C; ++c) lit = lit || emission(leaf, c) > 0;
    m_B.assign(static_cast<size_t>(m_C), std::vector<double>(m_nodes.size(), 0.0));
    m_H = m_B;
    if (lit && m_root >= 0) {
        // Refine against a guess, solve, refine against the solution, ...
        m_links.push_back(link_between(m_root, m_root));
        progress("refining", -1);
        // (See the header, "The first round".)
        const std::vector<double> guess = leaf_guess();
        CompensatedSum W;
        for (size_t i = 0; i < guess.size(); ++i) W.add(m_nodes[static_cast<size_t>(m_leaves[i])].length * guess[i]);
        if (m_emission_first) {
            std::vector<double> e(guess.size(), 0.0);
            for (size_t i = 0; i < e.size(); ++i)
                for (int c = 0; c < m_C; ++c) e[i] = std::max(e[i], emission(m_leaves[i], c));
            refine(refinement_values(std::move(e)), W.value());
        } else if (m_made_senders) {
            refine(refinement_values(guess), W.value());
        } else {
            refine(guess);
        }
        end_phase("refine 1");
        // Intermediate solves stop at a looser residual; the last is taken
        // on to gmres_tolerance (see intermediate_accuracy).
        double rho_max = 0;
        for (int leaf : m_leaves)
            for (int c = 0; c < m_C; ++c) rho_max = std::max(rho_max, rho(leaf, c));
        const double loose = m_opt.loose_intermediate_solves
                                 ? std::max(gmres_tolerance, intermediate_accuracy * (1 - rho_max))
                                 : gmres_tolerance;
        double last_tolerance = m_opt.max_passes > 1 ? loose : gmres_tolerance;
        solve(last_tolerance);
        end_phase("solve 1");
        m_passes = 1;
        for (int pass = 1; pass < m_opt.max_passes; ++pass) {
            // (The leaves and operator nodes are the ones solve() collected:
            // nothing splits between a solve and the next refinement.)
            std::vector<double> bmax(static_cast<size_t>(m_element_leaves), 0.0);
            for (size_t i = 0; i < bmax.size(); ++i)
                for (int c = 0; c < m_C; ++c)
                    bmax[i] = std::max(bmax[i], m_B[static_cast<size_t>(c)][static_cast<size_t>(m_leaves[i])]);
            progress(fmt::format("refining (pass {})", pass + 1), -1);
            bool changed = false;
            if (m_made_senders) {
                CompensatedSum Wb;
                for (size_t i = 0; i < bmax.size(); ++i) Wb.add(m_nodes[static_cast<size_t>(m_leaves[i])].length * bmax[i]);
                changed = refine(refinement_values(std::move(bmax)), Wb.value());
            } else {
                changed = refine(bmax);
            }
            end_phase(fmt::format("refine {}", pass + 1));
            if (!changed) {
                m_refined_to_eps = true;
                break;
            }
            last_tolerance = pass + 1 < m_opt.max_passes ? loose : gmres_tolerance;
            solve(last_tolerance);
            end_phase(fmt::format("solve {}", pass + 1));
            ++m_passes;
        }
        // The links are final: the last values to full accuracy (a
        // solve again, also for the links the last round dropped).
        if (last_tolerance > gmres_tolerance) {
            solve(gmres_tolerance);
            end_phase("solve final");
        }
    } else {
        collect_leaves();  // nothing emits: B = 0 everywhere, no link needed
        m_refined_to_eps = true;
        m_left_out = static_cast<long>(m_scene.patches.size());
        m_B.assign(static_cast<size_t>(m_C), std::vector<double>(m_nodes.size(), 0.0));
        m_H = m_B;
    }

    Solution sol;
    sol.method = "hierarchical";
    sol.subdivide = 1;
    sol.eps = m_opt.eps;
    sol.vis_eps = m_vis_eps;
    sol.channels = m_C;
    sol.patches.resize(m_scene.patches.size());
    // Per patch, on every thread (millions of small vectors at 10^6
    // segments): the element leaves below its root, by t0.
    const long P = static_cast<long>(sol.patches.size());
#pragma omp parallel num_threads(m_threads) if (P >= 4096)
    {
        std::vector<int> stack;
#pragma omp for schedule(dynamic, 1024)
        for (long p = 0; p < P; ++p) {
            PatchResult& pr = sol.patches[static_cast<size_t>(p)];
            const Patch& patch = m_scene.patches[static_cast<size_t>(p)];
            const int root = m_patch_root.empty() ? -1 : m_patch_root[static_cast<size_t>(p)];  // (empty: no hierarchy)
            stack.assign(root >= 0 ? 1 : 0, root);
            while (!stack.empty()) {
                const int k = stack.back();
                stack.pop_back();
                const Node& nd = m_nodes[static_cast<size_t>(k)];
                if (nd.child >= 0) {
                    for (int ch = nd.child; ch < nd.child + nd.nchild; ++ch) stack.push_back(ch);
                    continue;
                }
                ElementValue v;
                // The oriented segment runs against the file order for a right-lit patch.
                v.t0 = patch.lit_left ? nd.s0 : 1 - nd.s1;
                v.t1 = patch.lit_left ? nd.s1 : 1 - nd.s0;
                for (int c = 0; c < m_C; ++c) v.B.push_back(m_B[static_cast<size_t>(c)][static_cast<size_t>(k)]);
                pr.elements.push_back(std::move(v));
            }
            std::sort(pr.elements.begin(), pr.elements.end(),
                      [](const ElementValue& x, const ElementValue& y) { return x.t0 < y.t0; });
            for (int c = 0; c < m_C; ++c)
                pr.radiosity.push_back(m_B[static_cast<size_t>(c)][static_cast<size_t>(root)]);  // pulled mean
        }
    }

    // Totals: absorbed by patches ((1 - rho) H) and sinks. Escaped: what the
    // links do not deliver of the power sent by patches whose light can
    // leave the scene (not escape-free, engine/connectivity.h). What the
    // escape-free ones lose is the solver's own error and shows as balance;
    // in a scene with no escape-free patch, balance only checks the solve.
    const std::vector<double> omega = landed_fraction();  // 0 everywhere when there are no links
    for (int c = 0; c < m_C; ++c) {
        const auto& B = m_B[static_cast<size_t>(c)];
        const auto& H = m_H[static_cast<size_t>(c)];
        CompensatedSum emitted, absorbed, escaped;
        for (size_t k = 0; k < m_nodes.size(); ++k) {
            const Node& n = m_nodes[k];
            if (n.child >= 0 || n.cluster()) continue;
            const double L = n.length;
            if (n.kind == Kind::Element) {
                emitted.add(L * emission(static_cast<int>(k), c));
                absorbed.add(L * (1 - rho(static_cast<int>(k), c)) * H[k]);
                if (!m_escape_free[static_cast<size_t>(n.patch)]) escaped.add(L * B[k] * (1 - omega[k]));
            } else {
                absorbed.add(L * H[k]);
            }
        }
        sol.totals.add_channel(emitted.value(), absorbed.value(), escaped.value());
    }

    sol.stats.form_factor_time_s = m_ff_time;
    sol.stats.linear_solve_time_s = m_solve_time;
    sol.stats.elements = m_element_leaves;
    sol.stats.links = static_cast<long>(m_links.size());
    sol.stats.patches_left_out = m_left_out;
    // The links by kind, in one pass (cluster links once here, not on
    // every solve: both ends' nodes read at random; 0.045 s for 3.5
    // million links, measured when the 10^6 forest kept that many).
    sol.stats.cluster_links = sol.stats.chain_links = sol.stats.unqueried_links = 0;
    for (const Link& l : m_links) {
        sol.stats.cluster_links += m_nodes[static_cast<size_t>(l.r)].cluster() || m_nodes[static_cast<size_t>(l.s)].cluster();
        sol.stats.chain_links += l.uniform;
        sol.stats.unqueried_links += l.vis_pending;
    }
    sol.stats.cluster_tables = m_tables_count;
    sol.stats.sampled_tables = std::max(m_I_slotted, m_J_slotted);
    sol.stats.independent_parts = m_part_count;
    sol.stats.iterations = m_iterations;
    sol.stats.passes = m_passes;
    sol.stats.refined_to_eps = m_refined_to_eps;
    sol.stats.setups_kept = m_setups_kept;
    sol.stats.emission_first = m_emission_first && m_passes > 0;
    sol.stats.residual = m_residual;
    sol.stats.threads = m_threads;
    sol.stats.visibility = m_stats;
    end_phase("result");
    sol.stats.phases = std::move(m_phases);
    sol.stats.time_s = seconds_since(m_t_start);
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
    if (options.unblocked_leaf_size < 0)
        throw InputError(scene.file, "", fmt::format("unblocked_leaf_size: expected >= 0, found {}", options.unblocked_leaf_size));
    HierarchicalSolver solver(scene, options);
    return solver.run();
}

}  // namespace flatrad
