#pragma once
/// Whether a long blocker that is not one of a box's own segments runs
/// through the box.
///
/// The hierarchical solver's cluster links take one transmittance per link,
/// between stand-ins for the two ends (visibility/multiscale.h: a cluster's
/// stand-in is its box's cross-section), the ends' own segments left out.
/// That is a fair mean for the members where what else lies inside the box
/// is scattered among them as they are (a forest's sticks). It is not where
/// a blocker much longer than the box runs through it: the members then lie
/// on one side of it or the other, and the cross-section's mean says
/// nothing of either side. A shelf's top running through the box of a
/// small cluster made of the shelf's end face and a book's underside 1 mm
/// above the top hid 80% of the lines to the cross-section from the room's
/// left wall, while nothing stood between that wall and the end face
/// (docs/solver-history.md, "Forty-fourth session").
#include <cstdint>
#include <vector>

#include "engine/geometry.h"
#include "engine/hierarchy.h"

namespace flatrad {

/// The length of segment s's part inside the closed box b (b clipped to s)
/// where that part runs through b's interior; 0 where s misses b, only
/// touches it, or lies along its boundary, and for a box of no area.
/// "Through the interior": its midpoint lies inside b by more than 1e-9 of
/// the larger of b's diagonal and the coordinates' magnitude (far above
/// the clipping's rounding, far below any scene's detail). A chord whose
/// midpoint is inside b has all of it but its ends inside (b is convex).
double chord_through_box(const Segment& s, const Box& b);

/// Whether some segment of `h` that can block (Hierarchy::can_block), at
/// least `min_length` long, other than those at places [skip_first,
/// skip_first + skip_count) of h.order(), runs through `box` for at least
/// `min_chord` (chord_through_box > 0 and >= min_chord). Walks the
/// hierarchy's nodes whose boxes meet `box`; `stack` is scratch.
bool box_intruded_by_blocker(const Hierarchy& h, const Box& box, int32_t skip_first, int32_t skip_count,
                             double min_length, double min_chord, std::vector<int32_t>& stack);

}  // namespace flatrad
