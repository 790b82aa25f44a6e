#pragma once
/// Occlusion inside a cluster: how much of its members' sensitivity is seen
/// from outside it (DESIGN.md §3, "cluster senders and receivers need a
/// directional model").
///
/// A cluster's directional tables sum its members' cosine lobes, L cos+(n .
/// u): the sensitivity N(psi) and the exitance I(phi). That sum counts every
/// side facing a direction, also a side behind another member of the same
/// cluster, which no light from outside reaches and whose light never
/// leaves (a forest of blockers: a cluster of a hundred sticks holds tens
/// of layers). Transmittances between clusters skip the two clusters' own
/// contents (visibility/multiscale.h), so nothing else counts this loss:
/// without it a cluster link gives every hidden member its full share, and
/// the solution absorbs more than is emitted.
///
/// visible_fraction() measures, for one set of segments (the hierarchical
/// solver measures all its clusters at once, exactly, by merged front
/// envelopes: solver/front_envelopes.h, tested against this), per
/// direction bin, the share of the lobe
/// sum that is seen from far along that direction: a 1D visible-surface
/// problem (the frontmost segment per line across the cluster), solved on
/// a grid of lines across the set's extent, as a depth buffer. Seen from a
/// link's other end the lines are not parallel; this is the cluster's own
/// point approximation, whose error the link's error estimate carries.
#include <cstddef>
#include <cstdint>

#include "engine/geometry.h"
#include "solver/directional.h"

namespace flatrad {

/// Which sides of a segment exist (receive and send): bit 0 its left side
/// (engine/geometry.h's left normal), bit 1 its right side; bit 2 whether
/// the segment can block light at all (engine/hierarchy.h's set_blockers:
/// a wall on the scene's hull stands between nothing, and hides nothing).
inline constexpr uint8_t left_side = 1, right_side = 2, blocks = 4;

/// Which of segment s's existing sides (`has`, the bits above) face u and
/// -u, seen from far along each: way[0] along u (the side whose normal is
/// along u), way[1] along -u (a segment along u faces neither).
struct Facing {
    bool way[2];
};
inline Facing facing_ways(const Segment& s, uint8_t has, Vec2 u) {
    const double c = dot(s.left_normal(), u);
    const uint8_t along = c > 0 ? left_side : c < 0 ? right_side : 0;
    const uint8_t against = c > 0 ? right_side : c < 0 ? left_side : 0;
    return {{(has & along) != 0, (has & against) != 0}};
}

/// Up to this many segments visible_fraction is exact (see there).
inline constexpr size_t exact_up_to = 24;

/// Per direction bin k (directional.h's u_k): the fraction of sum over
/// existing sides of L cos+(n . u_k) that lies on sides not hidden, along
/// u_k, by another of the `n` segments: along each line of direction u_k,
/// seen from +u_k, the frontmost blocking segment is seen (whether or not
/// its side exists, it hides what lies behind), and so is every segment
/// that cannot block in front of it. 1 where no segment's projection
/// overlaps another's, and where nothing faces u_k.
///
/// With lines = 0 and at most exact_up_to segments, exactly (per side, its
/// interval across u minus the overlaps with blockers in front of it; n^2
/// per bin). Otherwise measured on `lines` equally spaced lines across the
/// set's extent (each counts the sides it meets): a share is exact to about
/// one line's width per visible run; with lines = 0, 2 per segment, at
/// most 1024. Cost: per bin, n plus lines times the mean depth in layers.
/// (On the 1000-segment forest the lines alone, 64 at least, were 18% of
/// a run at eps 1000; most clusters hold a few segments.)
void visible_fraction(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins],
                      int lines = 0);

/// The same, and per group of the segments (segment i in group[i], in 0 ..
/// groups - 1; a cluster's children): the share of each group's own lobes
/// seen from outside the whole set, written to group_out[g * K + k] (1
/// where none of the group's sides faces u_k). Measured on the same lines
/// (or exactly) as `out`, so that out's share is the groups' seen lobes
/// over all of their lobes.
/// With `front` (K values, not null), also per bin k the mean depth along
/// u_k, dot(x, u_k), of the lobes seen from far along u_k (each visible
/// part at its side's middle on the exact path, at the line's crossing on
/// lines): where the cluster's visible face lies. NaN where nothing is
/// seen (n < 2 included).
void visible_fraction(const Segment* segs, const uint8_t* sides, size_t n, double out[directional_bins],
                      const int32_t* group, int groups, double* group_out, int lines = 0, double* front = nullptr);

}  // namespace flatrad
