#include "solver/closed_rows.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "solver/loop_sides.h"

namespace flatrad {

namespace {

// A row whose patch reflects at least this much in some channel, where the
// refinement's lost light comes back 20 times or more (see the header).
constexpr double stiff_reflectance = 0.95;

// Whether some loop keeps the two sides apart (their classes, one char per
// loop).
bool apart(const std::string& a, const std::string& b) {
    for (size_t k = 0; k < a.size(); ++k)
        if (kept_apart(static_cast<LoopSide>(a[k]), static_cast<LoopSide>(b[k]))) return true;
    return false;
}

}  // namespace

ClosedRows closed_rows(const Scene& scene, const Connectivity& conn, const std::vector<char>& escape_free,
                       const std::vector<char>& visible_sink, const std::vector<char>& inert) {
    const size_t P = scene.patches.size();
    auto stiff = [&](size_t p) {
        const Material& m = scene.materials[static_cast<size_t>(scene.patches[p].material)];
        return *std::max_element(m.reflectance.begin(), m.reflectance.end()) >= stiff_reflectance;
    };
    auto side_of = [&](size_t p) {
        const Patch& q = scene.patches[p];
        return 2 * static_cast<size_t>(q.segment) + (q.lit_left ? 0 : 1);
    };
    // The sides that send nothing (dark_patch: the inert patch, -1 for a
    // sink), and the patches whose rows may close.
    std::vector<size_t> dark, candidates;  // dark: segment sides
    std::vector<long> dark_patch;
    for (size_t x = 0; x < visible_sink.size(); ++x)
        if (visible_sink[x]) {
            dark.push_back(x);
            dark_patch.push_back(-1);
        }
    for (size_t p = 0; p < P; ++p) {
        if (inert[p]) {
            dark.push_back(side_of(p));
            dark_patch.push_back(static_cast<long>(p));
        } else if (escape_free[p]) {
            candidates.push_back(p);
        }
    }
    ClosedRows r;
    r.closed.assign(P, 0);
    r.inert_sends.assign(P, 0);
    r.sink_sends.assign(visible_sink.size(), 0);
    if (candidates.empty()) return r;
    if (dark.empty()) {
        for (size_t p : candidates) r.closed[p] = 1;
        return r;
    }
    // Each side's classes against the loops, one char per loop. Sides with
    // the same string are kept apart from the same ones, so each side holds
    // the number of its string (the strings refined loop by loop: most
    // sides share a few), and the pairs are tested string against string.
    // Items: the dark sides, then the candidates (stiff ones flagged).
    const size_t S = scene.segments.size(), D = dark.size();
    std::vector<size_t> item_side(dark);
    for (size_t p : candidates) item_side.push_back(side_of(p));
    std::vector<int32_t> kind(item_side.size(), 0);
    std::vector<std::string> strings(1);
    double budget = 1e8;
    for (const SceneLoop& L : conn.loops) {
        if (!L.simple || L.orientation == 0) continue;
        const double cost = static_cast<double>(S) * static_cast<double>(L.polygon.size());
        if (cost > budget) continue;
        budget -= cost;
        const std::vector<LoopSide> where = loop_sides(scene, L);
        std::vector<int32_t> next(strings.size() * 3, -1);  // (old string, class) -> new string
        std::vector<std::string> refined;
        for (size_t i = 0; i < item_side.size(); ++i) {
            const char c = static_cast<char>(where[item_side[i]]);
            int32_t& to = next[static_cast<size_t>(kind[i]) * 3 + static_cast<size_t>(c)];
            if (to < 0) {
                to = static_cast<int32_t>(refined.size());
                refined.push_back(strings[static_cast<size_t>(kind[i])] + c);
            }
            kind[i] = to;
        }
        strings = std::move(refined);
    }
    // The strings of the dark sides, of the candidates, of the stiff ones.
    std::vector<char> is_dark(strings.size(), 0), is_cand(strings.size(), 0), is_stiff(strings.size(), 0);
    for (size_t i = 0; i < item_side.size(); ++i) {
        const size_t k = static_cast<size_t>(kind[i]);
        if (i < D) is_dark[k] = 1;
        else {
            is_cand[k] = 1;
            if (stiff(candidates[i - D])) is_stiff[k] = 1;
        }
    }
    std::vector<size_t> dark_kinds, cand_kinds;
    for (size_t k = 0; k < strings.size(); ++k) {
        if (is_dark[k]) dark_kinds.push_back(k);
        if (is_cand[k]) cand_kinds.push_back(k);
    }
    const double loops = static_cast<double>(strings[0].size());
    if (static_cast<double>(dark_kinds.size()) * static_cast<double>(cand_kinds.size()) * loops > 1e8) return r;
    // The kinds of dark side that some stiff candidate may see are made
    // senders; a candidate's row closes when every kind it may see is.
    std::vector<char> sends(strings.size(), 0);
    for (size_t c : cand_kinds)
        if (is_stiff[c])
            for (size_t d : dark_kinds)
                if (!apart(strings[d], strings[c])) sends[d] = 1;
    std::vector<char> closes(strings.size(), 0);
    for (size_t c : cand_kinds) {
        closes[c] = 1;
        for (size_t d : dark_kinds)
            if (!sends[d] && !apart(strings[d], strings[c])) {
                closes[c] = 0;
                break;
            }
    }
    for (size_t i = 0; i < item_side.size(); ++i) {
        const size_t k = static_cast<size_t>(kind[i]);
        if (i >= D) {
            r.closed[candidates[i - D]] = closes[k];
        } else if (sends[k]) {
            if (dark_patch[i] < 0) r.sink_sends[dark[i]] = 1;
            else r.inert_sends[static_cast<size_t>(dark_patch[i])] = 1;
        }
    }
    return r;
}

}  // namespace flatrad
