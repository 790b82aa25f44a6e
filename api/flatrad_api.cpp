// The embedding API (include/flatrad/flatrad.h): a thin facade over
// engine/scene.h, solver/exact_solver.h, solver/hierarchical_solver.h and
// solver/group_form_factor.h. Engine errors are re-thrown as the API's own
// InputError so that the public header needs no internal one.
#include "flatrad/flatrad.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/error.h"
#include "engine/scene.h"
#include "solver/exact_solver.h"
#include "solver/group_form_factor.h"
#include "solver/hierarchical_solver.h"

namespace flatrad::api {

using nlohmann::ordered_json;

namespace {

std::string one_line(const std::string& file, const std::string& path, const std::string& message) {
    return path.empty() ? fmt::format("{}: {}", file, message) : fmt::format("{}: {}: {}", file, path, message);
}

/// Runs f, turning the engine's InputError into the API's.
template <class F>
auto translate_errors(F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const flatrad::InputError& e) {
        throw InputError(e.file(), e.path(), e.message());
    }
}

Side to_api(flatrad::Side s) {
    switch (s) {
        case flatrad::Side::Left: return Side::Left;
        case flatrad::Side::Right: return Side::Right;
        case flatrad::Side::Both: return Side::Both;
        case flatrad::Side::In: return Side::In;
        case flatrad::Side::Out: return Side::Out;
    }
    return Side::Left;
}

ordered_json channel_values(const std::vector<double>& v) {
    if (v.size() == 1) return v[0];
    return ordered_json(v);
}

ordered_json point_json(Point p) { return ordered_json::array({p.x, p.y}); }

ordered_json points_json(const std::vector<Point>& points) {
    ordered_json a = ordered_json::array();
    for (const Point& p : points) a.push_back(point_json(p));
    return a;
}

}  // namespace

InputError::InputError(std::string file, std::string path, std::string message)
    : std::runtime_error(one_line(file, path, message)),
      m_file(std::move(file)),
      m_path(std::move(path)),
      m_message(std::move(message)) {}

const char* side_name(Side side) {
    switch (side) {
        case Side::Left: return "left";
        case Side::Right: return "right";
        case Side::Both: return "both";
        case Side::In: return "in";
        case Side::Out: return "out";
    }
    return "unknown";
}

// ---------------------------------------------------------------- Scene

struct Scene::Impl {
    flatrad::Scene scene;
};

Scene::Scene(std::shared_ptr<const Impl> impl) : m_impl(std::move(impl)) {}

const std::string& Scene::name() const { return m_impl->scene.name; }
int Scene::channels() const { return m_impl->scene.channels; }
std::size_t Scene::patch_count() const { return m_impl->scene.patches.size(); }
std::size_t Scene::segment_count() const { return m_impl->scene.segments.size(); }

const std::vector<std::string>& Scene::warnings() const { return m_impl->scene.warnings; }

std::vector<std::string> Scene::surface_names() const {
    std::vector<std::string> names;
    names.reserve(m_impl->scene.surfaces.size());
    for (const flatrad::Surface& s : m_impl->scene.surfaces) names.push_back(s.name);
    return names;
}

namespace {
Scene wrap(flatrad::Scene scene) {
    return Scene(std::make_shared<const Scene::Impl>(Scene::Impl{std::move(scene)}));
}
}  // namespace

Scene load_scene(const std::string& path) {
    return translate_errors([&] { return wrap(flatrad::load_scene(path)); });
}

Scene parse_scene(const std::string& json_text, const std::string& label) {
    return translate_errors([&] { return wrap(flatrad::parse_scene(json_text, label)); });
}

// ---------------------------------------------------------------- SceneBuilder

struct SceneBuilder::Impl {
    std::string name, label;
    std::vector<std::string> material_names;
    ordered_json materials = ordered_json::object();
    ordered_json surfaces = ordered_json::array();

    ordered_json document() const {
        ordered_json doc;
        doc["flatrad"] = 1;
        doc["name"] = name;
        doc["materials"] = materials;
        doc["surfaces"] = surfaces;
        return doc;
    }
};

SceneBuilder::SceneBuilder(std::string name, std::string label)
    : m_impl(std::make_unique<Impl>()) {
    m_impl->name = std::move(name);
    m_impl->label = std::move(label);
}
SceneBuilder::~SceneBuilder() = default;
SceneBuilder::SceneBuilder(const SceneBuilder& o) : m_impl(std::make_unique<Impl>(*o.m_impl)) {}
SceneBuilder& SceneBuilder::operator=(const SceneBuilder& o) {
    if (this != &o) m_impl = std::make_unique<Impl>(*o.m_impl);
    return *this;
}
SceneBuilder::SceneBuilder(SceneBuilder&&) noexcept = default;
SceneBuilder& SceneBuilder::operator=(SceneBuilder&&) noexcept = default;

SceneBuilder& SceneBuilder::add_material(const std::string& name, const std::vector<double>& reflectance,
                                         const std::vector<double>& emission) {
    m_impl->material_names.push_back(name);
    ordered_json m = ordered_json::object();
    if (!reflectance.empty()) m["reflectance"] = channel_values(reflectance);
    if (!emission.empty()) m["emission"] = channel_values(emission);
    // A repeated name is refused in build(); keep the first here.
    if (!m_impl->materials.contains(name)) m_impl->materials[name] = std::move(m);
    return *this;
}

SceneBuilder& SceneBuilder::add_polyline(const std::string& name, const std::string& material,
                                         const std::vector<Point>& points, Side side) {
    m_impl->surfaces.push_back(ordered_json{{"name", name},
                                            {"material", material},
                                            {"points", points_json(points)},
                                            {"side", side_name(side)}});
    return *this;
}

