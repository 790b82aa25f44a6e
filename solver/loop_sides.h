#pragma once
/// Where each segment side lies against one closed loop of the scene: a
/// side that can only see the loop's interior (In), only its exterior
/// (Out), or either (Unknown). The walls of a closed loop block every line
/// between its interior and its exterior, so an In side and an Out side of
/// the same loop never see each other, whatever crosses the loop elsewhere
/// (a lamp through a wall is Unknown, the wall's two sides stay In and
/// Out). Used by the sink rule (solver/sink_visibility.h) and the row sums'
/// rule (solver/closed_rows.h).
///
/// L must be simple with a known orientation (engine/connectivity.h).
///  - L's own segments: the side facing L's interior is In, the other Out.
///  - Any other segment, both sides alike: In when both endpoints are
///    inside L and it has no contact with L, or when it touches L with no
///    end outside, crosses no edge properly, has no corner of L on it and
///    its midpoint inside (a shelf against a wall: L stays closed where it
///    is touched); Out when both endpoints are outside and it has no contact
///    with L; else Unknown.
/// Point-in-polygon by crossing number with a rounding margin
/// (solver/polygon_tests.h): a point within rounding of L is Unknown.
/// Cost: O((segments off L) x |L|).
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

namespace flatrad {

enum class LoopSide : char { Unknown = 0, In = 1, Out = 2 };

/// Two entries per segment (left side, right side of a -> b). in_line_contacts:
/// a segment in line with an edge of L counts as touching it wherever it
/// lies on that line (polygon_tests.h, meets_or_in_line: the sink rule's
/// old contact test, kept for its results).
std::vector<LoopSide> loop_sides(const Scene& scene, const SceneLoop& loop, bool in_line_contacts = false);

/// Whether two sides are kept apart by the loop they were classified against.
inline bool kept_apart(LoopSide a, LoopSide b) {
    return (a == LoopSide::In && b == LoopSide::Out) || (a == LoopSide::Out && b == LoopSide::In);
}

}  // namespace flatrad
