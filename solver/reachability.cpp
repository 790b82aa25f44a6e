#include "solver/reachability.h"

#include <boost/graph/breadth_first_search.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>

namespace flatrad {

std::vector<char> reachable_directed(int vertices, const std::vector<DirectedEdge>& edges,
                                     const std::vector<char>& sources) {
    using Graph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                                     boost::no_property, uint32_t, uint32_t>;
    const Graph graph(boost::edges_are_unsorted_multi_pass, edges.begin(), edges.end(), static_cast<uint32_t>(vertices));
    std::vector<boost::default_color_type> color(static_cast<size_t>(vertices), boost::white_color);
    auto color_map = boost::make_iterator_property_map(color.begin(), boost::get(boost::vertex_index, graph));
    boost::queue<uint32_t> queue;
    for (int v = 0; v < vertices; ++v)
        if (sources[static_cast<size_t>(v)] && color[static_cast<size_t>(v)] == boost::white_color)
            boost::breadth_first_visit(graph, static_cast<uint32_t>(v), queue, boost::default_bfs_visitor(), color_map);
    std::vector<char> reached(static_cast<size_t>(vertices));
    for (int v = 0; v < vertices; ++v) reached[static_cast<size_t>(v)] = color[static_cast<size_t>(v)] != boost::white_color;
    return reached;
}

}  // namespace flatrad
