#include "solver/closed_rows.h"

#include <string>
#include <unordered_set>

#include "solver/loop_sides.h"

namespace flatrad {

std::vector<char> closed_rows(const Scene& scene, const Connectivity& conn, const std::vector<char>& escape_free,
                              const std::vector<char>& visible_sink, const std::vector<char>& inert) {
    const size_t P = scene.patches.size();
    auto side_of = [&](size_t p) {
        const Patch& q = scene.patches[p];
        return 2 * static_cast<size_t>(q.segment) + (q.lit_left ? 0 : 1);
    };
    // The sides that send nothing, and the patches whose rows may close.
    std::vector<size_t> dark(0), candidates;
    for (size_t x = 0; x < visible_sink.size(); ++x)
        if (visible_sink[x]) dark.push_back(x);
    for (size_t p = 0; p < P; ++p) {
        if (inert[p]) dark.push_back(side_of(p));
        else if (escape_free[p]) candidates.push_back(p);
    }
    std::vector<char> closed(P, 0);
    if (dark.empty()) {
        for (size_t p : candidates) closed[p] = 1;
        return closed;
    }
    if (candidates.empty()) return closed;
    // Each dark side's and each candidate's class against each loop, as
    // strings of one char per loop (dark sides with the same string are
    // kept apart from the same candidates: test each string once).
    const size_t S = scene.segments.size();
    std::vector<std::string> dark_where(dark.size()), cand_where(candidates.size());
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
    const std::unordered_set<std::string> distinct(dark_where.begin(), dark_where.end());
    const size_t K = cand_where[0].size();
    if (static_cast<double>(distinct.size()) * static_cast<double>(candidates.size()) * static_cast<double>(K) > 1e8)
        return closed;
    for (size_t i = 0; i < candidates.size(); ++i) {
        bool apart_from_all = true;
        for (const std::string& d : distinct) {
            bool apart = false;
            for (size_t k = 0; k < K && !apart; ++k)
                apart = kept_apart(static_cast<LoopSide>(d[k]), static_cast<LoopSide>(cand_where[i][k]));
            if (!apart) {
                apart_from_all = false;
                break;
            }
        }
        closed[candidates[i]] = apart_from_all ? 1 : 0;
    }
    return closed;
}

}  // namespace flatrad
