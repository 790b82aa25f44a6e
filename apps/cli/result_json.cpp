#include "cli/result_json.h"

#include <cstddef>

namespace flatrad {

using nlohmann::ordered_json;

namespace {

// Names from the scene passed nlohmann's UTF-8 checks when read, so
// `replace` never fires on them; it keeps a dump from throwing regardless.
std::string compact(const ordered_json& j) {
    return j.dump(-1, ' ', false, ordered_json::error_handler_t::replace);
}

ordered_json point_json(Vec2 p) { return ordered_json::array({p.x, p.y}); }

}  // namespace

ordered_json visibility_stats_json(const VisibilityStats& s) {
    ordered_json j;
    j["queries"] = s.queries;
    j["unoccluded"] = s.unoccluded;
    j["culled"] = s.culled;
    j["clusters_visited"] = s.clusters_visited;
    j["approximated"] = s.approximated;
    j["blockers"] = s.blockers;
    j["events"] = s.events;
    j["separated"] = s.separated;
    j["subshafts"] = s.subshafts;
    return j;
}

ordered_json result_json(const Scene& scene, const Solution& solution) {
    ordered_json j;
    j["flatrad"] = 1;
    j["scene"] = scene.name;
    j["method"] = solution.method;

    ordered_json settings;
    settings["subdivide"] = solution.subdivide;
    if (solution.method == "hierarchical") {
        settings["eps"] = solution.eps;
        settings["vis_eps"] = solution.vis_eps;
    }
    j["settings"] = settings;

    ordered_json patches = ordered_json::array();
    for (std::size_t p = 0; p < scene.patches.size(); ++p) {
        const Patch& patch = scene.patches[p];
        const SceneSegment& seg = scene.segments[static_cast<std::size_t>(patch.segment)];
        const PatchResult& r = solution.patches.at(p);
        ordered_json pj;
        pj["surface"] = scene.surfaces[static_cast<std::size_t>(patch.surface)].name;
        pj["segment"] = seg.index;
        pj["side"] = side_name(patch.side);
        pj["a"] = point_json(seg.seg.a);
        pj["b"] = point_json(seg.seg.b);
        pj["length"] = patch.length;
        pj["radiosity"] = r.radiosity;
        ordered_json elements = ordered_json::array();
        for (const ElementValue& e : r.elements) {
            ordered_json ej = ordered_json::array({e.t0, e.t1});
            for (double b : e.B) ej.push_back(b);
            elements.push_back(std::move(ej));
        }
        pj["elements"] = std::move(elements);
        patches.push_back(std::move(pj));
    }
    j["patches"] = std::move(patches);

    const Totals& t = solution.totals;
    j["totals"] = ordered_json{{"emitted", t.emitted},
                               {"absorbed", t.absorbed},
                               {"escaped", t.escaped},
                               {"balance", t.balance}};

    const SolveStats& s = solution.stats;
    ordered_json stats;
    stats["time_s"] = s.time_s;
    stats["elements"] = s.elements;
    stats["links"] = s.links;
    stats["iterations"] = s.iterations;
    stats["patches_left_out"] = s.patches_left_out;
    stats["cluster_links"] = s.cluster_links;
    stats["independent_parts"] = s.independent_parts;
    stats["cluster_tables"] = s.cluster_tables;
    stats["sampled_tables"] = s.sampled_tables;
    stats["residual"] = s.residual;
    stats["threads"] = s.threads;
    stats["form_factor_time_s"] = s.form_factor_time_s;
    stats["linear_solve_time_s"] = s.linear_solve_time_s;
    stats["visibility"] = visibility_stats_json(s.visibility);
    j["stats"] = std::move(stats);
    return j;
}

std::string format_result(const ordered_json& result) {
    if (!result.is_object()) return compact(result) + "\n";
    std::string text = "{\n";
    bool first = true;
    for (auto it = result.begin(); it != result.end(); ++it) {
        if (!first) text += ",\n";
        first = false;
        text += "  " + compact(ordered_json(it.key())) + ": ";
        const ordered_json& value = it.value();
        if (it.key() == "patches" && value.is_array() && !value.empty()) {
            text += "[\n";
            for (std::size_t i = 0; i < value.size(); ++i) {
                text += "    " + compact(value[i]);
                text += i + 1 < value.size() ? ",\n" : "\n";
            }
            text += "  ]";
        } else {
            text += compact(value);
        }
    }
    text += "\n}\n";
    return text;
}

}  // namespace flatrad
