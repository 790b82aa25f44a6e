#pragma once
/// A cheap proof that a crowded shaft is closed (its exchange exactly 0),
/// from a band of its blockers across it.
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
/// Why it pays: the bounds of a long shaft through a dense forest turn
/// about the shaft's centre, and within one of their bins the far pieces
/// move by more than their own shadows: their lower bound is 0 and their
/// upper a sizeable share of the window, so their midpoint claims light
/// where the truth is ~exp(-depth x density x mean shadow). A band a few
/// layers deep shows the 0 for a few small sorts.
///
/// Only a proof: false means "not shown closed", never "open". Rounding
/// can only misplace shadow ends by ulps of the coordinates: gaps of that
/// measure, as in the exact integral.
#include <cstddef>
#include <vector>

#include "engine/geometry.h"
#include "visibility/direction_bounds.h"

namespace flatrad {

/// Scratch memory of one thread.
struct OpaqueBandScratch {
    using Interval = OffsetInterval;
    struct Bin {
        double c, h;
    };
    std::vector<Segment> blockers;  // for the caller: the blockers to pass
    std::vector<Vec2> local;        // the blockers' ends in the pair's frame, clipped to the slab
    std::vector<double> mid;
    std::vector<size_t> bucket_first, bucket_fill, bucket_items;  // a band's pieces by section
    std::vector<size_t> index;
    std::vector<Vec2> points;  // per section: its ends, 4 side points, its pieces' ends; about its midpoint
    std::vector<double> radius;
    std::vector<Interval> shadows;
    struct Section {
        size_t first, count;
    };
    std::vector<Section> sections;
};

/// Bands tried, at depths evenly spaced between the patches.
inline constexpr int opaque_band_count = 3;
/// Pieces in a band: those nearest to its depth until the lengths of their
/// shadows across the pair's axis add up to this many times the section X
/// (a dense forest's band then covers X with room for the drift), or
/// opaque_band_max_pieces.
inline constexpr double opaque_band_layers = 6;
/// Shafts whose pieces' shadows add up to fewer layers than this over the
/// whole slab (their sum over the shaft's mean width) are not tried: a
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
/// 1%).
inline constexpr double opaque_band_max_checks = 256;

/// True when the blockers (whole segments: each is clipped here to the
/// depths between the patches) are shown to stop every line from ci to cj,
/// a mutually clipped facing pair lit on the left. Pairs whose depth
/// ranges touch along the pair's axis (a shared endpoint: no slab between
/// them) are not tried.
bool band_closes_shaft(const Segment& ci, const Segment& cj, const Segment* blockers, size_t count,
                       OpaqueBandScratch& scratch);

}  // namespace flatrad
