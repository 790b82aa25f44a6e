#pragma once
/// Occlusion inside every cluster of a hierarchy at once, exactly, by
/// merging front envelopes bottom-up.
///
/// What visible_fraction (solver/self_occlusion.h) gives for one set of
/// segments, with groups, and its `front`: per direction bin u_k, the
/// share of the existing sides facing u_k that is seen from far along u_k
/// (the frontmost blocking segment of each line across u_k is seen, and
/// so is every segment that cannot block in front of it), per group and
/// in all, and the mean depth dot(x, u_k) of what is seen. Here for many
/// nested sets at once: the clusters of a Hierarchy, each with its
/// children as groups.
///
/// Along u_k a set's blockers have a front envelope: over the axis across
/// u_k, the piecewise-linear depth of the frontmost blocker, each piece
/// labelled with its segment. A cluster's envelope is the pointwise
/// front of its children's: a merge of two sorted lists of pieces in one
/// pass (where two pieces overlap, the one in front, split at the point
/// where they cross if they do). The pieces of a facing side are its
/// seen part; a segment that cannot block is seen where it lies in front
/// of the envelope. Bin k + K/2 looks along -u_k: the same pieces with
/// the back envelope (the least depth). So every cluster costs about its
/// envelopes' sizes (the visible pieces, not the members) per bin, where
/// measuring each cluster from its members costs their number times the
/// layers they make (visible_fraction's lines); and the answer is exact
/// at every size, where visible_fraction is exact only up to exact_up_to
/// members (to rounding: the same numbers as its exact path, up to the
/// order of summation; `front` exactly, where its exact path takes each
/// seen part at its segment's middle).
///
/// Not finite where projections overflow (coordinates near the largest
/// double): such a bin is left unmeasured for every cluster (shares 1,
/// front NaN), as visible_fraction leaves a set whose extent overflows.
#include <cstdint>
#include <vector>

#include "engine/hierarchy.h"
#include "solver/directional.h"
#include "solver/uninitialized_allocator.h"

namespace flatrad {

/// The clusters to measure and their groups.
struct EnvelopeClusters {
    /// Hierarchy nodes, each with at least two members (others are not
    /// measured: shares 1, front NaN).
    std::vector<int32_t> node;
    /// Node c's groups are [group_begin[c], group_begin[c + 1]) (size
    /// node.size() + 1).
    std::vector<int32_t> group_begin;
    /// Per group: its hierarchy node, whose places in the hierarchy's
    /// order make up the group. A cluster's groups tile its places (in any
    /// order).
    std::vector<int32_t> group_node;
};

/// Per cluster and per group, K = directional_bins values each, held bin
/// after bin: a direction's pass writes its own bins' runs, not one value
/// in every cluster's row of K (rows written a bin at a time by every pass
/// kept the passes waiting on memory: on the 10^6 forest of `scripts/
/// make-scene 1000000 --seed 1 --density 30`, two threads, the passes took
/// 3.6 s with rows, 3.0 s with runs; a caller that reads the clusters in
/// their order reads K runs in step).
/// (Each pass also writes its bins' defaults: the columns' pages are first
/// touched by the passes, side by side, not by one thread beforehand.)
struct EnvelopeShares {
    using Column = std::vector<double, UninitializedAllocator<double>>;
    size_t clusters = 0, groups = 0;
    Column whole_by_bin;  ///< cluster c, bin k at k * clusters + c
    Column group_by_bin;  ///< group g, bin k at k * groups + g
    Column front_by_bin;  ///< cluster c, bin k at k * clusters + c
    /// Cluster c's visible_fraction `out` at bin k.
    double whole(size_t c, int k) const { return whole_by_bin[static_cast<size_t>(k) * clusters + c]; }
    /// Group g's `group_out` at bin k.
    double group(size_t g, int k) const { return group_by_bin[static_cast<size_t>(k) * groups + g]; }
    /// Cluster c's `front` at bin k (NaN: nothing seen).
    double front(size_t c, int k) const { return front_by_bin[static_cast<size_t>(k) * clusters + c]; }
};

/// `sides_at[q]`: the sides bits (self_occlusion.h's left_side, right_side,
/// blocks) of the segment at place q of h.order(); segments from
/// h.segment_at(q). Bins are shared among `threads` threads.
EnvelopeShares cluster_visible_fractions(const Hierarchy& h, const std::vector<uint8_t>& sides_at,
                                         const EnvelopeClusters& clusters, int threads = 1);

}  // namespace flatrad
