// solver/uninitialized_allocator.h: a vector that leaves resize(n)'s new
// elements unwritten still constructs what it is given (push_back, insert,
// copies), and keeps its elements through growth.
#include "solver/uninitialized_allocator.h"

#include <doctest/doctest.h>

#include <vector>

using namespace flatrad;

namespace {

struct Pair {
    int a = -1;
    double b = 2.5;
};

}  // namespace

TEST_CASE("uninitialized allocator: given values are constructed, resize then write holds them") {
    std::vector<Pair, UninitializedAllocator<Pair>> v;
    v.push_back(Pair{1, 0.5});
    v.push_back(Pair{});  // a value-initialised argument is copied, not left out
    CHECK(v[0].a == 1);
    CHECK(v[0].b == 0.5);
    CHECK(v[1].a == -1);
    CHECK(v[1].b == 2.5);
    // Growth by resize, every new element written before it is read (the
    // allocator's contract), then growth that moves them.
    v.resize(1000);
    for (size_t k = 2; k < v.size(); ++k) v[k] = Pair{static_cast<int>(k), 0.25 * static_cast<double>(k)};
    v.insert(v.end(), Pair{7, 7.0});
    v.reserve(5000);
    REQUIRE(v.size() == 1001);
    bool kept = v[0].a == 1 && v[1].b == 2.5 && v[1000].a == 7;
    for (size_t k = 2; k < 1000; ++k) kept = kept && v[k].a == static_cast<int>(k) && v[k].b == 0.25 * static_cast<double>(k);
    CHECK(kept);
    // Copies construct from the source, shrinking keeps the prefix.
    const std::vector<Pair, UninitializedAllocator<Pair>> w = v;
    CHECK(w.size() == v.size());
    CHECK(w[999].a == 999);
    v.resize(3);
    CHECK(v[2].a == 2);
}
