#pragma once
/// Whether a box is cut in two by a blocker that is not one of its own
/// segments.
///
/// The hierarchical solver's cluster links take one transmittance per link,
/// between stand-ins for the two ends (visibility/multiscale.h: a cluster's
/// stand-in is its box's cross-section), the ends' own segments left out.
/// That is a fair mean for the members where what else lies inside the box
/// is scattered among them (a forest's sticks). It is not where a segment
/// that is not a member runs right across the box: the members then lie on
/// one side of it or the other, and the cross-section's mean says nothing
/// of either side. A shelf's top running through the box of a small
/// cluster made of the shelf's end face and a book's underside 1 mm above
/// the top hid 80% of the lines to the cross-section from the room's left
/// wall, while nothing stood between that wall and the end face
/// (docs/solver-history.md, "Forty-fourth session").
#include <cstdint>
#include <vector>

#include "engine/geometry.h"
#include "engine/hierarchy.h"

namespace flatrad {

/// Whether segment s cuts the closed box b in two: its part inside b (b
/// clipped to s) runs from a point on b's boundary to another, through b's
/// interior. A segment along an edge, one that only touches b, or one that
/// ends inside b does not. A box of no area is cut by nothing. "On the
/// boundary" and "through the interior" are taken to within 1e-9 of the
/// larger of b's diagonal and the coordinates' magnitude (far above the
/// clipping's rounding, far below any scene's detail).
bool segment_cuts_box(const Segment& s, const Box& b);

/// Whether some segment of `h` that can block (Hierarchy::can_block), at
/// least `min_length` long, other than those at places [skip_first,
/// skip_first + skip_count) of h.order(), cuts `box` in two
/// (segment_cuts_box). Walks the hierarchy's nodes whose boxes meet `box`;
/// `stack` is scratch.
bool box_cut_by_blocker(const Hierarchy& h, const Box& box, int32_t skip_first, int32_t skip_count,
                        std::vector<int32_t>& stack, double min_length = 0);

}  // namespace flatrad
