#pragma once
/// A tiny plot writer: one standalone SVG document per plot, hand-written
/// (no library), for the tables the command line draws (`flatrad sweep`'s
/// DESIGN §5 figures, and later others).
///
/// A plot is a frame with an x axis, a y axis and optionally a second y
/// axis on the right, each linear or logarithmic; series drawn as lines
/// and/or points; shaded bands; horizontal and vertical reference lines; a
/// title, a subtitle and a legend row above the frame (so that it never
/// hides data). Everything is clipped to the frame.
///
/// Conventions that could surprise:
/// - Axis limits not given are taken from the series and reference lines
///   (bands are left out: a band is context and may be far wider than the
///   data, as an error bound often is; it is clipped to the frame). Linear
///   limits are widened to round tick values, log limits to whole decades.
/// - On a log axis, values <= 0 (and any NaN or infinity anywhere) cannot
///   be drawn: a point is skipped and a line is broken there. The caller
///   says so in the subtitle when it matters.
#include <optional>
#include <string>
#include <vector>

namespace flatrad {

enum class AxisScale { Linear, Log };

struct PlotAxis {
    std::string label;
    AxisScale scale = AxisScale::Linear;
    std::optional<double> min, max;  ///< fixed limits; from the data when absent
    bool include_zero = false;       ///< linear, automatic limits: always show 0
    std::string color = "#222222";   ///< axis line, ticks and label
};

enum class PlotMark { Line, Points, LineAndPoints };

struct PlotSeries {
    std::string label;  ///< legend entry; none when empty
    std::vector<double> x, y;  ///< same length
    PlotMark mark = PlotMark::Line;
    std::string color = "#1f77b4";
    bool right_axis = false;  ///< plotted against y2 (the plot must have one)
    bool dashed = false;
    /// Optional text beside each point (e.g. the eps it was run at): empty,
    /// or one entry per point (an empty entry: no text there). Drawn up
    /// and to the right of the point, small, in the series' colour, for
    /// drawable points only.
    std::vector<std::string> point_labels{};
};

/// The region between lo(x) and hi(x), shaded.
struct PlotBand {
    std::string label;
    std::vector<double> x, lo, hi;  ///< same length, x increasing
    std::string color = "#1f77b4";
    double opacity = 0.18;
};

/// A reference line across the whole frame: horizontal at y = value (on y2
/// when right_axis) or vertical at x = value.
struct PlotRefLine {
    std::string label;
    double value = 0;
    bool vertical = false;
    bool right_axis = false;
    std::string color = "#d62728";
    bool dashed = true;
};

struct SvgPlot {
    std::string title, subtitle;
    PlotAxis x, y;
    std::optional<PlotAxis> y2;  ///< a second y axis on the right
    std::vector<PlotSeries> series;
    std::vector<PlotBand> bands;
    std::vector<PlotRefLine> lines;
    int width = 760, height = 500;  ///< pixels
};

/// The plot as a standalone SVG document (starts "<svg", ends "</svg>\n").
/// Throws std::invalid_argument when a series' or band's arrays differ in
/// length (a series' point_labels included, unless empty), when a
/// right-axis item has no y2, or when a fixed log limit is not > 0. An axis with no drawable data gets limits [0, 1] (log: [1, 10]).
std::string render_svg_plot(const SvgPlot& plot);

/// Round tick values for a linear axis over [lo, hi]: about `target`
/// multiples of 1, 2 or 5 x 10^k, all within [lo, hi] (up to rounding).
std::vector<double> linear_ticks(double lo, double hi, int target = 6);

}  // namespace flatrad
