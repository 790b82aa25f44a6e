#pragma once
/// A cheap proof that a crowded shaft is closed (its exchange exactly 0),
/// or a cheap upper bound on its exchange, from bands of its blockers
/// across it.
///
/// Depth x is measured along the pair's axis (shaft.h's PairFrame); patch i
/// lies at depths <= xi, patch j at >= xj > xi. A line from i to j has
/// |phi| < pi/2 in that frame, so its depth grows along it: at depths in
/// the slab [xi, xj] it is between its two ends, inside the shaft. Hence
/// any blocker point in the slab that the line meets stops it.
///
/// A band is the run of blockers (clipped to the slab) nearest in depth to
/// some t0 in the slab. Every line from i to j crosses the section X of the
/// shaft at depth t0, and at the band's outer depths it is inside the
/// shaft's sides. If, at every direction phi of the range, the band's
/// shadows cover the offsets of all such lines, no line passes: L_i F_ij =
/// 0, exactly. Coverage is checked by direction bins as in
/// direction_bounds.h: over a bin [c - h, c + h] each point's offset n(phi)
/// . (P - O) moves by at most |P - O| h; the lines to cover are widened by
/// that and the shadows narrowed by it. X is cut into sections a few
/// shadows wide, each turned about its own midpoint O, so that only the
/// band's depth makes the drift; bins are made narrow enough for it.
///
/// Where the shadows leave gaps, the same check sums them: the free length
/// of a section over a bin (its widened lines, also kept within the
/// patches' widened offsets, less its narrowed shadows) is at least the
/// free length of those lines at any direction of the bin, so the sum over
/// bins of h times the sum over sections bounds L_i F_ij = 1/2 Integral
/// free(phi) dphi from above (a line crossing two sections' widened windows
/// is counted twice: more, never less). Each band alone stops all but its
/// own free lines, so each bin takes the least of the bands' sums.
///
/// Why it pays: the bounds of a long shaft through a dense forest turn
/// about the shaft's centre, and within one of their bins the far pieces
/// move by more than their own shadows: their lower bound is 0 and their
/// upper a sizeable share of the window, so their midpoint claims light
/// where the truth is ~exp(-depth x density x mean shadow). A band a few
/// layers deep shows the 0 for a few small sorts.
///
/// Only a proof and a bound: "not shown closed" never means "open", and
/// the bound is no estimate (the truth is anywhere below it). Rounding
/// can only misplace shadow ends by ulps of the coordinates: gaps of that
/// measure, as in the exact integral.
#include <cstddef>
#include <utility>
#include <vector>

#include "engine/geometry.h"
#include "visibility/direction_bounds.h"

