#pragma once
/// The directional model of a cluster (DESIGN.md §3: "cluster senders and
/// receivers need a directional model ... a table per cluster is cheap"):
/// functions of one angle on a table of `directional_bins` equally spaced
/// directions phi_k = k 2 pi / K, read by linear interpolation (periodic).
///
/// A surface element e (length L_e, radiosity B_e, lit normal n_e) sends
/// into direction u(phi) the power per radian (B_e L_e / 2) cos+(n_e . u)
/// (radiance B / 2 in flatland: the cosine integrates to 2 over the half
/// circle), cos+ = max(0, cos). A cluster's exitance table is the sum over
/// its elements: I(phi_k). Light arriving at a cluster from direction psi
/// (the direction towards the sender) with density a (power per unit length
/// across the beam) gives each element e irradiance a cos+(n_e . u(psi));
/// the cluster's irradiance table J(psi_k) holds the arrivals spread onto
/// the two nearest directions with the interpolation weights, and an
/// element reads sum_k J_k cos+(n_e . u(psi_k)), i.e. its cosine
/// interpolated at psi.
///
/// Error: linear interpolation of a function f between samples h apart is
/// off by at most h^2/8 max|f''| where f is smooth; at the kink of cos+ (a
/// grazing element) by up to h/4 of its weight. Both show in the table's
/// second differences, which interpolation_error() returns as the estimate
/// used by the refinement oracle: half the largest |f_{j-1} - 2 f_j +
/// f_{j+1}| over the four samples j nearest phi. A kink at fraction c of an
/// interval errs by c (1 - c) h x slope and puts max(c, 1 - c) h x slope in
/// a second difference, so half of it covers the kink; smooth parts get a
/// 4x margin over h^2 f''/8. It is an estimate, not a bound: a convex kink
/// and a concave peak of two elements' lobes can cancel in one second
/// difference (tests/solver/cluster_model_test.cpp measures how often).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "engine/geometry.h"

