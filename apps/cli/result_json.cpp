#include "cli/result_json.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <future>
#include <string_view>
#include <vector>

namespace flatrad {

using nlohmann::ordered_json;

namespace {

// Names from the scene passed nlohmann's UTF-8 checks when read, so
// `replace` never fires on them; it keeps a dump from throwing regardless.
std::string compact(const ordered_json& j) {
    return j.dump(-1, ' ', false, ordered_json::error_handler_t::replace);
}

ordered_json point_json(Vec2 p) { return ordered_json::array({p.x, p.y}); }

// The keys before "patches" and after it.
ordered_json result_head(const Scene& scene, const Solution& solution) {
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
    return j;
}

void result_tail(ordered_json& j, const Solution& solution) {
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
    stats["chain_links"] = s.chain_links;
    stats["independent_parts"] = s.independent_parts;
    stats["cluster_tables"] = s.cluster_tables;
    stats["sampled_tables"] = s.sampled_tables;
    stats["unqueried_links"] = s.unqueried_links;
    stats["passes"] = s.passes;
    if (solution.method == "hierarchical") stats["refined_to_eps"] = s.refined_to_eps;
    stats["setups_kept"] = s.setups_kept;
    if (solution.method == "hierarchical") stats["first_round"] = s.emission_first ? "emission" : "closed_room";
    stats["residual"] = s.residual;
    stats["threads"] = s.threads;
    stats["form_factor_time_s"] = s.form_factor_time_s;
    stats["linear_solve_time_s"] = s.linear_solve_time_s;
    ordered_json phases = ordered_json::array();
    for (const Phase& ph : s.phases) phases.push_back({{"name", ph.name}, {"time_s", ph.time_s}});
    stats["phases"] = std::move(phases);
    stats["visibility"] = visibility_stats_json(s.visibility);
    j["stats"] = std::move(stats);
}

// A double as nlohmann's dump writes it (SPEC.md's numbers): shortest
// round-trip digits (std::to_chars), plain notation for decimal exponents
// -4 .. 15 with ".0" on integral values, else d.ddde+XX; null when not
// finite.
void append_number(std::string& out, double v) {
    if (!std::isfinite(v)) {
        out += "null";
        return;
    }
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
    std::string_view sci(buf, static_cast<size_t>(res.ptr - buf));
    if (sci.front() == '-') {
        out += '-';
        sci.remove_prefix(1);
    }
    const size_t e = sci.find('e');
    int exp10 = 0;
    std::from_chars(sci.data() + e + (sci[e + 1] == '+' ? 2 : 1), sci.data() + sci.size(), exp10);
    char digits[32];
    int k = 0;
    for (size_t i = 0; i < e; ++i)
        if (sci[i] != '.') digits[k++] = sci[i];
    const int n = exp10 + 1;  // the value is 0.digits x 10^n
    if (v == 0) {
        out += "0.0";
    } else if (k <= n && n <= 15) {
        out.append(digits, static_cast<size_t>(k));
        out.append(static_cast<size_t>(n - k), '0');
        out += ".0";
    } else if (0 < n && n <= 15) {
        out.append(digits, static_cast<size_t>(n));
        out += '.';
        out.append(digits + n, static_cast<size_t>(k - n));
    } else if (-4 < n && n <= 0) {
        out += "0.";
        out.append(static_cast<size_t>(-n), '0');
        out.append(digits, static_cast<size_t>(k));
    } else {
        out += digits[0];
        if (k > 1) {
            out += '.';
            out.append(digits + 1, static_cast<size_t>(k - 1));
        }
        out += 'e';
        const int x = n - 1;
        out += x < 0 ? '-' : '+';
        const int ax = std::abs(x);
        if (ax < 10) out += '0';
        out += std::to_string(ax);
    }
}

void append_array(std::string& out, const std::vector<double>& values) {
    out += '[';
    for (size_t i = 0; i < values.size(); ++i) {
        if (i > 0) out += ',';
        append_number(out, values[i]);
    }
    out += ']';
}

// [x,y], as append_array writes it, without a vector per point (two per
// patch: 2 million allocations at 10^6 patches).
void append_point(std::string& out, Vec2 p) {
    out += '[';
    append_number(out, p.x);
    out += ',';
    append_number(out, p.y);
    out += ']';
}

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
    j["bounded"] = s.bounded;
    j["opaque"] = s.opaque;
    j["banded"] = s.banded;
    j["slabs"] = s.slabs;
    j["screens"] = s.screens;
    j["screened"] = s.screened;
    j["boxed"] = s.boxed;
    return j;
}

ordered_json result_json(const Scene& scene, const Solution& solution) {
    ordered_json j = result_head(scene, solution);
    ordered_json patches = ordered_json::array();
    for (size_t p = 0; p < scene.patches.size(); ++p) {
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
    result_tail(j, solution);
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

std::string result_text(const Scene& scene, const Solution& solution) {
    const ordered_json head = result_head(scene, solution);
    ordered_json tail;
    result_tail(tail, solution);
    std::string text = "{\n";
    for (auto it = head.begin(); it != head.end(); ++it)
        text += "  " + compact(ordered_json(it.key())) + ": " + compact(it.value()) + ",\n";
    text += "  \"patches\": [";
    // The names once each, escaped as the DOM would.
    std::vector<std::string> names(scene.surfaces.size());
    for (size_t k = 0; k < names.size(); ++k) names[k] = compact(ordered_json(scene.surfaces[k].name));
    // Room for the lines of patches p0 to p1: per patch its surface's name,
    // the keys and five numbers (at most 24 bytes each) and a radiosity per
    // channel; per element two numbers and one per channel.
    const size_t channels = static_cast<size_t>(std::max(solution.channels, 1));
    auto room = [&](size_t p0, size_t p1) {
        size_t bytes = 0;
        for (size_t p = p0; p < p1; ++p) {
            const PatchResult& r = solution.patches.at(p);
            bytes += names[static_cast<size_t>(scene.patches[p].surface)].size() + 80 + 24 * (5 + channels) +
                     r.elements.size() * (8 + 24 * (2 + channels));
        }
        return bytes;
    };
    // Appends the patches' lines from patch p0 to p1 (each led by its
    // separator) to out.
    auto patch_lines = [&](size_t p0, size_t p1, std::string& out) {
        for (size_t p = p0; p < p1; ++p) {
            const Patch& patch = scene.patches[p];
            const SceneSegment& seg = scene.segments[static_cast<std::size_t>(patch.segment)];
            const PatchResult& r = solution.patches.at(p);
            out += p == 0 ? "\n    {\"surface\":" : ",\n    {\"surface\":";
            out += names[static_cast<size_t>(patch.surface)];
            out += ",\"segment\":";
            out += std::to_string(seg.index);
            out += ",\"side\":\"";
            out += side_name(patch.side);
            out += "\",\"a\":";
            append_point(out, seg.seg.a);
            out += ",\"b\":";
            append_point(out, seg.seg.b);
            out += ",\"length\":";
            append_number(out, patch.length);
            out += ",\"radiosity\":";
            append_array(out, r.radiosity);
            out += ",\"elements\":[";
            for (size_t i = 0; i < r.elements.size(); ++i) {
                const ElementValue& e = r.elements[i];
                out += i == 0 ? "[" : ",[";
                append_number(out, e.t0);
                out += ',';
                append_number(out, e.t1);
                for (double b : e.B) {
                    out += ',';
                    append_number(out, b);
                }
                out += ']';
            }
            out += "]}";
        }
    };
    // A large result in two halves, the second on another thread (each
    // number's shortest digits are most of the work), appended to the
    // first: the same text either way. The first half is written in place,
    // with room for the second, so that only the second half's pages are
    // new (fresh pages are slow to come by on some machines). A round room
    // of 10^6 walls, four alternating runs: 0.72-0.75 s against 1.06-1.10 s
    // on one thread; both halves written apart and then joined had been no
    // faster than one thread (0.71-0.76 s against 0.63-0.68 s).
    const size_t n = scene.patches.size();
    const size_t half = n >= parallel_result_patches ? n / 2 : n;  // the patches written in place
    const size_t room_first = room(0, half), room_second = room(half, n);
    text.reserve(text.size() + room_first + room_second + 4096);
    if (half < n) {
        std::future<std::string> second = std::async(std::launch::async, [&] {
            std::string out;
            out.reserve(room_second);
            patch_lines(half, n, out);
            return out;
        });
        patch_lines(0, half, text);
        text += second.get();
    } else {
        patch_lines(0, n, text);
    }
    text += scene.patches.empty() ? "]" : "\n  ]";
    for (auto it = tail.begin(); it != tail.end(); ++it)
        text += ",\n  " + compact(ordered_json(it.key())) + ": " + compact(it.value());
    text += "\n}\n";
    return text;
}

}  // namespace flatrad
