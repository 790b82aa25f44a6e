#include "solver/light_parts.h"

#include <boost/pending/disjoint_sets.hpp>

namespace flatrad {

LightParts connected_parts(int vertices, const std::vector<std::pair<int, int>>& edges) {
    const size_t n = static_cast<size_t>(vertices);
    std::vector<int> rank(n, 0), parent(n);
    boost::disjoint_sets<int*, int*> sets(rank.data(), parent.data());
    for (int v = 0; v < vertices; ++v) sets.make_set(v);
    for (const auto& [a, b] : edges) sets.union_set(a, b);
    LightParts out;
    out.part.assign(n, -1);
    std::vector<int> id(n, -1);  // representative -> part number
    for (int v = 0; v < vertices; ++v) {
        const int rep = sets.find_set(v);
        int& p = id[static_cast<size_t>(rep)];
        if (p < 0) p = out.count++;
        out.part[static_cast<size_t>(v)] = p;
    }
    return out;
}

}  // namespace flatrad
