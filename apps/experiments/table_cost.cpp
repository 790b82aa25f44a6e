// flatrad_table_cost: precomputation cost of the multi-scale cluster tables
// (issue "multi-scale visibility": precomputation time and memory per
// cluster, and the time for a cluster of 10^5 segments).
//
// Usage: flatrad_table_cost [REPEAT]   (median of REPEAT builds, default 3)
// For N in 10^3, 10^4, 10^5 random short segments in a unit square: the
// time to build the root cluster's table (all N segments), and to build
// every table of the hierarchy.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "visibility/cluster_tables.h"

using namespace flatrad;

int main(int argc, char** argv) {
    const int repeat = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    std::printf("# flatrad_table_cost %d: %d directions x %d bins, %zu bytes per table\n", repeat,
                ClusterTables::directions, ClusterTables::bins, ClusterTables::bytes_per_table());
    std::printf("%8s %8s %14s %16s %14s\n", "N", "nodes", "root_table_s", "all_tables_s", "all_MiB");
    for (int n : {1000, 10000, 100000}) {
        std::mt19937_64 rng(42);
        std::uniform_real_distribution<double> U(0, 1);
        std::vector<Segment> segs;
        for (int k = 0; k < n; ++k) {
            const Vec2 c{U(rng), U(rng)};
            const double a = 6.283185307179586 * U(rng), l = 0.5 / std::sqrt(static_cast<double>(n));
            segs.push_back({c - Vec2{std::cos(a), std::sin(a)} * (l / 2), c + Vec2{std::cos(a), std::sin(a)} * (l / 2)});
        }
        const Hierarchy h(segs, 2);
        std::vector<double> root_t, all_t;
        for (int r = 0; r < repeat; ++r) {
            const ClusterTables tables(h);
            auto t0 = std::chrono::steady_clock::now();
            (void)tables.table(h.root());
            root_t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            if (n <= 10000 || r == 0) {
                t0 = std::chrono::steady_clock::now();
                for (int k = 0; k < static_cast<int>(h.nodes().size()); ++k) (void)tables.table(k);
                all_t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
        }
        std::sort(root_t.begin(), root_t.end());
        std::sort(all_t.begin(), all_t.end());
        std::printf("%8d %8zu %14.4f %16.3f %14.1f\n", n, h.nodes().size(), root_t[root_t.size() / 2],
                    all_t[all_t.size() / 2],
                    static_cast<double>(h.nodes().size() * ClusterTables::bytes_per_table()) / (1 << 20));
    }
    return 0;
}
