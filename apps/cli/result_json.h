#pragma once
/// The result file of SPEC.md ("Result file") and the stats objects, as
/// JSON. Keys keep the SPEC's order (ordered_json), so the file reads as the
/// SPEC shows it.
#include <string>

#include <nlohmann/json.hpp>

#include "engine/scene.h"
#include "solver/solution.h"
#include "visibility/stats.h"

namespace flatrad {

/// Every VisibilityStats counter, by its member name.
nlohmann::ordered_json visibility_stats_json(const VisibilityStats& stats);

/// The whole result file for `solution`, a solve of `scene`:
/// {flatrad, scene, method, settings, patches, totals, stats}.
/// Patches come in SPEC numbering (Scene::patches order); `segment` is the
/// segment's number within its surface, `a` and `b` its points in file order.
/// Settings hold what shaped the result: `subdivide` always, `eps` and
/// `vis_eps` for the hierarchical method only (exact ignores them).
nlohmann::ordered_json result_json(const Scene& scene, const Solution& solution);

/// Text of a result: two-space indented at the top level, each patch on one
/// line (a patch with many elements is one long line rather than hundreds
/// of short ones). Doubles print with round-trip precision; a non-finite
/// value prints as null. Ends with a newline.
std::string format_result(const nlohmann::ordered_json& result);

/// format_result(result_json(scene, solution)), written straight from the
/// solution: the same JSON value and layout, without a DOM of every patch
/// (at 10^6 patches the DOM took 3.5 s and ~1 GB; this ~0.5 s). Doubles
/// get the shortest digits that read back to them (std::to_chars), where
/// nlohmann's grisu2 sometimes prints a 17th: the values are the same bits,
/// the text may be a digit shorter. From parallel_result_patches patches
/// on, the second half of the patches is written on a second thread.
std::string result_text(const Scene& scene, const Solution& solution);

/// Patches from which result_text writes in two halves at once.
inline constexpr size_t parallel_result_patches = 1 << 15;

}  // namespace flatrad
