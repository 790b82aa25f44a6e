#pragma once
/// Which patches' rows of form factors sum to 1 over the patches that send
/// light (the hierarchical solver's row sums, DESIGN.md §3: a leaf whose
/// row is closed must gather exactly 1 for B = 1 everywhere, and its
/// deficit, the refinement's own error, is given back to it).
///
/// A patch's row closes when its light cannot leave the scene
/// (engine/connectivity.h, escape_free_patches) and it sees no visible sink
/// (solver/sink_visibility.h). "Sees none" is proven per pair by a closed
/// loop between them (solver/loop_sides.h: one side In, the other Out), so
/// a sink seen only from outside a room leaves the rows inside it closed:
/// a lamp through a room's wall sees the wall's outer side (a sink) with
/// its outer part, and the walls inside, lit by a stiff room's many
/// bounces, no longer lose their closure to it (the refinement's error
/// came back 1 / (1 - rho) times: 5.5% at the default eps and reflectance
/// 0.99, 0.04% closed).
///
/// An inert patch (one that neither reflects nor emits in any channel)
/// sends nothing, so a row that sees it would miss what it absorbs. Such a
/// patch is made a sender where a closed row may see it (not kept apart by
/// a loop): its links carry 0 in the solve but count in the rows, and the
/// solver refines them as if it shone (a black plate in a room at
/// reflectance 0.99: no row closed before, 1.2e-2 relative L2 against exact
/// at the default eps; 1.2e-3 now).
///
/// Cost: classifying the sides against a loop is O(segments x |L|), loops
/// taken while that stays within 1e8 in all; then O(U x C x K) for U
/// distinct sets of classes among the visible sinks (and then among the
/// inert patches), C candidate patches and K loops, and beyond 1e8 no row
/// is closed (never wrong: a row left open is only less accurate).
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

namespace flatrad {

struct ClosedRows {
    std::vector<char> closed;       ///< per patch: its row closes
    std::vector<char> inert_sends;  ///< per patch: an inert patch that a closed row may see
};

/// escape_free: per patch (escape_free_patches); visible_sink: per segment
/// side (visible_sinks); inert: per patch.
ClosedRows closed_rows(const Scene& scene, const Connectivity& connectivity, const std::vector<char>& escape_free,
                       const std::vector<char>& visible_sink, const std::vector<char>& inert);

}  // namespace flatrad
