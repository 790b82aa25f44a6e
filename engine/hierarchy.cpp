#include "engine/hierarchy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/error.h"

namespace flatrad {

namespace {
// Bins of the surface-area heuristic: 16 planes are within a few percent of
// the best plane on real scenes, at linear cost per node.
constexpr int sah_bins = 16;
}  // namespace

Hierarchy::Hierarchy(const std::vector<Segment>& segments, int leaf_size, const std::vector<char>& alone)
    : m_segments(segments) {
    FLATRAD_ASSERT(leaf_size >= 1, "leaf size must be positive");
    if (!alone.empty() && alone.size() != segments.size())
        throw std::invalid_argument("Hierarchy: one 'alone' flag per segment expected");
    const int32_t n = static_cast<int32_t>(segments.size());
    if (n == 0) return;
    m_order.resize(static_cast<size_t>(n));
    std::vector<Vec2> centroid(static_cast<size_t>(n));
    for (int32_t k = 0; k < n; ++k) {
        m_order[static_cast<size_t>(k)] = k;
        centroid[static_cast<size_t>(k)] = segments[static_cast<size_t>(k)].midpoint();
    }
    m_nodes.reserve(static_cast<size_t>(2 * (n / leaf_size) + 2));
    // Below this depth the heuristic may make unbalanced splits; past it
    // every split is a median one, so depth <= sah_depth_limit + log2(N).
    const int sah_depth_limit = 2 * static_cast<int>(std::ceil(std::log2(static_cast<double>(n) + 1))) + 4;

    // Iterative top-down build; each entry is a node still to split.
    struct Todo { int32_t node; };
    std::vector<Todo> todo;
    m_nodes.push_back(ClusterNode{});
    m_nodes[0].first = 0;
    m_nodes[0].count = n;
    todo.push_back({0});
    while (!todo.empty()) {
        const int32_t k = todo.back().node;
        todo.pop_back();
        ClusterNode nd = m_nodes[static_cast<size_t>(k)];
        Box box, cbox;
        bool holds_alone = false;  // a segment that must have a leaf of its own
        for (int32_t q = nd.first; q < nd.first + nd.count; ++q) {
            const int32_t s = m_order[static_cast<size_t>(q)];
            box.add(segments[static_cast<size_t>(s)]);
            cbox.add(centroid[static_cast<size_t>(s)]);
            holds_alone = holds_alone || (!alone.empty() && alone[static_cast<size_t>(s)]);
        }
        nd.box = box;
        m_depth = std::max(m_depth, nd.depth + 1);
        const Vec2 ext = cbox.extent();
        const bool leaf = nd.count == 1 || (nd.count <= leaf_size && !holds_alone);
        if (!leaf && (ext.x > 0 || ext.y > 0)) {
            // Split along the longer axis of the centroids' box, at the
            // binned surface-area-heuristic plane (2D: the sum over the two
            // children of box perimeter x count), which separates outliers
            // and gaps (a cluster of blockers apart from the walls becomes
            // one node). Too deep a path, or no usable plane, falls back to
            // the median, so depth stays O(log N) and the build O(N log N).
            const bool along_x = ext.x >= ext.y;
            const double c0 = along_x ? cbox.lo.x : cbox.lo.y;
            const double width = along_x ? ext.x : ext.y;
            auto coord = [&](int32_t u) {
                const Vec2 c = centroid[static_cast<size_t>(u)];
                return along_x ? c.x : c.y;
            };
            auto bin_of = [&](int32_t u) {
                return std::min(sah_bins - 1, static_cast<int>((coord(u) - c0) / width * sah_bins));
            };
            int32_t mid = -1;
            if (nd.depth < sah_depth_limit) {
                Box bin_box[sah_bins];
                int32_t bin_count[sah_bins] = {};
                for (int32_t q = nd.first; q < nd.first + nd.count; ++q) {
                    const int32_t u = m_order[static_cast<size_t>(q)];
                    const int b = bin_of(u);
                    bin_box[b].add(segments[static_cast<size_t>(u)]);
                    ++bin_count[b];
                }
                auto perimeter = [](const Box& b) { return b.empty() ? 0.0 : 2 * (b.extent().x + b.extent().y); };
                // Suffix sweep, then prefix sweep choosing the cheapest plane.
                double right_cost[sah_bins];
                Box acc;
                int32_t cnt = 0;
                for (int b = sah_bins - 1; b > 0; --b) {
                    acc.add(bin_box[b]);
                    cnt += bin_count[b];
                    right_cost[b] = perimeter(acc) * cnt;
                }
                acc = Box{};
                cnt = 0;
                double best = std::numeric_limits<double>::infinity();
                int best_plane = -1;
                for (int b = 0; b + 1 < sah_bins; ++b) {
                    acc.add(bin_box[b]);
                    cnt += bin_count[b];
                    if (cnt == 0 || cnt == nd.count) continue;
                    const double cost = perimeter(acc) * cnt + right_cost[b + 1];
                    if (cost < best) {
                        best = cost;
                        best_plane = b + 1;
                    }
                }
                // A wide empty band between centroids (at least two empty
                // bins, an eighth of the extent) is a natural boundary
                // between groups: split in its middle, whatever the
                // heuristic says (it would rather halve a dense group
                // flanked by long walls).
                int run = 0, best_run = 0, run_end = -1;
                for (int b = 0; b < sah_bins; ++b) {
                    run = bin_count[b] == 0 ? run + 1 : 0;
                    if (run > best_run) {
                        best_run = run;
                        run_end = b;
                    }
                }
                if (best_run >= 2 && run_end < sah_bins - 1) best_plane = run_end - best_run / 2;
                if (best_plane > 0) {
                    auto split = std::partition(m_order.begin() + nd.first, m_order.begin() + nd.first + nd.count,
                                                [&](int32_t u) { return bin_of(u) < best_plane; });
                    mid = static_cast<int32_t>(split - m_order.begin());
                }
            }
            if (mid <= nd.first || mid >= nd.first + nd.count) {
                mid = nd.first + nd.count / 2;
                auto begin = m_order.begin() + nd.first;
                std::nth_element(begin, m_order.begin() + mid, begin + nd.count, [&](int32_t u, int32_t v) {
                    const double cu = coord(u), cv = coord(v);
                    return cu < cv || (cu == cv && u < v);
                });
            }
            const int32_t left = static_cast<int32_t>(m_nodes.size());
            ClusterNode l, r;
            l.first = nd.first;
            l.count = mid - nd.first;
            r.first = mid;
            r.count = nd.first + nd.count - mid;
            l.parent = r.parent = k;
            l.depth = r.depth = nd.depth + 1;
            m_nodes.push_back(l);
            m_nodes.push_back(r);
            nd.child[0] = left;
            nd.child[1] = left + 1;
            todo.push_back({left + 1});
            todo.push_back({left});
        }
        m_nodes[static_cast<size_t>(k)] = nd;
    }
    for (ClusterNode& nd : m_nodes) nd.blockers = nd.count;
    m_ordered.resize(m_order.size());
    for (size_t q = 0; q < m_order.size(); ++q) m_ordered[q] = m_segments[static_cast<size_t>(m_order[q])];
}

void Hierarchy::set_blockers(const std::vector<char>& can_block) {
    if (can_block.size() != m_segments.size())
        throw std::invalid_argument("Hierarchy::set_blockers: one flag per segment expected");
    m_can_block = can_block;
    m_can_block_at.resize(m_order.size());
    for (size_t q = 0; q < m_order.size(); ++q) m_can_block_at[q] = can_block[static_cast<size_t>(m_order[q])];
    // Children come after their parents: count bottom-up.
    for (size_t k = m_nodes.size(); k-- > 0;) {
        ClusterNode& nd = m_nodes[k];
        if (nd.leaf()) {
            nd.blockers = 0;
            for (int32_t q = nd.first; q < nd.first + nd.count; ++q)
                nd.blockers += can_block[static_cast<size_t>(m_order[static_cast<size_t>(q)])] ? 1 : 0;
        } else {
            nd.blockers = m_nodes[static_cast<size_t>(nd.child[0])].blockers + m_nodes[static_cast<size_t>(nd.child[1])].blockers;
        }
    }
}

}  // namespace flatrad
