#pragma once
/// `flatrad formfactor` (SPEC.md, "Command line"): the form factor between
/// two groups of surfaces, every segment of the scene an occluder, printed
/// as one JSON object.
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"

namespace flatrad {

/// Default tolerance of --method multiscale: an absolute error of 1e-3 on F.
inline constexpr double default_multiscale_eps = 1e-3;

struct FormFactorArgs {
    std::string scene;              ///< scene file
    std::string from, to;           ///< comma-separated surface names
    std::string method = "exact";   ///< "exact", "unoccluded" or "multiscale"
    std::optional<double> eps;      ///< multiscale tolerance
    std::string gamma = "bound";    ///< multiscale criterion: bound, paper or line-space
};

/// Indices of the surfaces named in `names` ("a,b,c"), in the order given,
/// each once. Throws UsageError for an empty name and InputError (file:
/// `flag`: ...) naming a surface the scene does not have.
std::vector<int> surface_group(const Scene& scene, const std::string& names, const std::string& flag);

/// Validates `args`, loads the scene, computes F and F_reverse and prints
/// {"from", "to", "method", "eps", "F", "F_reverse", "time_s",
/// "clusters_visited", "stats"} on one line to `out`.
int run_formfactor(const FormFactorArgs& args, std::ostream& out, std::ostream& err);

}  // namespace flatrad
