#include "solver/reachability.h"

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/connected_components.hpp>

namespace flatrad {

std::vector<char> reachable_patches(int patches, const std::vector<std::pair<int, int>>& facing,
                                    const std::vector<char>& emits) {
    using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS>;
    Graph graph(static_cast<size_t>(patches));
    for (const auto& [a, b] : facing) boost::add_edge(static_cast<size_t>(a), static_cast<size_t>(b), graph);
    std::vector<int> component(static_cast<size_t>(patches));
    const int count = boost::connected_components(graph, component.data());
    std::vector<char> lit_component(static_cast<size_t>(count), 0);
    for (int p = 0; p < patches; ++p)
        if (emits[static_cast<size_t>(p)]) lit_component[static_cast<size_t>(component[static_cast<size_t>(p)])] = 1;
    std::vector<char> reached(static_cast<size_t>(patches));
    for (int p = 0; p < patches; ++p)
        reached[static_cast<size_t>(p)] = lit_component[static_cast<size_t>(component[static_cast<size_t>(p)])];
    return reached;
}

}  // namespace flatrad
