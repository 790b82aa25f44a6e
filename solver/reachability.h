#pragma once
/// Which parts of the scene any emitter's light can reach (DESIGN.md §4,
/// "a surface that no emitter can reach is not solved").
///
/// The hierarchical solver moves light along a directed graph: a lit
/// element sends what it holds, senders pull from their children, links go
/// from sender to receiver, receivers push down to their children. Light
/// reaches exactly the vertices reachable from the emitters (a
/// breadth-first search from all of them, Boost.Graph on a compressed
/// sparse row graph: two uint32 per edge, for millions of links). The caller
/// passes only edges that may carry light, so what is left out truly
/// receives nothing.
#include <cstdint>
#include <utility>
#include <vector>

namespace flatrad {

/// `edges` (from, to) over vertices [0, vertices); `sources[v]` says whether
/// v starts lit. Returns, per vertex, whether light from a source reaches it.
using DirectedEdge = std::pair<uint32_t, uint32_t>;
std::vector<char> reachable_directed(int vertices, const std::vector<DirectedEdge>& edges,
                                     const std::vector<char>& sources);

}  // namespace flatrad
