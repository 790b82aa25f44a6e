#include "solver/closed_rows.h"

#include <string>
#include <unordered_set>

#include "solver/loop_sides.h"

namespace flatrad {

namespace {

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
    auto side_of = [&](size_t p) {
        const Patch& q = scene.patches[p];
        return 2 * static_cast<size_t>(q.segment) + (q.lit_left ? 0 : 1);
    };
    std::vector<size_t> sinks, inerts, candidates;
    for (size_t x = 0; x < visible_sink.size(); ++x)
        if (visible_sink[x]) sinks.push_back(x);
    for (size_t p = 0; p < P; ++p) {
        if (inert[p]) inerts.push_back(p);
        else if (escape_free[p]) candidates.push_back(p);
    }
    ClosedRows r;
    r.closed.assign(P, 0);
    r.inert_sends.assign(P, 0);
    if (candidates.empty()) return r;
    if (sinks.empty() && inerts.empty()) {
        for (size_t p : candidates) r.closed[p] = 1;
        return r;
    }
    // Each side's class against each loop, as strings of one char per loop
    // (sides with the same string are kept apart from the same ones: test
    // each string once).
    const size_t S = scene.segments.size();
    std::vector<std::string> sink_where(sinks.size()), inert_where(inerts.size()), cand_where(candidates.size());
    double budget = 1e8;
    for (const SceneLoop& L : conn.loops) {
        if (!L.simple || L.orientation == 0) continue;
        const double cost = static_cast<double>(S) * static_cast<double>(L.polygon.size());
        if (cost > budget) continue;
        budget -= cost;
        const std::vector<LoopSide> where = loop_sides(scene, L);
        for (size_t i = 0; i < sinks.size(); ++i) sink_where[i].push_back(static_cast<char>(where[sinks[i]]));
        for (size_t i = 0; i < inerts.size(); ++i) inert_where[i].push_back(static_cast<char>(where[side_of(inerts[i])]));
        for (size_t i = 0; i < candidates.size(); ++i)
            cand_where[i].push_back(static_cast<char>(where[side_of(candidates[i])]));
    }
    const std::unordered_set<std::string> sink_kinds(sink_where.begin(), sink_where.end());
    std::unordered_set<std::string> inert_kinds(inert_where.begin(), inert_where.end());
    const double K = static_cast<double>(cand_where[0].size());
    if (static_cast<double>(sink_kinds.size() + inert_kinds.size()) * static_cast<double>(candidates.size()) * K > 1e8)
        return r;
    // Rows kept apart from every visible sink close.
    for (size_t i = 0; i < candidates.size(); ++i) {
        bool closes = true;
        for (const std::string& d : sink_kinds) {
            if (apart(d, cand_where[i])) continue;
            closes = false;
            break;
        }
        r.closed[candidates[i]] = closes ? 1 : 0;
    }
    // Inert patches that some closed row may see send.
    std::unordered_set<std::string> seen;
    for (size_t i = 0; i < candidates.size() && seen.size() < inert_kinds.size(); ++i) {
        if (!r.closed[candidates[i]]) continue;
        for (const std::string& d : inert_kinds)
            if (!seen.count(d) && !apart(d, cand_where[i])) seen.insert(d);
    }
    for (size_t i = 0; i < inerts.size(); ++i) r.inert_sends[inerts[i]] = seen.count(inert_where[i]) ? 1 : 0;
    return r;
}

}  // namespace flatrad
