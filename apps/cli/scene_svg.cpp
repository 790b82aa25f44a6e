#include "cli/scene_svg.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli/svg_plot.h"

namespace flatrad {

namespace {

// Sizes in pixels, relative to the drawing's longer side (so to the scene).
constexpr double stroke_fraction = 0.003;   // element lines: ~2.7 px at 900 px
constexpr double min_stroke_px = 0.6;       // still visible when the drawing is tiny
constexpr double tick_min_patch_strokes = 6;  // no tick on patches shorter than this
constexpr double white_percentile = 0.99;   // tone map / color scale: this quantile is "white"
constexpr double gamma = 2.2;
constexpr double margin_px = 20;
constexpr double caption_px = 48;           // two caption lines above the drawing
constexpr double legend_px = 64;            // the color bar below it (one channel)

const char* const unlit_grey = "#9a9a9a";
const char* const tick_color = "#d8d8d8";
// The drawing sits on dark slate: saturated lamps (white) and black
// surfaces both stand out from it, and it is no grey of the unlit sides.
const char* const backdrop = "#363c46";

std::string escape_xml(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string num(double v) { return fmt::format("{:.2f}", v); }

std::string hex(const Rgb8& c) { return fmt::format("#{:02x}{:02x}{:02x}", c.r, c.g, c.b); }

// The white point: the 99th percentile of the channel values of the
// elements of patches that emit nothing, each weighted by its length (so
// that the picture's brightness follows what covers the picture). Lamps are
// left out: a lamp is 100 times brighter than what it lights and would
// make everything else black; it saturates instead. Falls back to every
// patch when none is unlit, then to the largest value, then to 1, so that
// a dark scene still draws.
double white_point(const Scene& scene, const Solution& solution) {
    auto emits = [&](size_t p) {
        const Material& m = scene.materials[static_cast<size_t>(scene.patches[p].material)];
        return std::any_of(m.emission.begin(), m.emission.end(), [](double e) { return e > 0; });
    };
    for (bool skip_lamps : {true, false}) {
        std::vector<std::pair<double, double>> v;  // (value, length)
        double total = 0, largest = 0;
        for (size_t p = 0; p < solution.patches.size(); ++p) {
            if (skip_lamps && emits(p)) continue;
            for (const ElementValue& e : solution.patches[p].elements)
                for (double b : e.B)
                    if (std::isfinite(b)) {
                        const double w = (e.t1 - e.t0) * scene.patches[p].length;
                        v.emplace_back(b, w);
                        total += w;
                        largest = std::max(largest, b);
                    }
        }
        if (v.empty()) continue;
        std::sort(v.begin(), v.end());
        double acc = 0, q = v.back().first;
        for (const auto& [b, w] : v)
            if ((acc += w) >= white_percentile * total) {
                q = b;
                break;
            }
        if (q > 0) return q;
        if (largest > 0) return largest;
    }
    return 1;
}

std::string settings_text(const Solution& s) {
    if (s.method == "hierarchical")
        return fmt::format("hierarchical, eps {:g}, vis_eps {:g}", s.eps, s.vis_eps);
    return fmt::format("{}, subdivide {}", s.method, s.subdivide);
}

}  // namespace

Rgb8 false_color(double x) {
    // matplotlib viridis at 0, 1/8, ..., 1.
    static constexpr int stops[9][3] = {{68, 1, 84},   {71, 44, 122},  {59, 81, 139},
                                        {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                        {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
    if (!(x > 0)) x = 0;  // NaN too
    if (x > 1) x = 1;
    const double f = x * 8;
    const int i = std::min(7, static_cast<int>(f));
    const double u = f - i;
    auto mix = [&](int c) { return static_cast<int>(std::lround(stops[i][c] + u * (stops[i + 1][c] - stops[i][c]))); };
    return {mix(0), mix(1), mix(2)};
}

int tone_map(double v, double white) {
    double x = v / white;
    if (!(x > 0)) return 0;  // NaN too
    x = std::min(1.0, std::pow(x, 1 / gamma));
    return static_cast<int>(std::lround(255 * x));
}

std::string render_scene_svg(const Scene& scene, const Solution& solution, const SceneSvgOptions& options) {
    if (solution.patches.size() != scene.patches.size())
        throw std::invalid_argument(fmt::format("scene svg: the solution has {} patches, the scene {}",
                                                solution.patches.size(), scene.patches.size()));
    if (solution.channels != scene.channels)
        throw std::invalid_argument("scene svg: the solution's channel count differs from the scene's");
    const bool rgb = scene.channels == 3;

    // 1. The map from scene to pixels: one scale, y up, the scene centred.
    double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
    for (const SceneSegment& s : scene.segments)
        for (const Vec2& p : {s.seg.a, s.seg.b}) {
            xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x);
            ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
        }
    if (scene.segments.empty()) xmin = ymin = 0, xmax = ymax = 1;
    const double span = std::max({xmax - xmin, ymax - ymin, 1e-300});
    const double size = std::max(100, options.size_px);
    const double scale = size / span;
    const double stroke = std::max(min_stroke_px, stroke_fraction * size);
    const double pad = margin_px + 2 * stroke;  // room for the lit-side offsets and ticks
    const double draw_w = (xmax - xmin) * scale, draw_h = (ymax - ymin) * scale;
    const double W = std::max(draw_w + 2 * pad, 420.0);
    const double H = caption_px + draw_h + 2 * pad + (rgb ? 0 : legend_px);
    const double ox = (W - draw_w) / 2, oy = caption_px + pad;
    auto px = [&](const Vec2& p) { return Vec2{ox + (p.x - xmin) * scale, oy + (ymax - p.y) * scale}; };

    const double white = white_point(scene, solution);
    auto color_of = [&](const std::vector<double>& B) {
        if (rgb) return hex({tone_map(B[0], white), tone_map(B[1], white), tone_map(B[2], white)});
        return hex(false_color(B.empty() ? 0 : B[0] / white));
    };

    std::string svg;
    auto out = std::back_inserter(svg);
    fmt::format_to(out,
                   "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
                   "font-family=\"Helvetica, Arial, sans-serif\">\n",
                   num(W), num(H));
    fmt::format_to(out, "<title>{}</title>\n", escape_xml(scene.name));
    fmt::format_to(out, "<rect width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>\n", num(W), num(H));

    fmt::format_to(out, "<rect class=\"backdrop\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>\n",
                   num(ox - pad), num(oy - pad), num(draw_w + 2 * pad), num(draw_h + 2 * pad), backdrop);

    // 2. Caption.
    fmt::format_to(out, "<text x=\"{}\" y=\"20\" font-size=\"16\" text-anchor=\"middle\">{}</text>\n", num(W / 2),
                   escape_xml(scene.name));
    fmt::format_to(out,
                   "<text x=\"{}\" y=\"40\" font-size=\"12\" text-anchor=\"middle\" fill=\"#444444\">{}; {} "
                   "elements, {:.3g} s; {}</text>\n",
                   num(W / 2), escape_xml(settings_text(solution)), solution.stats.elements, solution.stats.time_s,
                   rgb ? fmt::format("tone map: / {:.4g} (99th percentile, lamps excluded), gamma {}", white, gamma)
                       : std::string("color: radiosity, scale below"));

    // 3. Unlit sides (one-sided segments), one path, drawn first.
    std::string unlit;
    for (const SceneSegment& s : scene.segments) {
        if (s.lit_left && s.lit_right) continue;
        const Vec2 a = px(s.seg.a), b = px(s.seg.b);
        const double len = std::hypot(b.x - a.x, b.y - a.y);
        if (!(len > 0)) continue;
        // The left normal of a -> b in the scene is (-dy, dx); in pixels
        // (y down) the same side is (dy, -dx) of the pixel direction.
        double nx = (b.y - a.y) / len, ny = -(b.x - a.x) / len;
        if (s.lit_left) nx = -nx, ny = -ny;  // grey goes on the right: the unlit side
        const double o = 0.5 * stroke;
        unlit += fmt::format("M{} {}L{} {}", num(a.x + o * nx), num(a.y + o * ny), num(b.x + o * nx), num(b.y + o * ny));
    }
    if (!unlit.empty())
        fmt::format_to(out, "<path class=\"unlit\" d=\"{}\" stroke=\"{}\" stroke-width=\"{}\" fill=\"none\"/>\n", unlit,
                       unlit_grey, num(stroke));

    // 4. Elements, one line each, offset to the lit side; ticks at patch middles.
    std::string ticks;
    fmt::format_to(out, "<g stroke-width=\"{}\" stroke-linecap=\"square\">\n", num(stroke));
    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const Patch& patch = scene.patches[p];
        const Segment& seg = scene.segments[static_cast<size_t>(patch.segment)].seg;
        const Vec2 a = px(seg.a), b = px(seg.b);
        const double len = std::hypot(b.x - a.x, b.y - a.y);
        double nx = 0, ny = 0;
        if (len > 0) {
            nx = (b.y - a.y) / len, ny = -(b.x - a.x) / len;  // pixel normal on the scene-left side
            if (!patch.lit_left) nx = -nx, ny = -ny;
        }
        const double o = 0.5 * stroke;
        for (const ElementValue& e : solution.patches[p].elements) {
            const Vec2 p0{a.x + e.t0 * (b.x - a.x), a.y + e.t0 * (b.y - a.y)};
            const Vec2 p1{a.x + e.t1 * (b.x - a.x), a.y + e.t1 * (b.y - a.y)};
            fmt::format_to(out, "<line class=\"element\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\"/>\n",
                           num(p0.x + o * nx), num(p0.y + o * ny), num(p1.x + o * nx), num(p1.y + o * ny),
                           color_of(e.B));
        }
        if (len >= tick_min_patch_strokes * stroke) {
            const Vec2 m{(a.x + b.x) / 2 + stroke * nx, (a.y + b.y) / 2 + stroke * ny};
            ticks += fmt::format("M{} {}l{} {}", num(m.x), num(m.y), num(1.5 * stroke * nx), num(1.5 * stroke * ny));
        }
    }
    svg += "</g>\n";
    if (!ticks.empty())
        fmt::format_to(out, "<path class=\"lit-ticks\" d=\"{}\" stroke=\"{}\" stroke-width=\"{}\" fill=\"none\"/>\n",
                       ticks, tick_color, num(0.4 * stroke));

    // 5. Legend bar (one channel): the false-color scale from 0 to the white point.
    if (!rgb) {
        const double bx0 = W / 2 - 180, bx1 = W / 2 + 180, by = H - legend_px + 12, bh = 14;
        svg += "<defs><linearGradient id=\"scale\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">";
        for (int k = 0; k <= 16; ++k)
            fmt::format_to(out, "<stop offset=\"{:.4f}\" stop-color=\"{}\"/>", k / 16.0, hex(false_color(k / 16.0)));
        svg += "</linearGradient></defs>\n";
        fmt::format_to(out,
                       "<g class=\"legend\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"url(#scale)\" "
                       "stroke=\"#333333\" stroke-width=\"0.5\"/>\n",
                       num(bx0), num(by), num(bx1 - bx0), num(bh));
        for (double v : linear_ticks(0, white, 5)) {
            const double x = bx0 + (bx1 - bx0) * v / white;
            fmt::format_to(out,
                           "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#333333\" stroke-width=\"1\"/>"
                           "<text x=\"{0}\" y=\"{3}\" font-size=\"11\" text-anchor=\"middle\">{4:g}</text>\n",
                           num(x), num(by + bh), num(by + bh + 4), num(by + bh + 16), v + 0.0);  // no "-0"
        }
        fmt::format_to(out,
                       "<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\">radiosity "
                       "(&#8805; {:.4g}, the 99th percentile of lit surfaces: yellow)</text></g>\n",
                       num(W / 2), num(by + bh + 30), white);
    }
    svg += "</svg>\n";
    return svg;
}

}  // namespace flatrad
