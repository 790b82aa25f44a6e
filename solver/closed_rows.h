#pragma once
/// Which patches' rows of form factors sum to 1 over the patches that send
/// light (the hierarchical solver's row sums, DESIGN.md §3: a leaf whose
/// row is closed must gather exactly 1 for B = 1 everywhere, and its
/// deficit, the refinement's own error, is given back to it).
///
/// A patch's row closes when its light cannot leave the scene
/// (engine/connectivity.h, escape_free_patches) and every side it may see
/// is a link's sender, so that its links cover the whole row. Two kinds of
/// side send nothing: a visible sink (an unlit side,
/// solver/sink_visibility.h) and an inert patch (one that neither reflects
/// nor emits in any channel). "May see" is disproven per pair by a closed
/// loop between them (solver/loop_sides.h: one side In, the other Out), so
/// a sink seen only from outside a room leaves the rows inside it closed (a
/// lamp through a room's wall sees the wall's outer side with its outer
/// part; the walls inside do not).
///
/// Where a stiff row (reflectance 0.95 or more in some channel) may see a
/// side that sends nothing, that side is made a sender that carries 0: its
/// links count in the rows, the solver refines them as if it shone, and the
/// rows that see it close. Not below: closing rows gives each its deficit
/// in proportion to what its ancestors' links bring, and near a bright lamp
/// that moves small patches by more than the closure gains where light is
/// lost only a few times over (the furnished room, reflectance up to 0.9:
/// 1.45e-3 -> 2.8e-3 relative L2 against exact at the default eps, one
/// 3 cm face beside its standing lamp 13% too bright). Where rows reflect
/// 0.95 or more, what the refinement loses comes back 20 times or more.
///
/// Before, one sink seen from anywhere, or one inert patch anywhere, left
/// every row open. At reflectance 0.99 and the default eps, relative L2
/// against exact: a lamp through a wall 5.5e-2 -> 3.9e-4, a black plate in
/// the room 1.2e-2 -> 1.1e-3, a one-sided plate (its back a sink) 1.7e-2 ->
/// 2.7e-3 (docs/solver-history.md, forty-second session).
///
/// Cost: none where nothing is dark. Else classifying the sides against a
/// loop is O(segments x |L|), loops taken while that stays within 1e8 in
/// all, and a hash per side and loop gives each side the number of its
/// string of classes; then O(U x C x K) for U and C distinct strings among
/// the dark sides and the candidates and K loops, and beyond 1e8 no row is
/// closed (never wrong: a row left open is only less accurate). A side made
/// a sender costs an element tree and its links.
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

namespace flatrad {

struct ClosedRows {
    std::vector<char> closed;       ///< per patch: its row closes
    std::vector<char> inert_sends;  ///< per patch: an inert patch made a sender
    std::vector<char> sink_sends;   ///< per segment side: a visible sink made a sender
};

/// escape_free: per patch (escape_free_patches); visible_sink: per segment
/// side (visible_sinks); inert: per patch.
ClosedRows closed_rows(const Scene& scene, const Connectivity& connectivity, const std::vector<char>& escape_free,
                       const std::vector<char>& visible_sink, const std::vector<char>& inert);

}  // namespace flatrad