SceneBuilder& SceneBuilder::add_polygon(const std::string& name, const std::string& material,
                                        const std::vector<Point>& points, Side side) {
    m_impl->surfaces.push_back(ordered_json{{"name", name},
                                            {"material", material},
                                            {"points", points_json(points)},
                                            {"closed", true},
                                            {"side", side_name(side)}});
    return *this;
}

SceneBuilder& SceneBuilder::add_circle(const std::string& name, const std::string& material, Point center,
                                       double radius, int segments, Side side) {
    m_impl->surfaces.push_back(ordered_json{
        {"name", name},
        {"material", material},
        {"circle", ordered_json{{"center", point_json(center)}, {"radius", radius}, {"segments", segments}}},
        {"side", side_name(side)}});
    return *this;
}

std::string SceneBuilder::to_json() const {
    // Non-finite numbers come out as null, which the reader refuses with
    // their path; names that are not UTF-8 are replaced rather than throwing.
    return m_impl->document().dump(2, ' ', false, ordered_json::error_handler_t::replace);
}

Scene SceneBuilder::build() const {
    const std::vector<std::string>& names = m_impl->material_names;
    for (std::size_t i = 0; i < names.size(); ++i)
        if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(i), names[i]) !=
            names.begin() + static_cast<std::ptrdiff_t>(i))
            throw InputError(m_impl->label, "materials." + names[i],
                             fmt::format("material \"{}\" is added twice", names[i]));
    return parse_scene(to_json(), m_impl->label);
}

// ---------------------------------------------------------------- solve

Result solve(const Scene& api_scene, const SolveOptions& options) {
    const flatrad::Scene& scene = api_scene.impl().scene;
    if (options.threads < 0)
        throw InputError(scene.file, "threads",
                         fmt::format("expected an integer >= 0 (0: every core), got {}", options.threads));

    Solution solution = translate_errors([&] {
        if (options.method == Method::Hierarchical) {
            if (!(std::isfinite(options.eps) && options.eps > 0))
                throw InputError(scene.file, "eps", fmt::format("expected a finite number > 0, got {}", options.eps));
            if (!std::isfinite(options.vis_eps))
                throw InputError(scene.file, "vis_eps",
                                 fmt::format("expected a finite number (< 0: eps / 10), got {}", options.vis_eps));
            HierarchicalOptions h;
            h.eps = options.eps;
            h.vis_eps = options.vis_eps;
            h.threads = options.threads;
            return solve_hierarchical(scene, h);
        }
        if (options.subdivide < 1)
            throw InputError(scene.file, "subdivide",
                             fmt::format("expected an integer >= 1, got {}", options.subdivide));
        ExactSolverOptions e;
        e.subdivide = options.subdivide;
        e.threads = options.threads;
        return solve_exact(scene, e);
    });

    Result r;
    r.method = solution.method;
    r.channels = solution.channels;
    r.patches.reserve(scene.patches.size());
    for (std::size_t p = 0; p < scene.patches.size(); ++p) {
        const Patch& patch = scene.patches[p];
        const SceneSegment& seg = scene.segments[static_cast<std::size_t>(patch.segment)];
        PatchRadiosity out;
        out.surface = scene.surfaces[static_cast<std::size_t>(patch.surface)].name;
        out.segment = seg.index;
        out.side = to_api(patch.side);
        out.a = {seg.seg.a.x, seg.seg.a.y};
        out.b = {seg.seg.b.x, seg.seg.b.y};
        out.length = patch.length;
        out.radiosity = std::move(solution.patches.at(p).radiosity);
        r.patches.push_back(std::move(out));
    }
    r.emitted = std::move(solution.totals.emitted);
    r.absorbed = std::move(solution.totals.absorbed);
    r.escaped = std::move(solution.totals.escaped);
    r.balance = std::move(solution.totals.balance);
    r.time_s = solution.stats.time_s;
    r.elements = solution.stats.elements;
    r.links = solution.stats.links;
    r.residual = solution.stats.residual;
    r.refined_to_eps = solution.stats.refined_to_eps;
    r.threads = solution.stats.threads;
    return r;
}

// ---------------------------------------------------------------- form factors

namespace {

std::vector<int> surface_group(const flatrad::Scene& scene, const std::vector<std::string>& names,
                               const char* which) {
    if (names.empty()) throw InputError(scene.file, which, "expected at least one surface name");
    std::vector<int> group;
    for (const std::string& name : names) {
        const int index = scene.find_surface(name);
        if (index < 0) throw InputError(scene.file, which, fmt::format("no surface named \"{}\"", name));
        // A group is a set: naming a surface twice must not count it twice.
        if (std::find(group.begin(), group.end(), index) == group.end()) group.push_back(index);
    }
    return group;
}

}  // namespace

double form_factor(const Scene& api_scene, const std::vector<std::string>& from,
                   const std::vector<std::string>& to, FormFactorMethod method, double eps) {
    const flatrad::Scene& scene = api_scene.impl().scene;
    const std::vector<int> a = surface_group(scene, from, "from");
    const std::vector<int> b = surface_group(scene, to, "to");
    GroupFormFactorOptions options;
    flatrad::FormFactorMethod m = flatrad::FormFactorMethod::Exact;
    if (method == FormFactorMethod::Unoccluded) m = flatrad::FormFactorMethod::Unoccluded;
    if (method == FormFactorMethod::Multiscale) {
        if (!(std::isfinite(eps) && eps >= 0))
            throw InputError(scene.file, "eps", fmt::format("expected a finite number >= 0, got {}", eps));
        m = flatrad::FormFactorMethod::Multiscale;
        options.eps = eps;
    }
    return translate_errors([&] { return group_form_factor(scene, a, b, m, options).F; });
}

const char* version() { return FLATRAD_VERSION; }

}  // namespace flatrad::api
