#pragma once
/// Directional transmittance of the clusters of the shared hierarchy
/// (Soler 1995, §2; DESIGN.md §2), built lazily per cluster and cached.
///
/// For a cluster C (an axis-aligned box) and a direction theta, p runs over
/// the offsets of the lines of direction theta that cross the box
/// (width delta_p(theta)); tau_C(p, theta) is 1 when the line misses C's
/// segments and 0 when it meets one (segments are opaque; only those that
/// can block count, Hierarchy::set_blockers). Per sampled
/// direction the table keeps:
///   tau_bar = mean of tau_C over the box's lines = 1 - |union of shadows| / delta_p;
///   L1  = || tau_C - tau_bar ||_L1 = 2 delta_p tau_bar (1 - tau_bar)   (exact: tau_C is 0/1);
///   R2  = || tau_C - tau_bar ||_L2 = sqrt(delta_p tau_bar (1 - tau_bar)) (exact, unfiltered);
///   R2f = the same after the level-of-detail filter: the Haar projection of
///         tau_C onto `bins` equal cells across the box (details finer than
///         delta_p / bins, far below the cluster's size, are dropped);
///   R1  = sup over |theta' - theta| <= Delta_theta of || tau_f(., theta') - tau_f(., theta) ||_L2,
///         the filtered profiles compared in the box-centred frame (lines
///         outside the box transmit 1); the sup is taken over offsets of
///         1, 2, 4, ... samples and Delta_theta itself.
///
/// How the tables are made, and why not as the paper does: the paper
/// samples -log tau at the leaves and adds the children's densities
/// bottom-up, which treats overlapping shadows of different children as
/// independent (their product overcounts blocking). In 2D the exact union of
/// a cluster's shadows in one direction is a sort of n intervals, so each
/// table is computed exactly from the cluster's own segments: O(n log n) per
/// direction, built only for clusters a query actually asks about.
/// tau_bar is exact at the sampled directions; between them it is
/// interpolated linearly, and `interp_err` reports the change across the
/// interval as the interpolation's error bound (exact when tau_bar is
/// monotone between samples).
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "engine/hierarchy.h"

namespace flatrad {

struct ClusterTable {
    std::vector<double> delta_p, tau_bar, L1, R2, R2f, R1;  ///< per sampled direction
};

class ClusterTables {
public:
    static constexpr int directions = 256;  ///< samples of theta over [0, pi)
    static constexpr int bins = 16;         ///< level-of-detail cells across the box
    /// Delta_theta of DESIGN §2: the widest direction spread R1 covers.
    static constexpr double max_delta_theta = 0.25;

    explicit ClusterTables(const Hierarchy& hierarchy);

    /// The table of hierarchy node `node`, built on first use (thread-safe).
    const ClusterTable& table(int node) const;

    struct Sample {
        double delta_p, tau_bar, L1, R2, R2f, R1;
        double interp_err;  ///< |tau_bar change| across the interpolation interval
    };
    /// Linear interpolation at absolute direction theta (radians, any value:
    /// lines are unoriented, period pi).
    Sample at(int node, double theta) const;
    /// tau_bar alone at theta, from a table already obtained (hot loops).
    static double tau_bar_at(const ClusterTable& t, double theta);
    /// Largest L1 + delta_p * interp_err over the samples in [theta0, theta1]
    /// (and the two samples bracketing it): the L1 deviation bound over a
    /// range of directions.
    double max_l1_over(int node, double theta0, double theta1) const;

    long built() const { return m_built.load(); }
    double build_seconds() const;
    /// Bytes held by one built table.
    static size_t bytes_per_table();
    const Hierarchy& hierarchy() const { return *m_hierarchy; }

private:
    void build(int node) const;

    const Hierarchy* m_hierarchy;
    mutable std::vector<std::unique_ptr<ClusterTable>> m_tables;
    mutable std::unique_ptr<std::once_flag[]> m_once;
    mutable std::atomic<long> m_built{0};
    mutable std::atomic<long> m_build_ns{0};
};

/// The exact table entry of a segment set at one direction (the reference
/// the tables are tested against): tau_bar over the box's lines.
double exact_tau_bar(const std::vector<Segment>& segments, const Box& box, double theta);

}  // namespace flatrad
