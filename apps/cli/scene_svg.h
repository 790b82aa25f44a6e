#pragma once
/// A picture of a solved scene (`flatrad solve --svg`): a standalone SVG
/// document, hand-written like cli/svg_plot.h.
///
/// - Every element is one `<line class="element">`, colored by its
///   radiosity and drawn beside its segment on the lit side (so the two
///   patches of a `both` segment show side by side).
/// - Colors: 3 channels are true color after a simple tone map (each
///   channel divided by the 99th percentile of the element channel values,
///   then gamma 2.2, clamped to [0, 1]). The percentile is length-weighted
///   and over patches that emit nothing: lamps, far brighter than what they
///   light, would otherwise make the rest black; they saturate. 1 channel uses a
///   false-color scale (viridis-like, 0 at dark blue, the 99th percentile
///   and above at yellow) and a legend bar with numbers.
/// - The unlit side of a one-sided segment is a grey line on that side; a
///   small dark tick at each patch's middle points into its lit side
///   (patches shorter than a few stroke widths get none, so that thousands
///   of tiny blockers do not drown in ticks). The drawing's backdrop is dark
///   slate, so that both saturated lamps and black surfaces show.
/// - A caption above: the scene name, the method and its settings
///   (eps and vis_eps, or subdivide), elements and time.
/// - The scene keeps its aspect ratio (one scale for x and y, y up); the
///   stroke width is a fixed fraction of the drawing's size, so of the
///   scene's.
#include <string>

#include "engine/scene.h"
#include "solver/solution.h"

namespace flatrad {

struct SceneSvgOptions {
    int size_px = 900;  ///< the longer side of the drawing area, pixels
};

/// The SVG document (starts "<svg", ends "</svg>\n") for `solution`, a
/// solve of `scene`. Throws std::invalid_argument when the solution does
/// not match the scene (patch count or channel count differ).
std::string render_scene_svg(const Scene& scene, const Solution& solution, const SceneSvgOptions& options = {});

/// The false-color scale of one-channel pictures: x in [0, 1] (clamped)
/// to 8-bit RGB, a piecewise-linear fit of matplotlib's viridis through 9
/// stops. Monotone in lightness, readable in grey and for most color-blind
/// readers.
struct Rgb8 {
    int r = 0, g = 0, b = 0;
};
Rgb8 false_color(double x);

/// The simple tone map of three-channel pictures: v / white (white > 0)
/// raised to 1 / 2.2 and clamped to [0, 1], as an 8-bit value.
int tone_map(double v, double white);

}  // namespace flatrad
