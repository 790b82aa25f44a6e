#include "engine/hierarchy.h"

#include <algorithm>

#include "engine/error.h"

namespace flatrad {

Hierarchy::Hierarchy(const std::vector<Segment>& segments, int leaf_size) : m_segments(segments) {
    FLATRAD_ASSERT(leaf_size >= 1, "leaf size must be positive");
    const int32_t n = static_cast<int32_t>(segments.size());
    if (n == 0) return;
    m_order.resize(static_cast<size_t>(n));
    std::vector<Vec2> centroid(static_cast<size_t>(n));
    for (int32_t k = 0; k < n; ++k) {
        m_order[static_cast<size_t>(k)] = k;
        centroid[static_cast<size_t>(k)] = segments[static_cast<size_t>(k)].midpoint();
    }
    m_nodes.reserve(static_cast<size_t>(2 * (n / leaf_size) + 2));

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
        for (int32_t q = nd.first; q < nd.first + nd.count; ++q) {
            const int32_t s = m_order[static_cast<size_t>(q)];
            box.add(segments[static_cast<size_t>(s)]);
            cbox.add(centroid[static_cast<size_t>(s)]);
        }
        nd.box = box;
        m_depth = std::max(m_depth, nd.depth + 1);
        const Vec2 ext = cbox.extent();
        if (nd.count > leaf_size && (ext.x > 0 || ext.y > 0)) {
            // Median split along the longer axis of the centroids' box.
            const bool along_x = ext.x >= ext.y;
            const int32_t mid = nd.first + nd.count / 2;
            auto begin = m_order.begin() + nd.first;
            std::nth_element(begin, m_order.begin() + mid, begin + nd.count, [&](int32_t u, int32_t v) {
                const Vec2 cu = centroid[static_cast<size_t>(u)], cv = centroid[static_cast<size_t>(v)];
                return along_x ? (cu.x < cv.x || (cu.x == cv.x && u < v))
                               : (cu.y < cv.y || (cu.y == cv.y && u < v));
            });
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
}

}  // namespace flatrad
