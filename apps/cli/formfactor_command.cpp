#include "cli/formfactor_command.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <ostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/result_json.h"
#include "cli/scene_warnings.h"
#include "cli/usage_error.h"
#include "engine/error.h"
#include "solver/group_form_factor.h"

namespace flatrad {

namespace {

// A short list of the scene's surface names for "no such surface" messages.
std::string some_surface_names(const Scene& scene) {
    constexpr std::size_t shown = 8;
    std::string s;
    for (std::size_t i = 0; i < std::min(shown, scene.surfaces.size()); ++i)
        s += fmt::format("{}\"{}\"", i ? ", " : "", scene.surfaces[i].name);
    if (scene.surfaces.size() > shown) s += fmt::format(", ... ({} in all)", scene.surfaces.size());
    return s;
}

}  // namespace

std::vector<int> surface_group(const Scene& scene, const std::string& names, const std::string& flag) {
    std::vector<int> group;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = names.find(',', start);
        const std::string name =
            names.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (name.empty())
            throw UsageError(fmt::format("{} \"{}\": expected surface names separated by commas, "
                                         "found an empty name",
                                         flag, names));
        const int index = scene.find_surface(name);
        if (index < 0)
            throw InputError(scene.file, flag,
                             fmt::format("no surface named \"{}\" (the scene has {})", name,
                                         some_surface_names(scene)));
        // A group is a set: naming a surface twice must not count it twice.
        if (std::find(group.begin(), group.end(), index) == group.end()) group.push_back(index);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return group;
}

int run_formfactor(const FormFactorArgs& args, std::ostream& out, std::ostream& err) {
    FormFactorMethod method;
    if (args.method == "multiscale")
        method = FormFactorMethod::Multiscale;
    else if (args.method == "exact")
        method = FormFactorMethod::Exact;
    else if (args.method == "unoccluded")
        method = FormFactorMethod::Unoccluded;
    else
        throw UsageError(fmt::format("--method {}: expected exact, unoccluded or multiscale", args.method));
    if (args.eps && !(std::isfinite(*args.eps) && *args.eps >= 0))
        throw UsageError(fmt::format("--eps: expected a finite number >= 0, got {}", *args.eps));

    const Scene scene = load_scene_reporting(args.scene, err);
    const std::vector<int> from = surface_group(scene, args.from, "--from");
    const std::vector<int> to = surface_group(scene, args.to, "--to");
    GroupFormFactorOptions options;
    options.eps = method == FormFactorMethod::Multiscale ? args.eps.value_or(default_multiscale_eps) : 0.0;
    if (const auto rule = gamma_rule_from_name(args.gamma))
        options.rule = *rule;
    else
        throw UsageError(fmt::format("--gamma {}: expected bound, bound-uniform, paper or line-space", args.gamma));
    const GroupFormFactor result = group_form_factor(scene, from, to, method, options);

    nlohmann::ordered_json j;
    j["from"] = args.from;
    j["to"] = args.to;
    j["method"] = args.method;
    j["eps"] = options.eps;  // exact and unoccluded approximate nothing, whatever --eps says
    j["F"] = result.F;
    j["F_reverse"] = result.F_reverse;
    j["time_s"] = result.time_s;
    j["clusters_visited"] = result.stats.clusters_visited;
    if (method == FormFactorMethod::Multiscale) {
        j["clusters_approximated"] = result.stats.approximated;
        j["error_bound"] = result.error_bound;
        j["error_bound_reverse"] = result.error_bound_reverse;
        j["gamma"] = gamma_rule_name(options.rule);
        j["tables_built"] = result.tables_built;
        j["table_time_s"] = result.table_seconds;
    }
    j["stats"] = visibility_stats_json(result.stats);
    out << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n'
        << std::flush;
    return 0;
}

}  // namespace flatrad
