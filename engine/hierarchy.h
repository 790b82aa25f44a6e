#pragma once
/// The cluster hierarchy: a binary tree of axis-aligned boxes over the scene's
/// segments, shared by the visibility module and the hierarchical solver.
///
/// Built top-down: each node splits its segments along the longer axis of
/// the centroids' box at the plane (among 16 bins) that minimizes the
/// surface-area heuristic, sum over the children of box perimeter x count.
/// That plane separates gaps and outliers, so a compact group of blockers
/// away from the walls becomes one node (what the multi-scale criterion
/// needs). Unbalanced splits are allowed only down to depth
/// 2 ceil(log2(N + 1)) + 4; deeper, or when no plane separates anything,
/// the split is at the median centroid. So depth <= that limit + log2(N)
/// and the build is O(N log N). Sibling boxes may overlap, which costs a
/// little culling power but never correctness.
#include <cstdint>
#include <vector>

#include "engine/geometry.h"

namespace flatrad {

struct ClusterNode {
    Box box;                 ///< tight box of the node's segments
    int32_t child[2] = {-1, -1};  ///< children (both -1 for a leaf)
    int32_t parent = -1;
    int32_t first = 0;       ///< the node's segments are order[first .. first+count)
    int32_t count = 0;
    int32_t depth = 0;
    int32_t blockers = 0;    ///< how many of them can block (all, unless Hierarchy::set_blockers said otherwise)
    bool leaf() const { return child[0] < 0; }
};

class Hierarchy {
public:
    Hierarchy() = default;
    /// Builds over `segments` (indices are the caller's segment numbers).
    /// Leaves hold at most `leaf_size` segments (>= 1); a segment flagged
    /// in `alone` (empty, or one flag per segment) gets a leaf of its own
    /// (the hierarchical solver's blockers, among walls grouped by 8).
    explicit Hierarchy(const std::vector<Segment>& segments, int leaf_size = 2, const std::vector<char>& alone = {});

    const std::vector<ClusterNode>& nodes() const { return m_nodes; }
    const ClusterNode& node(int k) const { return m_nodes[static_cast<size_t>(k)]; }
    int root() const { return m_nodes.empty() ? -1 : 0; }
    /// Segment numbers, grouped so that each node's are contiguous.
    const std::vector<int32_t>& order() const { return m_order; }
    const std::vector<Segment>& segments() const { return m_segments; }
    /// The segment at place q of order(), kept in that order too: a walk
    /// through neighbouring leaves reads it in sequence (segments() is in
    /// the caller's order, scattered over the whole scene).
    const Segment& segment_at(int32_t q) const { return m_ordered[static_cast<size_t>(q)]; }
    int depth() const { return m_depth; }

    /// Marks which segments can block light (`can_block[segment number]`,
    /// e.g. engine/convex_scene.h's possible_blockers): the visibility
    /// module skips the others, and nodes with no blocker below. Every
    /// segment can block until this is called.
    void set_blockers(const std::vector<char>& can_block);
    bool can_block(int segment) const {
        return m_can_block.empty() || m_can_block[static_cast<size_t>(segment)] != 0;
    }
    /// can_block of the segment at place q of order().
    bool can_block_at(int32_t q) const {
        return m_can_block_at.empty() || m_can_block_at[static_cast<size_t>(q)] != 0;
    }

    /// Visits every segment whose node boxes pass `box_test(const Box&)`,
    /// calling `on_segment(int segment_number, const Segment&)`. Returns the
    /// number of nodes visited (for stats).
    template <class BoxTest, class OnSegment>
    long query(BoxTest&& box_test, OnSegment&& on_segment, std::vector<int32_t>& stack) const {
        return walk<false>(box_test, on_segment, stack);
    }
    /// The same over the segments that can block (set_blockers), never
    /// entering a node with none below.
    template <class BoxTest, class OnSegment>
    long query_blockers(BoxTest&& box_test, OnSegment&& on_segment, std::vector<int32_t>& stack) const {
        return walk<true>(box_test, on_segment, stack);
    }

private:
    template <bool only_blockers, class BoxTest, class OnSegment>
    long walk(BoxTest& box_test, OnSegment& on_segment, std::vector<int32_t>& stack) const {
        long visited = 0;
        if (m_nodes.empty()) return 0;
        stack.clear();
        stack.push_back(0);
        while (!stack.empty()) {
            const ClusterNode& n = m_nodes[static_cast<size_t>(stack.back())];
            stack.pop_back();
            if (only_blockers && n.blockers == 0) continue;
            ++visited;
            if (!box_test(n.box)) continue;
            if (n.leaf()) {
                for (int32_t k = n.first; k < n.first + n.count; ++k) {
                    if (only_blockers && !can_block_at(k)) continue;
                    on_segment(m_order[static_cast<size_t>(k)], m_ordered[static_cast<size_t>(k)]);
                }
            } else {
                stack.push_back(n.child[1]);
                stack.push_back(n.child[0]);
            }
        }
        return visited;
    }

    std::vector<ClusterNode> m_nodes;
    std::vector<int32_t> m_order;
    std::vector<Segment> m_segments;
    std::vector<char> m_can_block;  // per segment number; empty: all
    std::vector<Segment> m_ordered;    // m_segments[m_order[q]] at q
    std::vector<char> m_can_block_at;  // m_can_block[m_order[q]] at q; empty: all
    int m_depth = 0;
};

}  // namespace flatrad
