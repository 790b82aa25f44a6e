#include "visibility/opaque_band.h"

#include <algorithm>
#include <cmath>

#include "visibility/shaft.h"

namespace flatrad {

namespace {

using Interval = OpaqueBandScratch::Interval;
using Bin = OpaqueBandScratch::Bin;
using Section = OpaqueBandScratch::Section;  // points [first, first + count) of the scratch

// Points of a section before its pieces' ends: its own two ends, then two
// points of the lower side and two of the upper (covers()).
constexpr size_t section_head = 6;

// Whether the section's pieces stop every line that crosses the section, at
// every direction of [c - h, c + h], among the lines that stay inside the
// shaft over the band's depths. Each point's offset n(phi) . P (about the
// section's midpoint) is within |P| h of its value at c; the lines to stop
// are widened by that, each piece's shadow narrowed by it (what it shadows
// at every direction of the bin). Anything not finite leaves it uncovered.
bool covers(const Section& section, Bin bin, OpaqueBandScratch& ws) {
    const double nx = -std::sin(bin.c), ny = std::cos(bin.c), h = bin.h;
    const Vec2* P = ws.points.data() + section.first;
    const double* R = ws.radius.data() + section.first;
    auto proj = [&](size_t k) { return nx * P[k].x + ny * P[k].y; };
    // Lines across the section (points 0, 1), above the lower side at the
    // band's outer depths (points 2, 3), below the upper side there (4, 5).
    // The section's own ends are widened too: the sections tile X at the
    // bin's centre direction only, and elsewhere in the bin a line through
    // a boundary between two sections can fall outside both unwidened
    // windows.
    Interval window = swept(proj(0), R[0] * h, proj(1), R[1] * h);
    for (const size_t k : {size_t{2}, size_t{3}}) window.a = std::max(window.a, proj(k) - R[k] * h);
    for (const size_t k : {size_t{4}, size_t{5}}) window.b = std::min(window.b, proj(k) + R[k] * h);
    if (!(window.b > window.a)) return window.b <= window.a;  // no line to stop; false if not finite
    auto& shadows = ws.shadows;
    shadows.clear();
    for (size_t k = section_head; k + 1 < section.count; k += 2) {
        const Interval s = held(proj(k), R[k] * h, proj(k + 1), R[k + 1] * h);
        if (s.b > s.a && s.b > window.a && s.a < window.b) shadows.push_back(s);
    }
    std::sort(shadows.begin(), shadows.end(), [](const Interval& x, const Interval& y) { return x.a < y.a; });
    double reach = window.a;
    for (const Interval& s : shadows) {
        if (s.a > reach) return false;  // a gap of positive width
        reach = std::max(reach, s.b);
        if (reach >= window.b) return true;
    }
    return false;
}

// The y at depth t of the line through p and q (a side of the shaft, whose
// ends lie on either side of every depth between the patches).
double y_at(double t, Vec2 p, Vec2 q) { return p.y + (t - p.x) / (q.x - p.x) * (q.y - p.y); }

}  // namespace

bool band_closes_shaft(const Segment& ci, const Segment& cj, const Segment* blockers, size_t count,
                       OpaqueBandScratch& ws) {
    if (count == 0) return false;
    const shaft_detail::PairFrame frame(ci, cj);
    const double delta = frame.delta_theta;
    if (!(delta > 0) || !std::isfinite(delta)) return false;
    // The shaft A0 A1 C0 C1 in the frame, x the depth along the pair's axis.
    const Vec2 A0 = frame.local(ci.a), A1 = frame.local(ci.b), C0 = frame.local(cj.a), C1 = frame.local(cj.b);
    const double xi = std::max(A0.x, A1.x), xj = std::min(C0.x, C1.x);
    if (!(xj > xi) || !std::isfinite(xj - xi)) return false;  // no transversal x = t0 between them

    // The blockers clipped to the slab xi <= x <= xj: a line from ci to
    // cj is at those depths only between its ends on the patches (its depth
    // grows along it, |phi| < pi/2), so a blocker there stops it wherever
    // the line meets it.
    auto& local = ws.local;
    local.clear();
    for (size_t q = 0; q < count; ++q) {
        const Vec2 P = frame.local(blockers[q].a), Q = frame.local(blockers[q].b);
        if (!(std::isfinite(P.x) && std::isfinite(P.y) && std::isfinite(Q.x) && std::isfinite(Q.y))) continue;
        double t_lo = 0, t_hi = 1;
        if (P.x != Q.x) {
            const double ta = (xi - P.x) / (Q.x - P.x), tb = (xj - P.x) / (Q.x - P.x);
            t_lo = std::max(t_lo, std::min(ta, tb));
            t_hi = std::min(t_hi, std::max(ta, tb));
        } else if (!(P.x >= xi && P.x <= xj)) {
            continue;
        }
        if (!(t_hi > t_lo)) continue;
        local.push_back(lerp(P, Q, t_lo));
        local.push_back(lerp(P, Q, t_hi));
    }
    const size_t n = local.size() / 2;
    if (n == 0) return false;
    {
        // Layers over the whole slab: the pieces' shadows across the axis
        // over the shaft's mean width. A band holds a share of them; with
        // few in all, no band closes the shaft and the attempt is skipped.
        double across = 0;
        for (size_t q = 0; q < n; ++q) across += std::abs(local[2 * q + 1].y - local[2 * q].y);
        const auto width_at = [&](double t) { return std::abs(y_at(t, A1, C0) - y_at(t, C1, A0)); };
        const double mean_width = 0.5 * (width_at(xi) + width_at(xj));
        if (!(across >= opaque_band_min_layers * mean_width)) return false;
    }
    // The pieces by the depth of their midpoints: a band is a run of them
    // around its depth.
    auto& index = ws.index;
    auto& mid = ws.mid;
    index.resize(n);
    mid.resize(n);
    for (size_t q = 0; q < n; ++q) {
        index[q] = q;
        mid[q] = 0.5 * (local[2 * q].x + local[2 * q + 1].x);
    }
    std::sort(index.begin(), index.end(), [&](size_t a, size_t b) { return mid[a] < mid[b]; });

    ws.points.clear();
    ws.radius.clear();
    auto& sections = ws.sections;
    sections.clear();
    // Band k (the middle one first) as sections [first, sections.size());
    // returns the widest bin half-width at which its pieces drift by at
    // most opaque_band_drift of their mean shadow (0: no piece).
    auto build_band = [&](int k) {
        const int slot = (k + opaque_band_count / 2) % opaque_band_count;
        const double t0 = xi + (xj - xi) * (slot + 0.5) / opaque_band_count;
        // The shaft's sides are the edges A1 -> C0 and C1 -> A0, the only
        // two that cross x = t for t between the patches.
        const bool side1_low = y_at(t0, A1, C0) <= y_at(t0, C1, A0);
        auto low_side = [&](double t) { return side1_low ? y_at(t, A1, C0) : y_at(t, C1, A0); };
        auto high_side = [&](double t) { return side1_low ? y_at(t, C1, A0) : y_at(t, A1, C0); };
        const double ya = low_side(t0), yb = high_side(t0);
        // Pieces nearest in depth, until their shadows across the axis add
        // up to opaque_band_layers times the section X (or to
        // opaque_band_max_pieces).
        const double needed = opaque_band_layers * (yb - ya);
        size_t right = static_cast<size_t>(
            std::lower_bound(index.begin(), index.end(), t0, [&](size_t q, double t) { return mid[q] < t; }) -
            index.begin());
        size_t left = right;                  // the run taken is index[left, right)
        double across = 0, before = 0, after = 0;  // before, after: the run's reach in depth
        while (across < needed && right - left < opaque_band_max_pieces && (left > 0 || right < n)) {
            const bool take_left = right == n || (left > 0 && t0 - mid[index[left - 1]] < mid[index[right]] - t0);
            const size_t q = take_left ? index[--left] : index[right++];
            across += std::abs(local[2 * q + 1].y - local[2 * q].y);
            before = std::max({before, t0 - local[2 * q].x, t0 - local[2 * q + 1].x});
            after = std::max({after, local[2 * q].x - t0, local[2 * q + 1].x - t0});
        }
        const size_t taken = right - left;
        if (taken == 0 || !(across > 0)) return 0.0;
        // X in sections a few mean shadows wide, each turned about its own
        // midpoint: the drift grows with the distance to the centre.
        const double mean_shadow = across / static_cast<double>(taken);
        const double wanted = std::ceil((yb - ya) / (opaque_band_section_shadows * mean_shadow));
        const int S = static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(opaque_band_max_sections)));
        // A piece whose offset can reach a section's lines at some direction
        // of the range: across the axis within the section's half-width, plus
        // its depth from t0 times tan(delta), over cos(delta) (a wider margin
        // only costs time).
        const double depth = std::max(before, after);
        const double w = (yb - ya) / S;
        const double margin = (0.5 * w + depth * std::tan(delta)) / std::cos(delta) + 0.5 * w;
        // Which sections each piece may reach (counting sort by section).
        auto& first_of = ws.bucket_first;
        auto& items = ws.bucket_items;
        first_of.assign(static_cast<size_t>(S) + 1, 0);
        auto span = [&](size_t q) {
            const Vec2 P = local[2 * q], Q = local[2 * q + 1];
            const double lo = std::ceil((std::min(P.y, Q.y) - margin - ya) / w - 0.5);
            const double hi = std::floor((std::max(P.y, Q.y) + margin - ya) / w - 0.5);
            return std::pair<int, int>{static_cast<int>(std::clamp(lo, 0.0, S - 1.0)),
                                       static_cast<int>(std::clamp(hi, -1.0, S - 1.0))};
        };
        for (size_t r = left; r < right; ++r) {
            const auto [lo, hi] = span(index[r]);
            for (int s = lo; s <= hi; ++s) ++first_of[static_cast<size_t>(s) + 1];
        }
        for (int s = 0; s < S; ++s) first_of[static_cast<size_t>(s) + 1] += first_of[static_cast<size_t>(s)];
        items.resize(first_of[static_cast<size_t>(S)]);
        {
            auto& fill = ws.bucket_fill;
            fill.assign(first_of.begin(), first_of.end() - 1);
            for (size_t r = left; r < right; ++r) {
                const auto [lo, hi] = span(index[r]);
                for (int s = lo; s <= hi; ++s) items[fill[static_cast<size_t>(s)]++] = index[r];
            }
        }
        double reach = 0;
        for (int s = 0; s < S; ++s) {
            const double y0 = ya + w * s, y1 = ya + w * (s + 1);
            const Vec2 O{t0, 0.5 * (y0 + y1)};
            Section section{ws.points.size(), 0};
            auto add = [&](Vec2 p) {
                ws.points.push_back(p - O);
                ws.radius.push_back(norm(p - O));
                ++section.count;
            };
            add({t0, y0});
            add({t0, y1});
            // A line from ci to cj stays inside the shaft at every depth of
            // the slab, so at the run's outer depths it passes above the
            // lower side and below the upper: lines outside those (which
            // pieces inside the shaft need not stop) are not asked for.
            for (const double t : {t0 - before, t0 + after}) add({t, low_side(t)});
            for (const double t : {t0 - before, t0 + after}) add({t, high_side(t)});
            for (size_t it = first_of[static_cast<size_t>(s)]; it < first_of[static_cast<size_t>(s) + 1]; ++it) {
                add(local[2 * items[it]]);
                add(local[2 * items[it] + 1]);
            }
            for (size_t q = section.first; q < section.first + section.count; ++q)
                reach = std::max(reach, ws.radius[q]);
            sections.push_back(section);
        }
        return reach > 0 ? opaque_band_drift * mean_shadow / reach : 0.0;
    };

    // The bins: at least opaque_band_initial_bins, narrow enough for the
    // middle band. The other bands are built when a bin needs them; the
    // first bin no band closes ends the attempt (an open shaft usually
    // shows it within a few bins).
    size_t band_first[opaque_band_count + 1] = {};
    int built = 1;
    const double h_band = build_band(0);
    band_first[1] = sections.size();
    if (!(h_band > 0)) return false;
    const double bins_wanted = std::max<double>(opaque_band_initial_bins, std::ceil(delta / h_band));
    if (!(bins_wanted <= opaque_band_max_bins)) return false;  // too costly (or not finite)
    if (bins_wanted * static_cast<double>(band_first[1]) > opaque_band_max_checks) return false;
    const int bins = static_cast<int>(bins_wanted);
    const double h = delta / bins;
    for (int b = 0; b < bins; ++b) {
        const Bin bin{-delta + (2 * b + 1) * h, h};
        bool closed = false;
        for (int k = 0; k < opaque_band_count && !closed; ++k) {
            if (k == built) {
                build_band(k);
                band_first[++built] = sections.size();
            }
            closed = band_first[k + 1] > band_first[k];
            for (size_t sct = band_first[k]; sct < band_first[k + 1] && closed; ++sct)
                closed = covers(sections[sct], bin, ws);
        }
        if (!closed) return false;
    }
    return true;
}

}  // namespace flatrad
