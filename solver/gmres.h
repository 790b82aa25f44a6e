#pragma once
/// Restarted GMRES with Givens rotations (Saad & Schultz, "GMRES: a
/// generalized minimal residual algorithm for solving nonsymmetric linear
/// systems", SIAM J. Sci. Stat. Comput. 7, 1986) for A x = b, A given only
/// as a function apply(x) -> A x: the hierarchical solver's matrix-free
/// operator (DESIGN.md §3: reflectance near 1 must not make it crawl).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace flatrad {

struct GmresOptions {
    double tolerance = 1e-12;    ///< stop at ||b - A x|| <= tolerance ||b||
    int restart = 60;            ///< Krylov basis size before a restart
    long max_applications = 2000;
};

/// Solves A x = b from the initial x; returns the number of applications of
/// A and sets rel_residual = ||b - A x|| / ||b|| (0 for b = 0, where x = 0).
/// Stops early when a whole restart cycle makes no progress (stagnation).
template <class Apply>
long gmres(const Apply& apply, const Eigen::VectorXd& b, Eigen::VectorXd& x, double& rel_residual,
           const GmresOptions& o = {}) {
    const double bnorm = b.norm();
    long apps = 0;
    if (bnorm == 0) {
        x.setZero();
        rel_residual = 0;
        return 0;
    }
    const int n = static_cast<int>(b.size());
    const int m = std::min(o.restart, n);
    Eigen::MatrixXd V(n, m + 1), H = Eigen::MatrixXd::Zero(m + 1, m);
    Eigen::VectorXd cs(m), sn(m), g(m + 1);
    Eigen::VectorXd r = b - apply(x);
    ++apps;
    double beta = r.norm();
    rel_residual = beta / bnorm;
    while (rel_residual > o.tolerance && apps < o.max_applications) {
        V.col(0) = r / beta;
        g.setZero();
        g(0) = beta;
        H.setZero();
        int k = 0;
        for (; k < m && apps < o.max_applications; ++k) {
            Eigen::VectorXd w = apply(V.col(k));
            ++apps;
            for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
                H(i, k) = w.dot(V.col(i));
                w -= H(i, k) * V.col(i);
            }
            H(k + 1, k) = w.norm();
            if (H(k + 1, k) > 0) V.col(k + 1) = w / H(k + 1, k);
            for (int i = 0; i < k; ++i) {
                const double t = cs(i) * H(i, k) + sn(i) * H(i + 1, k);
                H(i + 1, k) = -sn(i) * H(i, k) + cs(i) * H(i + 1, k);
                H(i, k) = t;
            }
            const double d = std::hypot(H(k, k), H(k + 1, k));
            cs(k) = d > 0 ? H(k, k) / d : 1;
            sn(k) = d > 0 ? H(k + 1, k) / d : 0;
            H(k, k) = d;
            H(k + 1, k) = 0;
            g(k + 1) = -sn(k) * g(k);
            g(k) = cs(k) * g(k);
            if (std::abs(g(k + 1)) <= o.tolerance * bnorm || H(k, k) == 0) {
                ++k;
                break;
            }
        }
        // Solve the small triangular system and update x.
        Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
        x += V.leftCols(k) * y;
        r = b - apply(x);
        ++apps;
        beta = r.norm();
        const double prev = rel_residual;
        rel_residual = beta / bnorm;
        if (!(rel_residual < prev)) break;  // stagnation: no progress in a whole cycle
    }
    return apps;
}

}  // namespace flatrad
