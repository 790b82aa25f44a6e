#pragma once
// Two solutions compared exactly: the links, every visibility counter and
// the radiosity of every element (no tolerance: the claim of the tests
// that use it is bit-for-bit equality). Checks inside (doctest).
#include <doctest/doctest.h>

#include <cstddef>

#include "solver/solution.h"

namespace flatrad::test {

inline void check_same(const Solution& a, const Solution& b) {
    const VisibilityStats &u = a.stats.visibility, &v = b.stats.visibility;
    CHECK(a.stats.links == b.stats.links);
    CHECK(a.stats.cluster_links == b.stats.cluster_links);
    CHECK(a.stats.unqueried_links == b.stats.unqueried_links);
    CHECK(a.stats.passes == b.stats.passes);
    CHECK(a.stats.iterations == b.stats.iterations);
    CHECK(a.stats.elements == b.stats.elements);
    CHECK(u.queries == v.queries);
    CHECK(u.unoccluded == v.unoccluded);
    CHECK(u.culled == v.culled);
    CHECK(u.clusters_visited == v.clusters_visited);
    CHECK(u.blockers == v.blockers);
    CHECK(u.events == v.events);
    CHECK(u.separated == v.separated);
    CHECK(u.subshafts == v.subshafts);
    CHECK(u.bounded == v.bounded);
    CHECK(u.opaque == v.opaque);
    CHECK(u.banded == v.banded);
    CHECK(u.slabs == v.slabs);
    CHECK(u.screens == v.screens);
    CHECK(u.screened == v.screened);
    CHECK(a.totals.balance == b.totals.balance);
    REQUIRE(a.patches.size() == b.patches.size());
    size_t differing = 0;
    for (size_t p = 0; p < a.patches.size(); ++p) {
        const PatchResult &x = a.patches[p], &y = b.patches[p];
        bool same = x.radiosity == y.radiosity && x.elements.size() == y.elements.size();
        for (size_t k = 0; same && k < x.elements.size(); ++k)
            same = x.elements[k].t0 == y.elements[k].t0 && x.elements[k].t1 == y.elements[k].t1 &&
                   x.elements[k].B == y.elements[k].B;
        differing += same ? 0 : 1;
    }
    CHECK(differing == 0);
}

}  // namespace flatrad::test
