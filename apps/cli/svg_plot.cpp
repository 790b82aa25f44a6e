#include "cli/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace flatrad {

namespace {

// Layout, in pixels.
constexpr double margin_left = 84, margin_right_single = 28, margin_right_double = 84;
constexpr double margin_bottom = 58;
constexpr double title_baseline = 24, title_line = 19, subtitle_line = 15, legend_row_height = 20;
constexpr double title_char_width = 9.2;     // ~ average advance of 15 px bold sans-serif
constexpr double subtitle_char_width = 6.4;  // ~ 11 px sans-serif
constexpr double tick_length = 5;
constexpr double legend_char_width = 6.4;  // ~ average advance of 11 px sans-serif
constexpr double point_radius = 2.4;
// Point labels: smaller than the axis text, set off the point by about
// twice its radius so that the text does not cover it.
constexpr double point_label_font_px = 9;
constexpr double point_label_offset = 5;

// Mapped coordinates are kept within this many frame sizes of the frame:
// anything beyond is clipped anyway, and huge numbers upset some renderers.
constexpr double max_overshoot = 5;

struct Limits {
    double lo = 0, hi = 1;
    AxisScale scale = AxisScale::Linear;
};

std::string escape_xml(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            case '\n': case '\r': out += ' '; break;
            default: out += c;
        }
    }
    return out;
}

// Greedy word wrap to lines of at most `width` pixels at `char_width` per
// character (a word longer than a line gets a line of its own).
std::vector<std::string> wrap(const std::string& text, double width, double char_width) {
    const size_t max_chars = static_cast<size_t>(std::max(10.0, width / char_width));
    std::vector<std::string> lines;
    std::string line;
    size_t k = 0;
    while (k < text.size()) {
        const size_t space = text.find(' ', k);
        const std::string word = text.substr(k, space == std::string::npos ? std::string::npos : space - k);
        k = space == std::string::npos ? text.size() : space + 1;
        if (!line.empty() && line.size() + 1 + word.size() > max_chars) lines.push_back(line), line.clear();
        line += (line.empty() ? "" : " ") + word;
    }
    if (!line.empty()) lines.push_back(line);
    return lines;
}

bool drawable(double v, AxisScale scale) {
    return std::isfinite(v) && (scale == AxisScale::Linear || v > 0);
}

// Position of v along the axis, 0 at lo and 1 at hi; NaN when v cannot be
// drawn on this axis.
double unit(const Limits& l, double v) {
    if (!drawable(v, l.scale)) return std::numeric_limits<double>::quiet_NaN();
    const double u = l.scale == AxisScale::Log ? (std::log10(v) - std::log10(l.lo)) / (std::log10(l.hi) - std::log10(l.lo))
                                               : (v - l.lo) / (l.hi - l.lo);
    return std::clamp(u, -max_overshoot, 1 + max_overshoot);
}

double nice_step(double range, int target) {
    const double raw = range / std::max(1, target - 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0})
        if (m * mag >= raw * (1 - 1e-9)) return m * mag;
    return 10 * mag;
}

// Limits of one axis from the values drawn against it.
Limits axis_limits(const PlotAxis& axis, const std::vector<double>& values) {
    Limits l;
    l.scale = axis.scale;
    if (axis.scale == AxisScale::Log) {
        if ((axis.min && !(*axis.min > 0)) || (axis.max && !(*axis.max > 0)))
            throw std::invalid_argument("svg plot: a log axis needs limits > 0");
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (double v : values)
            if (drawable(v, AxisScale::Log)) lo = std::min(lo, v), hi = std::max(hi, v);
        if (!(lo <= hi)) lo = 1, hi = 10;
        l.lo = axis.min.value_or(std::pow(10.0, std::floor(std::log10(lo))));
        l.hi = axis.max.value_or(std::pow(10.0, std::ceil(std::log10(hi))));
        if (!(l.hi > l.lo)) {
            if (axis.max) l.lo = l.hi / 10; else l.hi = l.lo * 10;
        }
        return l;
    }
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : values)
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (axis.include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (axis.min) lo = *axis.min;
    if (axis.max) hi = *axis.max;
    if (!(hi > lo)) {
        const double half = lo != 0 ? 0.05 * std::abs(lo) : 0.5;
        if (!axis.min) lo -= half;
        if (!axis.max) hi += half;
        if (!(hi > lo)) hi = lo + 2 * half;
    }
    // A little air around the data, not across 0 (a quantity that starts at
    // 0 should start at the frame), then out to round ticks.
    constexpr double pad = 0.03;
    const double span = hi - lo;
    if (!axis.min) lo = lo >= 0 && lo - pad * span < 0 ? 0.0 : lo - pad * span;
    if (!axis.max) hi = hi <= 0 && hi + pad * span > 0 ? 0.0 : hi + pad * span;
    const double step = nice_step(hi - lo, 6);
    l.lo = axis.min ? lo : std::floor(lo / step + 1e-9) * step;
    l.hi = axis.max ? hi : std::ceil(hi / step - 1e-9) * step;
    return l;
}

