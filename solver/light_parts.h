#pragma once
/// Independent sub-scenes (DESIGN.md §4): groups of nodes of the solver's
/// tree between which no light passes, so that each is solved apart.
///
/// Two nodes are coupled when a link joins them (the receiver gathers from
/// the sender), and a leaf is coupled to every ancestor that ends a link
/// (a sender pulls from the leaves below it, a receiver pushes down to
/// them). The parts are the connected components of that graph: Boost's
/// disjoint sets (the union-find of Boost.Graph's incremental components),
/// near-linear in the edges and with no adjacency lists to store, which
/// matters at tens of millions of links.
#include <utility>
#include <vector>

namespace flatrad {

struct LightParts {
    std::vector<int> part;  ///< per vertex: its part, numbered 0 .. count - 1 in order of first vertex
    int count = 0;
};

/// Connected components of the undirected graph on [0, vertices) with
/// `edges`. A vertex with no edge is a part of its own.
LightParts connected_parts(int vertices, const std::vector<std::pair<int, int>>& edges);

}  // namespace flatrad