namespace flatrad {

/// Scratch memory of one thread.
struct OpaqueBandScratch {
    using Interval = OffsetInterval;
    /// A band: its pieces (by_depth[first, last)), its section X at depth t0
    /// from y = ya in `sections` of width w, and their head points (ends,
    /// side points, patch ends) from points[head], section_head a section;
    /// its pieces' ends, in run order, from run_ends[ends_first].
    struct Band {
        double t0, ya, w;
        int sections;
        size_t first, last, head, ends_first;
    };
    std::vector<Segment> blockers;  // for the caller: the blockers to pass
    std::vector<Vec2> local;        // the blockers' ends in the pair's frame, clipped to the slab
    /// The pieces by the depth of their midpoints (sorted on depth alone).
    struct Depth {
        double mid;
        size_t piece;
    };
    std::vector<Depth> by_depth;
    /// by_depth's buckets of depth: bucket b holds places [depth_first[b],
    /// depth_first[b + 1]), sorted once depth_sorted[b] (band_bound).
    std::vector<size_t> depth_first, depth_fill;
    std::vector<char> depth_sorted;
    std::vector<double> depth_mid;
    std::vector<Vec2> run_ends;     // the bands' pieces' ends, band after band (Band::ends_first)
    std::vector<Band> bands;
    std::vector<Vec2> points;
    std::vector<double> radius;
    /// A piece in a section's bucket: its ends p, q about the section's
    /// midpoint O, and their distances |p|, |q| to it.
    struct Item {
        Vec2 p, q;
        double rp, rq;
    };
    /// A band's pieces by section, for a group of consecutive bins
    /// (band_bound's bins loop): items[first[s], first[s + 1]) are section
    /// s's, in the band's run order, read in sequence by each bin's check.
    struct Buckets {
        std::vector<size_t> first;
        std::vector<Item> items;
        int group = -1;       // the group they are for (-1: none yet)
        int group_size = 0;   // bins per group (0: not chosen yet)
    };
    Buckets buckets[3];  // per band (opaque_band_count)
    std::vector<size_t> bucket_fill;
    std::vector<std::pair<int, int>> bucket_range;
    std::vector<Interval> shadows;
};

/// Bands tried, at depths evenly spaced between the patches.
inline constexpr int opaque_band_count = 3;
static_assert(sizeof(OpaqueBandScratch::buckets) / sizeof(OpaqueBandScratch::Buckets) == opaque_band_count,
              "one bucketing per band");
/// Pieces in a band: those nearest to its depth until the lengths of their
/// shadows across the pair's axis add up to this many times the section X
/// (a dense forest's band then covers X with room for the drift), or
/// opaque_band_max_pieces. With 6, a quarter of the proofs of closure on
/// the 10^5 forest at eps 10 (12 325 of 49 960, one thread) failed at a
/// bin: the shadows, narrowed by their drift, left gaps. With 8, 2 260 of
/// 25 110 (the proofs that close drop links whole, higher up the tree, so
/// fewer are asked): that forest 7.4-7.5 -> 6.4-6.8 s on two threads
/// (cluster visits 141 M -> 92 M), the 10^6 forest's solve 106 -> 99.5 s
/// (2.45 G cluster visits against 3.21 G); 9 and 10 layers about as good
/// (10.1 and 10.5 s against 9.6 s on one thread), 12 worse (more proofs
/// past opaque_band_max_bins: 11.9 s). The 10^3 and 10^4 forests and
/// data/forest.json at eps 0.1 and 1: the same errors, times within noise.
inline constexpr double opaque_band_layers = 8;
/// Shafts whose pieces' shadows add up to fewer layers than this over the
/// whole slab (their sum over the shaft's mean width; with the bands'
/// depths given, over the narrowest of their sections) are not tried: a
/// band holds a share of them. (On the 10^3 forest of `scripts/bench
/// versus` at eps 4, trying from 0 layers took 14% more instructions than
/// from 8, for 13% more shafts shown closed.)
inline constexpr double opaque_band_min_layers = 8;
inline constexpr size_t opaque_band_max_pieces = 2048;
/// A band's section X is checked in pieces about this many mean shadows
/// wide (at most opaque_band_max_sections), each turned about its own
/// midpoint.
inline constexpr double opaque_band_section_shadows = 4;
inline constexpr int opaque_band_max_sections = 32;
/// Bins over the range of directions: at least opaque_band_initial_bins,
/// and narrow enough that the middle band's pieces drift by at most
/// opaque_band_drift of their mean shadow within one (a deep band of thin
/// sticks needs narrow bins); past opaque_band_max_bins the proof is not
/// tried.
inline constexpr int opaque_band_initial_bins = 16;
inline constexpr double opaque_band_drift = 0.25;
inline constexpr int opaque_band_max_bins = 128;
/// Nor past this many section checks (the middle band's sections times the
/// bins): shafts that wide and deep (across a 10^4-segment forest, 1000 to
/// 8000 pieces) were almost never shown closed, and trying cost 15% of
/// that run (the 10^4 forest at eps 1: 12.6 s trying all, 10.9 s with
/// this cap, 11.4 s without the proofs; the 1000-segment forest at eps 4:
/// +10% instructions trying all, +1.4% with it, the same shafts closed to
/// 1%). That cap was 256 until the box proofs (box_closure.h) of the 10^6
/// forest at eps 10 met it: 78 000 of their proofs were refused for it
/// (wide shafts: boxes of 3-10 units 40-60 apart). With 1024 the form
/// factors took 42.6 s instead of 46.2 s (one run each; cluster visits
/// 1.56 G -> 1.17 G), about the same with 4096; on the 10^5 forest (one
/// thread, callgrind) 75.1 G instructions against 76.0 G with 256, 76.1 G
/// with 2048, 76.5 G with 4096.
inline constexpr double opaque_band_max_checks = 1024;
/// With a tolerance (band_bound's limit > 0: a bound within it answers the
/// query), the bins need only keep the drift within the mean shadow, and the
/// cap is higher: a bound pays for shafts across a forest, where the
/// direction bounds sort every piece of the shaft in each of their bins.
/// Measured on the forests of `scripts/make-scene N --density 30` (2 cores,
/// one run each): at 10^4 segments, eps 1, 10.3 s with the proof alone
/// (opaque_band_drift, opaque_band_max_checks), 8.6 s with bounds (drift 1,
/// 1024 checks; 8.9 s with drift 0.25 and no cap), eps 0.1 34.1 s and 28.5
/// s; at 10^3, eps 5 and 0.1, the same times within 3%.
inline constexpr double band_bound_drift = 1;
inline constexpr double band_bound_max_checks = 1024;

/// A bin whose bands all leave more free than its share is checked again
/// in halves, each half that does the same halved again, this many times
/// at most (a gap may be the drift's, not the band's: within a half each
/// piece drifts half as far, and its narrowed shadow is wider). A true gap
/// at some direction stays open at any width, and costs about two checks
/// per band and halving on its way down. On the 10^6 forest at eps 10
/// (`scripts/make-scene 1000000 --seed 1 --density 30`, 2 threads, one run
/// each): form factors 42.6 s with none, 30.9 / 30.3 / 28.7 / 27.7 s with
/// 2 / 3 / 5 / 8 (cluster visits 1.17 G -> 0.77 G: links closed whole
/// higher up the tree).
inline constexpr int opaque_band_halvings = 8;

struct BandOptions {
    double limit = 0;  ///< give up once the bound would exceed this (0: the proof of closure)
    int halvings = opaque_band_halvings;  ///< see above (0: bins of one width)
    double max_checks = opaque_band_max_checks;  ///< see above
    double drift = opaque_band_drift;            ///< bins narrow enough for this drift (see above)
    /// The bands' depths t0 along the pair's axis (PairFrame of ci, cj),
    /// the first built first, each within the slab between the patches;
    /// null: evenly spaced (band_depth), the middle one first.
    const double* depths = nullptr;
    /// Pieces per bucket of depth when finding the bands' runs (see
    /// band_bound's .cpp): any value gives the same answer, bit for bit;
    /// SIZE_MAX sorts all the pieces at once (for tests: the oracle).
    size_t depth_bucket = 16;
};

/// Depth of band k (0 first) with evenly spaced bands between xi and xj:
/// the middle one first, then the one nearer j, then the one nearer i.
inline double band_depth(int k, double xi, double xj) {
    const int slot = (k + opaque_band_count / 2) % opaque_band_count;
    return xi + (xj - xi) * (slot + 0.5) / opaque_band_count;
}

/// Whether the shaft of ci and cj (as band_bound takes them) is no wider
/// across its axis at ci's end than at cj's: where bands need fewest pieces.
bool narrower_at_i(const Segment& ci, const Segment& cj);

/// An upper bound on L_i F_ij, the exchange of ci and cj (a mutually
/// clipped facing pair lit on the left) through the blockers (whole
/// segments: each is clipped here to the depths between the patches), from
/// bands of them (above). Returns +infinity when the bound would exceed
/// options.limit, and when the attempt is not made: pairs whose depth
/// ranges touch along the pair's axis (a shared endpoint: no slab between
/// them), shafts with fewer than opaque_band_min_layers, or more than
/// options.max_checks section checks (the middle band's sections times the
/// bins). With limit 0 it is the proof that the shaft is closed: 0 or
/// +infinity. The first bin that takes the sum past the limit, even
/// checked in halves (options.halvings), ends the attempt.
double band_bound(const Segment& ci, const Segment& cj, const Segment* blockers, size_t count,
                  const BandOptions& options, OpaqueBandScratch& scratch);

/// One step of a band section's check (band_bound's, per bin and section):
/// each item's shadow held at every direction of a bin (held() of its
/// ends' offsets n . p, n . q, widened by rp h and rq h), written in order
/// to kept[0, m) when it is not empty and meets `window`; returns m. kept
/// needs room for count intervals (a dropped shadow's place is written
/// over). With AVX four items a step, the same shadows bit for bit
/// (tests/visibility/opaque_band_test.cpp checks it against the obvious
/// loop, NaN and signed zeros included).
size_t held_in_window(const OpaqueBandScratch::Item* items, size_t count, Vec2 n, double h, OffsetInterval window,
                      OffsetInterval* kept);

/// True when the blockers are shown to stop every line from ci to cj
/// (band_bound with limit 0 and the proof's settings).
inline bool band_closes_shaft(const Segment& ci, const Segment& cj, const Segment* blockers, size_t count,
                              OpaqueBandScratch& scratch) {
    return band_bound(ci, cj, blockers, count, BandOptions{}, scratch) == 0;
}

}  // namespace flatrad
