#pragma once
/// Rooms: which closed loop of the scene each patch's light lives in
/// (DESIGN.md §4; the issue: "segments sharing endpoints form objects and
/// rooms"). Light cannot cross a closed loop, so two patches in different
/// rooms never exchange anything, whatever a cluster-level approximation of
/// visibility would say (a cluster link's transmittance does not count the
/// clusters' own segments as blockers, so without rooms light from one
/// closed box would leak into the box beside it through their walls).
///
/// A side's room is the innermost simple loop of known orientation
/// (engine/connectivity.h) that nothing else crosses or touches, holding its
/// light:
///  - a side of a loop's own segment lit towards the loop's interior: that
///    loop;
///  - a side lit towards the exterior, or a segment on no loop: the
///    innermost loop that strictly contains the segment (both endpoints
///    inside by crossing number, no contact with it), or "outside" (-1);
///  - when a test is too close to call, "unknown" (-2), which is taken to
///    share a room with everything.
/// Cost: O(patches x segments of the loops tried); beyond 1e8 point tests in
/// all, the remaining patches are "unknown" (never wrong, just no pruning).
#include <cstdint>
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"

namespace flatrad {

inline constexpr int room_outside = -1;
inline constexpr int room_unknown = -2;

/// Two entries per segment (left and right side of a -> b, lit or not): a
/// loop index (Connectivity::loops), room_outside or room_unknown.
std::vector<int> side_rooms(const Scene& scene, const Connectivity& connectivity);

/// A set of rooms as a 64-bit mask (room r -> bit (r + 1) mod 64; unknown:
/// every bit), so that a cluster holds the union of its sides' rooms. Two
/// sets with no common bit share no room; a common bit may be a collision,
/// which only costs a link that could have been skipped.
inline uint64_t room_mask(int room) {
    return room == room_unknown ? ~uint64_t{0} : uint64_t{1} << (static_cast<unsigned>(room + 1) % 64u);
}

}  // namespace flatrad
