#pragma once
/// Form factor between two groups of surfaces (SPEC.md, `flatrad formfactor`):
/// F_AB = sum_{i in A, j in B} L_i F_ij / L_A over lit patches, every segment
/// of the scene an occluder; F_reverse the same from B to A.
#include <string>
#include <vector>

#include "engine/scene.h"
#include "visibility/multiscale.h"
#include "visibility/stats.h"

namespace flatrad {

enum class FormFactorMethod { Exact, Unoccluded, Multiscale };

struct GroupFormFactorOptions {
    double eps = 0;                      ///< multiscale tolerance on each patch pair's F
    GammaRule rule = GammaRule::Bound;   ///< multiscale criterion
};

struct GroupFormFactor {
    double F = 0;
    double F_reverse = 0;
    double time_s = 0;
    /// Multiscale: claimed bound on |F - F_exact| (F_AB is a length-weighted
    /// mean of patch-pair F_ij, so the bound is the same mean of theirs), and
    /// the same for F_reverse.
    double error_bound = 0, error_bound_reverse = 0;
    double table_seconds = 0;   ///< multiscale: time spent building cluster tables
    long tables_built = 0;
    VisibilityStats stats;
};

/// A scene's visibility structures (hierarchy, exact visibility, lazily
/// built cluster tables) kept warm across many form-factor queries, as a
/// sweep over eps needs: tables built by one query serve the next.
class FormFactorContext {
public:
    explicit FormFactorContext(const Scene& scene);
    FormFactorContext(const FormFactorContext&) = delete;
    FormFactorContext& operator=(const FormFactorContext&) = delete;

    /// `from` and `to` are surface indices (a surface may appear in both).
    /// `time_s` excludes building this context but includes any cluster
    /// table the query builds (reported in table_seconds as well).
    GroupFormFactor compute(const std::vector<int>& from, const std::vector<int>& to, FormFactorMethod method,
                            const GroupFormFactorOptions& options = {}) const;

    const Scene& scene() const { return *m_scene; }
    const ClusterTables& tables() const { return m_tables; }

private:
    const Scene* m_scene;
    Hierarchy m_hierarchy;
    ExactVisibility m_exact;
    ClusterTables m_tables;
    MultiscaleVisibility m_multiscale;
};

/// One-shot form: builds a context and computes.
GroupFormFactor group_form_factor(const Scene& scene, const std::vector<int>& from,
                                  const std::vector<int>& to, FormFactorMethod method,
                                  const GroupFormFactorOptions& options = {});

}  // namespace flatrad
