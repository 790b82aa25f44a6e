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
#include <utility>
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

/// Per cluster and per group, one value per bin held, held bin after bin:
/// a direction's pass writes its own bins' runs, not one value in every
/// cluster's row of K (rows written a bin at a time by every pass kept the
/// passes waiting on memory: on the 10^6 forest of `scripts/make-scene
/// 1000000 --seed 1 --density 30`, two threads, the passes took 3.6 s with
/// rows, 3.0 s with runs; a caller that reads the clusters in their order
/// reads its bins' runs in step).
/// (Each pass also writes its bins' defaults: the columns' pages are first
/// touched by the passes, side by side, not by one thread beforehand.)
///
/// The bins held: the passes [first_pass, first_pass + passes) of the K/2
/// direction pairs, that is bins first_pass .. first_pass + passes - 1 and
/// the same plus K/2. All K by default; a caller that consumes the shares
/// a few passes at a time (the hierarchical solver) holds only those: at
/// 10^6 segments all K bins are 1 GB of doubles.
struct EnvelopeShares {
    using Column = std::vector<double, UninitializedAllocator<double>>;
    size_t clusters = 0, groups = 0;
    int first_pass = 0, passes = directional_bins / 2;
    Column whole_by_bin;  ///< cluster c, bin k at column(k) * clusters + c
    Column group_by_bin;  ///< group g, bin k at column(k) * groups + g
    Column front_by_bin;  ///< cluster c, bin k at column(k) * clusters + c
    /// Whether bin k is held.
    bool holds(int k) const {
        const int pass = k % (directional_bins / 2);
        return k >= 0 && k < directional_bins && pass >= first_pass && pass < first_pass + passes;
    }
    /// Bin k's column (k held).
    size_t column(int k) const {
        const int pair = directional_bins / 2;
        return static_cast<size_t>(k < pair ? k - first_pass : passes + (k - pair - first_pass));
    }
    /// Cluster c's visible_fraction `out` at bin k.
    double whole(size_t c, int k) const { return whole_by_bin[column(k) * clusters + c]; }
    /// Group g's `group_out` at bin k.
    double group(size_t g, int k) const { return group_by_bin[column(k) * groups + g]; }
    /// Cluster c's `front` at bin k (NaN: nothing seen).
    double front(size_t c, int k) const { return front_by_bin[column(k) * clusters + c]; }
};

/// The measure of every cluster of `clusters` (sides_at[q]: the sides bits,
/// self_occlusion.h's left_side, right_side, blocks, of the segment at
/// place q of h.order(); segments from h.segment_at(q)), set up once and
/// run a few direction pairs at a time. Keeps references to its arguments.
class EnvelopeMeasure {
public:
    EnvelopeMeasure(const Hierarchy& h, const std::vector<uint8_t>& sides_at, const EnvelopeClusters& clusters);
    /// The shares of the passes [first_pass, first_pass + passes) (0 <=
    /// first_pass, passes >= 1, first_pass + passes <= K/2) into `out`,
    /// whose columns are reused (grown only if too small). The passes are
    /// shared among `threads` threads.
    void run(int first_pass, int passes, int threads, EnvelopeShares& out) const;

private:
    const Hierarchy& m_h;
    const std::vector<uint8_t>& m_sides;
    const EnvelopeClusters& m_clusters;
    std::vector<int32_t> m_wanted, m_non_blockers;
    std::vector<std::pair<int32_t, int32_t>> m_by_first, m_nb_range;
};

/// Every bin at once (EnvelopeMeasure, all K/2 passes). Bins are shared
/// among `threads` threads.
EnvelopeShares cluster_visible_fractions(const Hierarchy& h, const std::vector<uint8_t>& sides_at,
                                         const EnvelopeClusters& clusters, int threads = 1);

}  // namespace flatrad
