#pragma once
/// Which patches any emitter's light can reach (DESIGN.md §4, "a surface
/// that no emitter can reach is not solved"). Two patches that face each
/// other's lit side can exchange light both ways, so the interaction graph
/// is undirected and reachability from the emitters is membership of a
/// connected component holding an emitter (Boost.Graph's
/// connected_components). The caller passes the pairs that may exchange
/// light (a non-zero form factor or visibility bound), so a patch left out
/// truly receives nothing.
#include <utility>
#include <vector>

namespace flatrad {

/// `facing` lists pairs (a, b) of patch indices in [0, patches) that may
/// exchange light; `emits[p]` says whether patch p emits in any channel.
/// Returns, per patch, whether light from some emitter can reach it.
std::vector<char> reachable_patches(int patches, const std::vector<std::pair<int, int>>& facing,
                                    const std::vector<char>& emits);

}  // namespace flatrad