namespace flatrad {

/// Each table also has a linear part, two numbers after the samples (so a
/// table is directional_table_width doubles): the vector sum_i w_i n_i of
/// the lobes added to it. Where every member faces a direction u (the
/// cluster's normal cone, engine/normal_cone.h), the sum of lobes IS that
/// vector dotted with u, exactly: no interpolation, no kink. A curved wall
/// seen from along itself (every exchange on a round room's wall) reads
/// its exitance and sensitivity there; the samples serve the rest.
/// Arrival tables use the linear part for arrivals every member faces:
/// each element reads n . (sum of a u), exactly its cosine.
///
/// 32 directions: 0.196 rad apart; the smooth-case interpolation error of a
/// cosine lobe is h^2/8 = 0.5%, and every link with more error than its
/// share gets refined below the clusters anyway.
inline constexpr int directional_bins = 32;

/// Samples, then the linear part (x, y).
inline constexpr int directional_table_width = directional_bins + 2;

/// Where an angle falls in the table: samples k and (k + 1) mod K, weight t
/// of the second.
struct BinWeight {
    int k = 0;
    double t = 0;
    int next() const { return k + 1 == directional_bins ? 0 : k + 1; }
};

inline BinWeight bin_of(Vec2 u) {
    constexpr double step = 2 * std::numbers::pi / directional_bins;
    double phi = std::atan2(u.y, u.x);
    if (phi < 0) phi += 2 * std::numbers::pi;
    double x = phi / step;
    int k = static_cast<int>(std::floor(x));
    double t = x - k;
    if (k >= directional_bins) k -= directional_bins;  // phi rounded up to 2 pi
    if (k < 0) k = 0;
    return {k, t};
}

/// Where the opposite direction -u falls, given where u falls: half the
/// table further on, with the same weight (one atan2 per link instead of
/// two).
inline BinWeight opposite(BinWeight b) {
    static_assert(directional_bins % 2 == 0, "the opposite of a sample is a sample");
    return {(b.k + directional_bins / 2) % directional_bins, b.t};
}

/// Unit directions of the samples.
inline const std::array<Vec2, directional_bins>& bin_directions() {
    static const std::array<Vec2, directional_bins> dirs = [] {
        std::array<Vec2, directional_bins> d{};
        for (int k = 0; k < directional_bins; ++k) {
            const double phi = 2 * std::numbers::pi * k / directional_bins;
            d[static_cast<size_t>(k)] = {std::cos(phi), std::sin(phi)};
        }
        return d;
    }();
    return dirs;
}

namespace directional_detail {
// A factor of 1 at every bin (the unscaled lobes: x * 1.0 is x).
struct Unscaled {
    double operator[](int) const { return 1.0; }
};
// n . u(phi_k) from d = bin_directions() (fetched once per loop, outside
// it: a call per bin keeps the loops from vectorising), as every lobe
// function below computes it: the same rounding everywhere, so that
// lobe_bins' mask is where these are positive.
inline double cosine_at(const std::array<Vec2, directional_bins>& d, Vec2 n, int k) {
    return n.x * d[static_cast<size_t>(k)].x + n.y * d[static_cast<size_t>(k)].y;
}
template <class Scale>
inline void add_lobe(double* samples, double* linear, Vec2 n, double w, const Scale& scale) {
    if (samples) {
        const auto& d = bin_directions();
        for (int k = 0; k < directional_bins; ++k) {
            const double c = cosine_at(d, n, k);
            samples[k] += w * scale[k] * std::max(c, 0.0);
        }
    }
    linear[0] += w * n.x;
    linear[1] += w * n.y;
}
template <class Scale>
inline double read_lobe(const double* samples, const double* linear, Vec2 n, const Scale& scale) {
    double s = 0;
    if (samples) {
        const auto& d = bin_directions();
        for (int k = 0; k < directional_bins; ++k) {
            const double c = cosine_at(d, n, k);
            s += scale[k] * samples[k] * std::max(c, 0.0);
        }
    }
    return s + n.x * linear[0] + n.y * linear[1];
}
// read_lobe over the bins of `mask` alone (lobe_bins: where the cosine
// is positive), in ascending order: the terms left out are the zeros the
// others add, so the sum is the same bit for bit. (Not for add_lobe: its
// loop over every bin has no chain of sums and vectorises; masked, the
// 1000-segment forest's pulls took twice the instructions.)
template <class Scale>
inline double read_lobe_masked(const double* samples, const double* linear, Vec2 n, const Scale& scale, uint32_t mask) {
    double s = 0;
    if (samples) {
        const auto& d = bin_directions();
        for (uint32_t m = mask; m; m &= m - 1) {
            const int k = std::countr_zero(m);
            const double c = cosine_at(d, n, k);
            s += scale[k] * samples[k] * std::max(c, 0.0);
        }
    }
    return s + n.x * linear[0] + n.y * linear[1];
}
}  // namespace directional_detail

static_assert(directional_bins <= 32, "a lobe's bins fit a 32-bit mask");

/// The bins where the cosine lobe of unit normal n is positive: bit k set
/// where n . u(phi_k) > 0, computed as add_cosine_lobe and read_cosine_lobe
/// compute it. The masked read_cosine_lobe visits only these (about half
/// the table): the solver's operator reads every side's lobe once per
/// application, a chain of sums that does not vectorise.
inline uint32_t lobe_bins(Vec2 n) {
    const auto& d = bin_directions();
    uint32_t mask = 0;
    for (int k = 0; k < directional_bins; ++k) {
        const double c = directional_detail::cosine_at(d, n, k);
        if (std::max(c, 0.0) > 0) mask |= uint32_t{1} << k;
    }
    return mask;
}

/// Adds the lobe w cos+(n . u) to a table held as two arrays: to its
/// samples (w cos+(n . u(phi_k))), unless `samples` is null (a table kept
/// without samples, solver/table_array.h), and to its linear part (w n).
/// (This and read_cosine_lobe add w max(c, 0) at every bin, not only where
/// c > 0: a lobe's bins are one run of about half the table, which a branch
/// mispredicts at both ends, once per side and operator application; w * 0
/// added to a finite sum leaves it as it was. The same sums bit for bit,
/// tests/solver/cluster_model_test.cpp; on the 1000-segment forest at eps
/// 50, 5% fewer instructions in all, callgrind, one thread.)
inline void add_cosine_lobe(double* samples, double* linear, Vec2 n, double w) {
    directional_detail::add_lobe(samples, linear, n, w, directional_detail::Unscaled{});
}

/// The same with the samples' terms scaled per bin by `scale` (not null;
/// floats: the solver's per-child factors, solver/hierarchical_solver.cpp).
inline void add_cosine_lobe(double* samples, double* linear, Vec2 n, double w, const float* scale) {
    directional_detail::add_lobe(samples, linear, n, w, scale);
}

/// The same on a table of directional_table_width doubles.
inline void add_cosine_lobe(double* table, Vec2 n, double w) {
    add_cosine_lobe(table, table + directional_bins, n, w);
}

/// What an element of normal n receives from an arrival table: sum_k J_k
/// cos+(n . u(psi_k)) from the samples (none when `samples` is null), plus
/// n . (linear part).
inline double read_cosine_lobe(const double* samples, const double* linear, Vec2 n) {
    return directional_detail::read_lobe(samples, linear, n, directional_detail::Unscaled{});
}

/// The same with the samples scaled per bin by `scale` (not null).
inline double read_cosine_lobe(const double* samples, const double* linear, Vec2 n, const float* scale) {
    return directional_detail::read_lobe(samples, linear, n, scale);
}

/// read_cosine_lobe over the bins of mask = lobe_bins(n) alone: the same
/// sum, bit for bit, for finite samples.
inline double read_cosine_lobe(const double* samples, const double* linear, Vec2 n, uint32_t mask) {
    return directional_detail::read_lobe_masked(samples, linear, n, directional_detail::Unscaled{}, mask);
}
inline double read_cosine_lobe(const double* samples, const double* linear, Vec2 n, const float* scale, uint32_t mask) {
    return directional_detail::read_lobe_masked(samples, linear, n, scale, mask);
}
/// The same on a table of directional_table_width doubles.
inline double read_cosine_lobe(const double* table, Vec2 n) {
    return read_cosine_lobe(table, table + directional_bins, n);
}

/// The linear part read at unit direction u (`linear`: its two numbers).
inline double read_linear_part(const double* linear, Vec2 u) { return linear[0] * u.x + linear[1] * u.y; }

/// Adds an arrival of weight c from direction u to a linear part.
inline void add_linear_part(double* linear, Vec2 u, double c) {
    linear[0] += c * u.x;
    linear[1] += c * u.y;
}

/// The same two on a table of directional_table_width doubles.
inline double read_linear(const double* table, Vec2 u) { return read_linear_part(table + directional_bins, u); }
inline void add_linear(double* table, Vec2 u, double c) { add_linear_part(table + directional_bins, u, c); }

template <class T>
inline double interpolate(const T* table, BinWeight b) {
    return (1 - b.t) * table[b.k] + b.t * table[b.next()];
}

/// Estimated interpolation error of `table` at b (see the header).
inline double interpolation_error(const double* table, BinWeight b) {
    auto at = [&](int k) { return table[(k % directional_bins + directional_bins) % directional_bins]; };
    auto second = [&](int k) { return std::abs(at(k - 1) - 2 * at(k) + at(k + 1)); };
    return 0.5 * std::max({second(b.k - 1), second(b.k), second(b.k + 1), second(b.k + 2)});
}

}  // namespace flatrad
