#pragma once
/// How far one solution of a scene is from another, taken as the reference
/// (DESIGN.md §5: "relative L2 over patches, length-weighted; L-infinity").
/// Used by `flatrad compare` and by `flatrad sweep` over whole solutions.
///
/// Errors are over patches (their length-weighted mean radiosity), all
/// channels, each patch weighted by its length L_p:
///   relative_l2  = sqrt(sum_pc L_p (B_pc - R_pc)^2 / sum_pc L_p R_pc^2),
///   max_relative = max_pc |B_pc - R_pc| / rms_c, rms_c the length-weighted
///                  RMS of the reference's channel c (so a dark patch's
///                  error counts at the scale of the scene, not of itself).
/// Both are 0 when the solutions agree, and 0 (not NaN) for an all-dark
/// reference that is matched exactly; +inf for a mismatch against it.
///
/// Both measure errors at the scale of the scene's light, which its
/// brightest patches set. Each patch's error at its own scale,
///   q_pc = |B_pc - R_pc| / R_pc   (0 where both are 0, +inf where only
///                                  R_pc is),
/// is summarised by its length-weighted quantiles over patches and
/// channels (patch_relative): how well each surface is known, the dim
/// ones included (a forest's shade, whose errors of 10x and more the
/// relative L2 of 1% at its lamp does not show).
#include <vector>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

/// A patch's share of the squared L2 error: sum_c L_p (B_pc - R_pc)^2 over
/// the sum of that over all patches.
struct PatchErrorShare {
    int patch = -1;
    double share = 0;
};

/// q_pc (above) summarised: its length-weighted median, its 90th
/// percentile (the least q with at least that share of the length at or
/// below it) and its largest.
struct PatchRelative {
    double median = 0, p90 = 0, max = 0;
};

/// Where the error lies: how many patches `largest` lists at most.
inline constexpr int largest_error_patches = 5;

struct CompareError {
    double relative_l2 = 0;
    double max_relative = 0;
    int worst_patch = -1;  ///< where max_relative is reached; -1 when none
    /// The patches with the largest shares of the squared L2 error, largest
    /// first (ties by patch number), at most largest_error_patches of them,
    /// none with a share of 0: empty when the solutions agree. A relative
    /// L2 error dominated by a few patches is told apart from one spread
    /// over the scene (a forest's lit trees next to its lamp, say).
    std::vector<PatchErrorShare> largest;
    /// Each patch at its own scale (q_pc above); all 0 with no patch.
    PatchRelative patch_relative;
};

/// Errors of `solution` against `reference`, two solves of `scene` (same
/// patches, same channels), as above. Meshes may differ: only the patches'
/// mean radiosities are compared.
CompareError compare_solutions(const Scene& scene, const Solution& solution, const Solution& reference);

}  // namespace flatrad
