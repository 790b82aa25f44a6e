#include "solver/closed_rows.h"

#include <algorithm>
#include <string>
#include <unordered_set>

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
    // Each side's class against each loop, as strings of one char per loop
    // (dark sides with the same string are seen from the same rows: test
    // each string once).
    const size_t S = scene.segments.size();
    std::vector<std::string> dark_where(dark.size()), cand_where(candidates.size());
    if (!dark.empty()) {
        double budget = 1e8;
        for (const SceneLoop& L : conn.loops) {
            if (!L.simple || L.orientation == 0) continue;
            const double cost = static_cast<double>(S) * static_cast<double>(L.polygon.size());
            if (cost > budget) continue;
            budget -= cost;
            const std::vector<LoopSide> where = loop_sides(scene, L);
            for (size_t i = 0; i < dark.size(); ++i) dark_where[i].push_back(static_cast<char>(where[dark[i]]));
            for (size_t i = 0; i < candidates.size(); ++i)
                cand_where[i].push_back(static_cast<char>(where[side_of(candidates[i])]));
        }
        const std::unordered_set<std::string> kinds(dark_where.begin(), dark_where.end());
        const double K = static_cast<double>(cand_where[0].size());
        if (static_cast<double>(kinds.size()) * static_cast<double>(candidates.size()) * K > 1e8) return r;
        // The kinds of dark side that some stiff candidate may see are made
        // senders; a candidate's row closes when every kind it may see is.
        std::unordered_set<std::string> senders;
        for (size_t i = 0; i < candidates.size() && senders.size() < kinds.size(); ++i) {
            if (!stiff(candidates[i])) continue;
            for (const std::string& d : kinds)
                if (!senders.count(d) && !apart(d, cand_where[i])) senders.insert(d);
        }
        for (size_t i = 0; i < dark.size(); ++i) {
            if (!senders.count(dark_where[i])) continue;
            if (dark_patch[i] < 0) r.sink_sends[dark[i]] = 1;
            else r.inert_sends[static_cast<size_t>(dark_patch[i])] = 1;
        }
        for (size_t i = 0; i < candidates.size(); ++i) {
            bool closes = true;
            for (const std::string& d : kinds) {
                if (senders.count(d) || apart(d, cand_where[i])) continue;
                closes = false;
                break;
            }
            r.closed[candidates[i]] = closes ? 1 : 0;
        }
        return r;
    }
    for (size_t p : candidates) r.closed[p] = 1;
    return r;
}

}  // namespace flatrad
