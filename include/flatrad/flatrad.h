#pragma once
/// flatrad's embedding API: the one header another program includes to build
/// or load a flatland scene, solve it and read the radiosity back.
///
/// It includes only the standard library and hides everything else (Eigen,
/// nlohmann/json, the engine's own types) behind value types and a pimpl, so
/// a program built against the installed package needs nothing but
///
///     find_package(flatrad REQUIRED)
///     target_link_libraries(app PRIVATE flatrad::api)
///
/// Words and units are the SPEC's (SPEC.md):
///  - coordinates and lengths are in scene units (any unit; radiosity is
///    power per unit length of that unit);
///  - a *material* has a reflectance in [0, 1] and an emission >= 0 per
///    channel (1 or 3 channels; one value is broadcast to every channel);
///  - a *surface* (polyline, closed polygon or circle) is cut into
///    segments; each lit side of a segment is a *patch*, and radiosity
///    lives on patches; patches are numbered in SPEC order (surface by
///    surface, segment by segment, a closed shape's closing segment last,
///    a `Both` segment's left/in patch before its right/out one);
///  - every segment blocks light, whichever side is lit; an unlit side is
///    black.
///
/// Errors: bad input (a scene the SPEC refuses, unknown names, bad options)
/// throws flatrad::api::InputError, which names the file (or the builder's
/// label) and the JSON path of the fault, exactly as the `flatrad` command
/// reports it. A failure to read a file is an InputError too. A bug in
/// flatrad itself throws std::logic_error; running out of memory throws
/// std::bad_alloc. Nothing here prints or exits.
///
/// Threads: solve() and form_factor() use OpenMP internally (SolveOptions::
/// threads). Scene and Result are immutable values, safe to read from
/// several threads; solving one Scene from several threads at once is not
/// tested.
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace flatrad::api {

/// Bad input: the scene, a name or an option. what() is the one line
/// `FILE: JSON.PATH: MESSAGE` (path left out when empty).
class InputError : public std::runtime_error {
public:
    InputError(std::string file, std::string path, std::string message);
    /// The file as given to load_scene, or the label given to
    /// SceneBuilder / parse_scene.
    const std::string& file() const noexcept { return m_file; }
    /// Where in the scene, as in `surfaces[2].points[3]` or
    /// `materials.white.reflectance`; an option's name (`subdivide`) for a
    /// bad option; may be empty.
    const std::string& path() const noexcept { return m_path; }
    /// What was expected and what was found.
    const std::string& message() const noexcept { return m_message; }

private:
    std::string m_file, m_path, m_message;
};

/// A point of the plane, in scene units.
struct Point {
    double x = 0, y = 0;
};

/// Which side of a surface is lit (SPEC, "Scene file"). An open polyline
/// takes Left, Right (of its direction of travel, point to point) or Both;
/// a closed polygon or circle takes In, Out or Both (the winding is worked
/// out from the points, so their order does not matter).
enum class Side { Left, Right, Both, In, Out };

/// "left", "right", "both", "in" or "out".
const char* side_name(Side side);

/// A validated scene. Copies are cheap (shared, immutable).
class Scene {
public:
    /// The scene's name (the file stem when the file has none).
    const std::string& name() const;
    /// 1 or 3.
    int channels() const;
    /// Number of patches (lit sides of segments), the length of
    /// Result::patches.
    std::size_t patch_count() const;
    /// Number of segments.
    std::size_t segment_count() const;
    /// Surface names in file (or builder) order.
    std::vector<std::string> surface_names() const;
    /// What the reader ignored, one line each ("PATH: unknown key, ignored",
    /// with the key likely meant when one is close, e.g. "emision"): at most
    /// ten, then a line counting the rest. Empty for a clean file.
    const std::vector<std::string>& warnings() const;

    /// Internal: Scenes come from load_scene, parse_scene and
    /// SceneBuilder::build (Impl is defined in api/flatrad_api.cpp).
    struct Impl;
    explicit Scene(std::shared_ptr<const Impl> impl);
    const Impl& impl() const { return *m_impl; }

private:
    std::shared_ptr<const Impl> m_impl;
};

/// Builds a scene in code. Each add_* call records one material or surface
/// in order (numbers that are not finite are recorded as JSON null and so
/// refused); nothing is checked until build(), which runs the very checks
/// the scene-file reader runs (the builder writes the scene-file JSON and
/// reads it back), so build() throws InputError with the JSON path a file
/// would have: `materials.NAME.reflectance`, `surfaces[K].points[I]`, with
/// K the surface's position in add order.
class SceneBuilder {
public:
    /// `name`: the scene's name (result and summaries). `label`: stands for
    /// the file name in errors.
    explicit SceneBuilder(std::string name = "scene", std::string label = "<SceneBuilder>");
    ~SceneBuilder();
    SceneBuilder(const SceneBuilder&);
    SceneBuilder& operator=(const SceneBuilder&);
    SceneBuilder(SceneBuilder&&) noexcept;
    SceneBuilder& operator=(SceneBuilder&&) noexcept;

    /// A material. `reflectance` and `emission`: 1 value (broadcast) or one
    /// per channel (every list of a scene 1 or 3 long, or
    /// broadcast); empty means 0. Reflectance in [0, 1], emission >= 0.
    /// A name used twice is refused at build().
    SceneBuilder& add_material(const std::string& name, const std::vector<double>& reflectance,
                               const std::vector<double>& emission = {});

    /// An open polyline of at least two points (segments point to point).
    /// `side`: Left, Right or Both.
    SceneBuilder& add_polyline(const std::string& name, const std::string& material,
                               const std::vector<Point>& points, Side side = Side::Left);

    /// A closed polygon of at least three points (a last point equal to the
    /// first is dropped); the closing segment is its last. `side`: In, Out
    /// (both need a simple polygon of non-zero area) or Both.
    SceneBuilder& add_polygon(const std::string& name, const std::string& material,
                              const std::vector<Point>& points, Side side);

    /// A circle cut into `segments` >= 3 segments, radius > 0, points
    /// counter-clockwise from angle 0. `side`: In, Out or Both.
    SceneBuilder& add_circle(const std::string& name, const std::string& material, Point center,
                             double radius, int segments, Side side);

    /// The scene-file JSON text (SPEC.md) of what was added so far, e.g. to
    /// save it for the `flatrad` command.
    std::string to_json() const;

    /// Validates and builds. Throws InputError on any fault the SPEC lists
    /// (and for a material name given twice). The builder is left as it was.
    Scene build() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// Reads and validates a scene file (SPEC.md, "Scene file"). Throws
/// InputError (file: `path` as given) when the file cannot be read or is
/// refused.
Scene load_scene(const std::string& path);

/// Same, from scene-file JSON text; `label` stands for the file in errors.
Scene parse_scene(const std::string& json_text, const std::string& label = "<text>");

enum class Method {
    /// The reference: every patch cut into `subdivide` equal elements, every
    /// element pair's exact occluded form factor, one dense linear system.
    /// Memory 3 (patches x subdivide)^2 x 8 bytes; more than 8 GiB is
    /// refused (InputError) before any work.
    Exact,
    /// Hierarchical radiosity (Hanrahan et al. 1991) with multi-scale
    /// visibility (Soler 1995): `eps` is the relative refinement tolerance,
    /// `vis_eps` the absolute tolerance on form factors.
    Hierarchical,
};

struct SolveOptions {
    Method method = Method::Hierarchical;
    double eps = 3e-3;     ///< Hierarchical: relative refinement tolerance, > 0 and finite (3e-3: 0.06-0.2% relative L2 error on the data scenes, 0.1: 0.4-1.2%)
    double vis_eps = -1;   ///< Hierarchical: visibility tolerance on F, >= 0; < 0: eps / 10; 0: exact visibility on every occluded link
    int subdivide = 1;     ///< Exact: elements per patch, >= 1
    int threads = 0;       ///< OpenMP threads for form factors, >= 0; 0: every core
};

/// One patch of the solution, in SPEC patch order.
struct PatchRadiosity {
    std::string surface;   ///< name of its surface
    int segment = 0;       ///< segment number within the surface (closing one last)
    Side side = Side::Left;  ///< which side of the segment: Left/Right (open), In/Out (closed)
    Point a, b;            ///< the segment's ends in file order
    double length = 0;     ///< scene units
    /// Length-weighted mean radiosity over the patch, per channel (power per
    /// unit length).
    std::vector<double> radiosity;
};

/// What solve() returns. Totals are per channel, as in the SPEC's result
/// file: emitted, absorbed (including all power reaching unlit sides) and
/// escaped (leaving an open scene) are powers (radiosity x length);
/// balance = |emitted - absorbed - escaped| / emitted (0 when nothing is
/// emitted).
struct Result {
    std::string method;                   ///< "exact" or "hierarchical"
    int channels = 1;
    std::vector<PatchRadiosity> patches;  ///< SPEC patch order, Scene::patch_count() of them
    std::vector<double> emitted, absorbed, escaped, balance;
    double time_s = 0;     ///< wall time of the solve
    long elements = 0;     ///< elements solved for
    long links = 0;        ///< non-zero element-pair form factors (interactions)
    double residual = 0;   ///< max over channels of ||(I - rho F) B - E||_inf / ||E||_inf
    /// Hierarchical: the last refinement round split no link, so every link
    /// is within eps; false when the rounds ran out first (the error may
    /// then exceed what eps promises). True for the exact method's.
    bool refined_to_eps = false;
    int threads = 1;       ///< threads used

    std::size_t patch_count() const { return patches.size(); }
};

/// Solves `scene`. Throws InputError for options out of range (path: the
/// option's name, e.g. `subdivide`), for an exact solve beyond the memory
/// limit, and for a scene without a unique solution (a closed enclosure of
/// reflectance 1 and no absorber, in some channel).
Result solve(const Scene& scene, const SolveOptions& options = {});

enum class FormFactorMethod {
    Exact,       ///< exact occluded visibility
    Unoccluded,  ///< every blocker ignored (crossed strings)
    Multiscale,  ///< clusters of blockers replaced by mean transmittance (Soler 1995), tolerance eps
};

/// The form factor from the group of surfaces `from` to the group `to`
/// (SPEC, `flatrad formfactor`): F_AB = sum over lit patches i of A and j
/// of B of L_i F_ij / L_A, every segment of the scene an occluder; a
/// name given twice counts once. Dimensionless, in [0, 1].
/// `eps` (Multiscale only, >= 0): absolute error allowed on F per
/// approximated cluster. Throws InputError for an empty group, an unknown
/// surface name (path `from` or `to`) or a bad eps.
double form_factor(const Scene& scene, const std::vector<std::string>& from,
                   const std::vector<std::string>& to, FormFactorMethod method = FormFactorMethod::Exact,
                   double eps = 1e-3);

/// The library's version, "MAJOR.MINOR.PATCH".
const char* version();

}  // namespace flatrad::api