struct Tick {
    double value;
    std::string label;  // SVG text content (may hold a tspan); empty: minor tick
};

std::vector<Tick> ticks_of(const Limits& l) {
    std::vector<Tick> out;
    if (l.scale == AxisScale::Linear) {
        const std::vector<double> values = linear_ticks(l.lo, l.hi);
        if (values.size() < 2) return out;
        const double step = values[1] - values[0];
        double largest = 0;
        for (double v : values) largest = std::max(largest, std::abs(v));
        for (double v : values) {
            if (std::abs(v) < 1e-9 * step) v = 0;  // no "-0.000"
            std::string s;
            if (largest >= 1e6 || (largest > 0 && largest < 1e-3)) {
                const int digits = std::max(1, static_cast<int>(std::ceil(std::log10(largest / step))) + 1);
                s = fmt::format("{:.{}g}", v, digits);
            } else {
                const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
                s = fmt::format("{:.{}f}", v, decimals);
            }
            out.push_back({v, s});
        }
        return out;
    }
    const double e_lo = std::log10(l.lo), e_hi = std::log10(l.hi);
    const int first = static_cast<int>(std::ceil(e_lo - 1e-9)), last = static_cast<int>(std::floor(e_hi + 1e-9));
    const int decades = last - first + 1;
    if (decades < 2) {
        // Less than a decade in view: 1, 2, 5 x 10^k.
        for (int e = first - 1; e <= last; ++e)
            for (double m : {1.0, 2.0, 5.0}) {
                const double v = m * std::pow(10.0, e);
                if (v >= l.lo * (1 - 1e-9) && v <= l.hi * (1 + 1e-9)) out.push_back({v, fmt::format("{:g}", v)});
            }
        return out;
    }
    const int stride = (decades + 7) / 8;
    for (int e = first; e <= last; ++e) {
        const double v = std::pow(10.0, e);
        if ((e - first) % stride == 0)
            out.push_back({v, fmt::format("10<tspan dy=\"-6\" font-size=\"9\">{}</tspan>", e)});
        if (stride == 1 && decades <= 8)
            for (int m = 2; m <= 9; ++m)
                if (m * v <= l.hi * (1 + 1e-9)) out.push_back({m * v, ""});
    }
    return out;
}

std::string num(double v) { return fmt::format("{:.2f}", v); }

struct Frame {
    double x0, x1, y0, y1;  // left, right, top, bottom
    double px(const Limits& l, double v) const { return x0 + unit(l, v) * (x1 - x0); }
    double py(const Limits& l, double v) const { return y1 - unit(l, v) * (y1 - y0); }
};

std::string dash_attr(bool dashed) { return dashed ? " stroke-dasharray=\"6 4\"" : ""; }

struct LegendItem {
    enum Kind { Line, Points, LineAndPoints, Band } kind;
    std::string label, color;
    bool dashed = false;
    double opacity = 1;
};

}  // namespace

std::vector<double> linear_ticks(double lo, double hi, int target) {
    std::vector<double> out;
    if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo)) return out;
    const double step = nice_step(hi - lo, target);
    const double slack = 1e-9 * step;
    for (double k = std::ceil((lo - slack) / step); k * step <= hi + slack; k += 1) out.push_back(k * step);
    return out;
}

