#pragma once
// The visibility structures of one random cloud (tests/support/clouds.h):
// its hierarchy, cluster tables, and the exact and multi-scale methods over
// them, built together in the order they depend on each other.
#include "support/clouds.h"
#include "visibility/exact_visibility.h"
#include "visibility/multiscale.h"

namespace flatrad::test {

struct CloudVisibility {
    explicit CloudVisibility(const Cloud& c)
        : hierarchy(c.segments), tables(hierarchy), multiscale(hierarchy, tables), exact(hierarchy) {}
    CloudVisibility(const CloudVisibility&) = delete;
    CloudVisibility& operator=(const CloudVisibility&) = delete;

    const Hierarchy hierarchy;
    const ClusterTables tables;
    MultiscaleVisibility multiscale;  // (settable: set_min_pieces_to_bound)
    const ExactVisibility exact;
};

}  // namespace flatrad::test
