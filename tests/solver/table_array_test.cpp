// Tables with samples only where slotted (solver/table_array.h): the linear
// parts of every table and the samples of the slotted ones behave as full
// tables (directional.h) would, and the slot invariant is enforced.
#include "solver/table_array.h"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "engine/error.h"

using namespace flatrad;

namespace {
Vec2 dir(double a) { return {std::cos(a), std::sin(a)}; }
}  // namespace

TEST_CASE("table array: slotted tables match full ones, the others keep only the linear part") {
    // Sums of a few terms of size ~1: rounding only.
    constexpr double tol = 1e-13;
    // Three tables: 0 the parent of 1 and 2; only 1 with samples.
    const std::vector<int32_t> slot{-1, 0, -1};
    TableArray part;
    part.reset(slot, 1);
    TableArray full;
    full.reset_full(3);
    part.clear();  // a layout leaves its contents unspecified
    full.clear();
    REQUIRE(part.tables() == 3);
    CHECK(part.samples(0) == nullptr);
    CHECK(part.samples(2) == nullptr);
    CHECK(part.samples(1) != nullptr);
    CHECK(full.samples(2) != nullptr);
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> U(0, 1);
    for (int t = 1; t <= 2; ++t)
        for (int k = 0; k < 4; ++k) {
            const Vec2 n = dir(2 * std::numbers::pi * U(rng));
            const double w = 0.2 + U(rng);
            add_cosine_lobe(part.samples(t), part.linear(t), n, w);
            add_cosine_lobe(full.samples(t), full.linear(t), n, w);
        }
    for (int k = 0; k < directional_bins; ++k) CHECK(std::abs(part.samples(1)[k] - full.samples(1)[k]) <= tol);
    // Pull into the parent: linear parts only there.
    for (TableArray* a : {&part, &full}) {
        a->sum_child(0, 1);
        a->sum_child(0, 2);
    }
    for (int k = 0; k < 2; ++k) CHECK(std::abs(part.linear(0)[k] - full.linear(0)[k]) <= tol);
    // An arrival at the parent from a direction every lobe faces, pushed
    // down: each child reads, through a lobe, what the linear part gives.
    part.clear();
    full.clear();
    const Vec2 from = dir(1.1);
    add_linear_part(part.linear(0), from, 2.0);
    add_linear_part(full.linear(0), from, 2.0);
    for (TableArray* a : {&part, &full}) {
        a->add_parent(1, 0);
        a->add_parent(2, 0);
    }
    const Vec2 n = dir(0.7);
    for (int t = 1; t <= 2; ++t)
        CHECK(std::abs(read_cosine_lobe(part.samples(t), part.linear(t), n) -
                       read_cosine_lobe(full.samples(t), full.linear(t), n)) <= tol);
    // Clearing one table, then all.
    add_cosine_lobe(part.samples(1), part.linear(1), n, 1.0);
    part.clear(1);
    for (int k = 0; k < directional_bins; ++k) CHECK(part.samples(1)[k] == 0);
    CHECK(part.linear(2)[0] != 0);
    part.clear();
    CHECK(part.linear(2)[0] == 0);
    // The invariant: a parent with samples above a child without would lose
    // the samples' light in a pull or a push; refused.
    const std::vector<int32_t> wrong{0, -1};
    TableArray bad;
    bad.reset(wrong, 1);
    bad.clear();
    CHECK_THROWS_AS(bad.sum_child(0, 1), InternalError);
    CHECK_THROWS_AS(bad.add_parent(1, 0), InternalError);
}