std::string render_svg_plot(const SvgPlot& plot) {
    // Check the input.
    for (const PlotSeries& s : plot.series) {
        if (s.x.size() != s.y.size())
            throw std::invalid_argument(fmt::format("svg plot: series \"{}\": x and y differ in length", s.label));
        if (!s.point_labels.empty() && s.point_labels.size() != s.x.size())
            throw std::invalid_argument(
                fmt::format("svg plot: series \"{}\": point_labels and x differ in length", s.label));
        if (s.right_axis && !plot.y2)
            throw std::invalid_argument(fmt::format("svg plot: series \"{}\" is on a y2 axis the plot lacks", s.label));
    }
    for (const PlotBand& b : plot.bands)
        if (b.x.size() != b.lo.size() || b.x.size() != b.hi.size())
            throw std::invalid_argument(fmt::format("svg plot: band \"{}\": x, lo and hi differ in length", b.label));
    for (const PlotRefLine& r : plot.lines)
        if (r.right_axis && !r.vertical && !plot.y2)
            throw std::invalid_argument(fmt::format("svg plot: line \"{}\" is on a y2 axis the plot lacks", r.label));

    // Limits.
    std::vector<double> xs, ys, y2s;
    for (const PlotSeries& s : plot.series) {
        xs.insert(xs.end(), s.x.begin(), s.x.end());
        std::vector<double>& target = s.right_axis ? y2s : ys;
        target.insert(target.end(), s.y.begin(), s.y.end());
    }
    for (const PlotRefLine& r : plot.lines) (r.vertical ? xs : r.right_axis ? y2s : ys).push_back(r.value);
    const Limits lx = axis_limits(plot.x, xs), ly = axis_limits(plot.y, ys);
    const Limits ly2 = plot.y2 ? axis_limits(*plot.y2, y2s) : Limits{};

    // Legend entries, laid out in rows above the frame.
    std::vector<LegendItem> legend;
    for (const PlotSeries& s : plot.series)
        if (!s.label.empty())
            legend.push_back({s.mark == PlotMark::Line     ? LegendItem::Line
                              : s.mark == PlotMark::Points ? LegendItem::Points
                                                           : LegendItem::LineAndPoints,
                              s.label, s.color, s.dashed});
    for (const PlotRefLine& r : plot.lines)
        if (!r.label.empty()) legend.push_back({LegendItem::Line, r.label, r.color, r.dashed});
    for (const PlotBand& b : plot.bands)
        if (!b.label.empty()) legend.push_back({LegendItem::Band, b.label, b.color, false, b.opacity});

    const double W = plot.width, H = plot.height;
    Frame f;
    f.x0 = margin_left;
    f.x1 = W - (plot.y2 ? margin_right_double : margin_right_single);
    const std::vector<std::string> title_lines = wrap(plot.title, W - 30, title_char_width);
    const std::vector<std::string> subtitle_lines = wrap(plot.subtitle, W - 30, subtitle_char_width);
    double top = title_baseline + title_line * (static_cast<double>(title_lines.size()) - 1) +
                 subtitle_line * static_cast<double>(subtitle_lines.size()) + 8;
    struct Placed {
        const LegendItem* item;
        double x, y;
    };
    std::vector<Placed> placed;
    {
        double x = f.x0, y = top + legend_row_height / 2;
        for (const LegendItem& item : legend) {
            const double w = 26 + legend_char_width * static_cast<double>(item.label.size()) + 18;
            if (x > f.x0 && x + w > f.x1) x = f.x0, y += legend_row_height;
            placed.push_back({&item, x, y});
            x += w;
        }
        if (!legend.empty()) top = y + legend_row_height / 2 + 6;
    }
    f.y0 = top + 6;
    f.y1 = H - margin_bottom;

    std::string svg;
    auto out = std::back_inserter(svg);
    fmt::format_to(out,
                   "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
                   "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" font-size=\"11\">\n",
                   plot.width, plot.height);
    fmt::format_to(out, "<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"white\"/>\n", plot.width, plot.height);
    fmt::format_to(out, "<defs><clipPath id=\"frame\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath></defs>\n",
                   num(f.x0), num(f.y0), num(f.x1 - f.x0), num(f.y1 - f.y0));

    // Title, subtitle.
    double baseline = title_baseline;
    for (const std::string& line : title_lines) {
        fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">{}</text>\n",
                       num(W / 2), num(baseline), escape_xml(line));
        baseline += title_line;
    }
    baseline += subtitle_line - title_line;
    for (const std::string& line : subtitle_lines) {
        fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"11\" fill=\"#555555\">{}</text>\n",
                       num(W / 2), num(baseline), escape_xml(line));
        baseline += subtitle_line;
    }

    // Grid and ticks.
    const std::vector<Tick> tx = ticks_of(lx), ty = ticks_of(ly);
    svg += "<g stroke=\"#e4e4e4\" stroke-width=\"1\">\n";
    for (const Tick& t : tx)
        if (!t.label.empty()) {
            const double x = f.px(lx, t.value);
            fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\"/>\n", num(x), num(f.y0), num(f.y1));
        }
    for (const Tick& t : ty)
        if (!t.label.empty()) {
            const double y = f.py(ly, t.value);
            fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\"/>\n", num(f.x0), num(y), num(f.x1));
        }
    svg += "</g>\n";

    auto axis_ticks = [&](const std::vector<Tick>& ticks, const Limits& l, const PlotAxis& axis, int side) {
        // side: 0 bottom (x), 1 left (y), 2 right (y2)
        fmt::format_to(out, "<g stroke=\"{0}\" fill=\"{0}\">\n", axis.color);
        for (const Tick& t : ticks) {
            const double len = t.label.empty() ? tick_length * 0.6 : tick_length;
            if (side == 0) {
                const double x = f.px(l, t.value);
                fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\"/>\n", num(x), num(f.y1), num(f.y1 + len));
                if (!t.label.empty())
                    fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" stroke=\"none\">{}</text>\n", num(x),
                                   num(f.y1 + 18), t.label);
            } else {
                const double y = f.py(l, t.value);
                const double xa = side == 1 ? f.x0 : f.x1, dir = side == 1 ? -1 : 1;
                fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\"/>\n", num(xa), num(y), num(xa + dir * len));
                if (!t.label.empty())
                    fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"{}\" stroke=\"none\">{}</text>\n",
                                   num(xa + dir * (tick_length + 3)), num(y + 4), side == 1 ? "end" : "start", t.label);
            }
        }
        svg += "</g>\n";
    };
    axis_ticks(tx, lx, plot.x, 0);
    axis_ticks(ty, ly, plot.y, 1);
    if (plot.y2) axis_ticks(ticks_of(ly2), ly2, *plot.y2, 2);

    // Axis labels.
    fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"12\" fill=\"{}\">{}</text>\n",
                   num((f.x0 + f.x1) / 2), num(f.y1 + 42), plot.x.color, escape_xml(plot.x.label));
    fmt::format_to(out,
                   "<text transform=\"translate({},{}) rotate(-90)\" text-anchor=\"middle\" font-size=\"12\" fill=\"{}\">{}</text>\n",
                   num(16), num((f.y0 + f.y1) / 2), plot.y.color, escape_xml(plot.y.label));
    if (plot.y2)
        fmt::format_to(out,
                       "<text transform=\"translate({},{}) rotate(90)\" text-anchor=\"middle\" font-size=\"12\" fill=\"{}\">{}</text>\n",
                       num(W - 16), num((f.y0 + f.y1) / 2), plot.y2->color, escape_xml(plot.y2->label));

    // Data, clipped to the frame: bands under reference lines under series.
    svg += "<g clip-path=\"url(#frame)\">\n";
    for (const PlotBand& b : plot.bands) {
        // One closed path per run of drawable samples: along hi, back along lo.
        size_t k = 0;
        while (k < b.x.size()) {
            auto ok = [&](size_t i) {
                return drawable(b.x[i], lx.scale) && std::isfinite(b.lo[i]) && std::isfinite(b.hi[i]);
            };
            if (!ok(k)) {
                ++k;
                continue;
            }
            size_t end = k;
            while (end < b.x.size() && ok(end)) ++end;
            // On a log axis a lower edge <= 0 lies below the frame.
            auto y_of = [&](double v) { return drawable(v, ly.scale) ? f.py(ly, v) : f.y1 + max_overshoot * (f.y1 - f.y0); };
            std::string d;
            for (size_t i = k; i < end; ++i)
                d += fmt::format("{}{} {}", i == k ? "M" : " L", num(f.px(lx, b.x[i])), num(y_of(b.hi[i])));
            for (size_t i = end; i-- > k;) d += fmt::format(" L{} {}", num(f.px(lx, b.x[i])), num(y_of(b.lo[i])));
            fmt::format_to(out, "<path d=\"{} Z\" fill=\"{}\" fill-opacity=\"{}\" stroke=\"none\"/>\n", d, b.color, b.opacity);
            k = end;
        }
    }
    for (const PlotRefLine& r : plot.lines) {
        if (r.vertical) {
            if (!drawable(r.value, lx.scale)) continue;
            const double x = f.px(lx, r.value);
            fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"1.5\"{4}/>\n",
                           num(x), num(f.y0), num(f.y1), r.color, dash_attr(r.dashed));
        } else {
            const Limits& l = r.right_axis ? ly2 : ly;
            if (!drawable(r.value, l.scale)) continue;
            const double y = f.py(l, r.value);
            fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"{3}\" stroke-width=\"1.5\"{4}/>\n",
                           num(f.x0), num(y), num(f.x1), r.color, dash_attr(r.dashed));
        }
    }
    for (const PlotSeries& s : plot.series) {
        const Limits& l = s.right_axis ? ly2 : ly;
        if (s.mark != PlotMark::Points) {
            std::string d;
            bool pen_down = false;
            for (size_t i = 0; i < s.x.size(); ++i) {
                if (!drawable(s.x[i], lx.scale) || !drawable(s.y[i], l.scale)) {
                    pen_down = false;
                    continue;
                }
                d += fmt::format("{}{} {}", pen_down ? " L" : (d.empty() ? "M" : " M"), num(f.px(lx, s.x[i])),
                                 num(f.py(l, s.y[i])));
                pen_down = true;
            }
            if (!d.empty())
                fmt::format_to(out,
                               "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" stroke-linejoin=\"round\"{}/>\n",
                               d, s.color, dash_attr(s.dashed));
        }
        if (s.mark != PlotMark::Line) {
            fmt::format_to(out, "<g fill=\"{}\" fill-opacity=\"0.7\" stroke=\"none\">\n", s.color);
            for (size_t i = 0; i < s.x.size(); ++i)
                if (drawable(s.x[i], lx.scale) && drawable(s.y[i], l.scale))
                    fmt::format_to(out, "<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n", num(f.px(lx, s.x[i])),
                                   num(f.py(l, s.y[i])), point_radius);
            svg += "</g>\n";
        }
        if (!s.point_labels.empty()) {
            fmt::format_to(out, "<g fill=\"{}\" font-size=\"{}\">\n", s.color, point_label_font_px);
            for (size_t i = 0; i < s.x.size(); ++i)
                if (!s.point_labels[i].empty() && drawable(s.x[i], lx.scale) && drawable(s.y[i], l.scale))
                    fmt::format_to(out, "<text x=\"{}\" y=\"{}\">{}</text>\n",
                                   num(f.px(lx, s.x[i]) + point_label_offset), num(f.py(l, s.y[i]) - point_label_offset),
                                   escape_xml(s.point_labels[i]));
            svg += "</g>\n";
        }
    }
    svg += "</g>\n";

    // Frame on top of the data; y2's side in its colour.
    fmt::format_to(out, "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444444\"/>\n",
                   num(f.x0), num(f.y0), num(f.x1 - f.x0), num(f.y1 - f.y0));
    if (plot.y2)
        fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"1.5\"/>\n",
                       num(f.x1), num(f.y0), num(f.y1), plot.y2->color);

    // Legend.
    for (const Placed& p : placed) {
        const LegendItem& item = *p.item;
        const double x = p.x, y = p.y;
        switch (item.kind) {
            case LegendItem::Band:
                fmt::format_to(out, "<rect x=\"{}\" y=\"{}\" width=\"20\" height=\"10\" fill=\"{}\" fill-opacity=\"{}\"/>\n",
                               num(x), num(y - 5), item.color, item.opacity);
                break;
            case LegendItem::Points:
                fmt::format_to(out, "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"/>\n", num(x + 10), num(y),
                               point_radius + 0.6, item.color);
                break;
            case LegendItem::Line:
            case LegendItem::LineAndPoints:
                fmt::format_to(out, "<line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"2\"{4}/>\n",
                               num(x), num(x + 20), num(y), item.color, dash_attr(item.dashed));
                if (item.kind == LegendItem::LineAndPoints)
                    fmt::format_to(out, "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"/>\n", num(x + 10), num(y),
                                   point_radius, item.color);
                break;
        }
        fmt::format_to(out, "<text x=\"{}\" y=\"{}\">{}</text>\n", num(x + 26), num(y + 4), escape_xml(item.label));
    }
    svg += "</svg>\n";
    return svg;
}

}  // namespace flatrad
