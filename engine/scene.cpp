#include "engine/scene.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/error.h"
#include "engine/hierarchy.h"

namespace flatrad {

const char* side_name(Side s) {
    switch (s) {
        case Side::Left: return "left";
        case Side::Right: return "right";
        case Side::Both: return "both";
        case Side::In: return "in";
        case Side::Out: return "out";
    }
    return "unknown";
}

std::vector<Segment> Scene::segment_geometry() const {
    std::vector<Segment> out;
    out.reserve(segments.size());
    for (const SceneSegment& s : segments) out.push_back(s.seg);
    return out;
}

int Scene::find_surface(const std::string& surface_name) const {
    for (size_t i = 0; i < surfaces.size(); ++i)
        if (surfaces[i].name == surface_name) return static_cast<int>(i);
    return -1;
}

double scene_memory_bytes(double segments) {
    // Per segment: the segment, two patches, its point, and in the cluster
    // hierarchy a copy of the segment, its order entry and about one node.
    constexpr double per_segment = sizeof(SceneSegment) + 2 * sizeof(Patch) + sizeof(Vec2) + sizeof(Segment) +
                                   sizeof(int32_t) + sizeof(ClusterNode);
    return segments * per_segment;
}

double Scene::extent() const {
    Box box;
    for (const Surface& s : surfaces)
        for (Vec2 p : s.points) box.add(p);
    return box.diagonal();
}

namespace {

// ordered_json keeps the file's key order, so materials are numbered as written.
using Json = nlohmann::ordered_json;

/// Largest |coordinate| (and radius) accepted. geometry.h squares lengths and
/// multiplies coordinate differences without scaling; below 1e100 those stay
/// far from overflow (1e200 << 1.8e308), above it a legal-looking scene would
/// turn into infinities inside the kernels.
constexpr double max_coordinate = 1e100;

/// Largest ratio of the scene's extent (bounding-box diagonal) to its
/// shortest segment. The exact path keeps every answer to rounding up to
/// 1e16 (tests/solver/extremes_test.cpp: a 1e-8 segment beside a 1e8 one);
/// beyond about 1e17 the two sides of a sliver wedge (a 1e17-long wall
/// meeting another across a unit gap) span directions no double can tell
/// from a half turn, and small segments inside it are lost to rounding. So
/// the range is capped at 2e16, with a clear refusal.
constexpr double max_length_range = 2e16;

/// A circle's segment count is bounded so that a typo (1e9) is refused rather
/// than exhausting memory; a million segments is far finer than any solver
/// run needs.
constexpr double max_circle_segments = 1 << 20;

/// A circle's sagitta must exceed the rounding of its points this many times
/// (circle_points): a margin of 16 over the worst-case displacement.
constexpr double circle_rounding_factor = 16.0;

/// The shoelace sum of n cross products of vectors of length <= D rounds with
/// an error below about n * eps * sum|u||v| (each product rounds once, each
/// addition once). A twice-area not above this many times that bound has no
/// trustworthy sign, so the winding (and with it "in" vs "out") is unknown.
constexpr double winding_rounding_factor = 4.0;

std::string key_path(const std::string& base, std::string_view key) {
    return base.empty() ? std::string(key) : fmt::format("{}.{}", base, key);
}

std::string index_path(const std::string& base, size_t i) { return fmt::format("{}[{}]", base, i); }

std::string describe_number(double x) {
    return std::isfinite(x) ? fmt::format("{}", x) : fmt::format("{} (too large for a double)", x);
}

std::string shorten(std::string s) {
    constexpr size_t max_shown = 40;
    if (s.size() > max_shown) s = s.substr(0, max_shown - 3) + "...";
    return s;
}

/// What was found, for "expected X, found Y" messages. Short arrays of
/// scalars are shown in full (`[1, "a"]`), since that is usually the fault.
std::string describe(const Json& v, bool nested = false) {
    switch (v.type()) {
        case Json::value_t::null: return "null";
        case Json::value_t::boolean: return v.get<bool>() ? "true" : "false";
        case Json::value_t::number_integer: return fmt::format("{}", v.get<std::int64_t>());
        case Json::value_t::number_unsigned: return fmt::format("{}", v.get<std::uint64_t>());
        case Json::value_t::number_float: return describe_number(v.get<double>());
        case Json::value_t::string:
            return nested ? fmt::format("\"{}\"", shorten(v.get<std::string>()))
                          : fmt::format("the string \"{}\"", shorten(v.get<std::string>()));
        case Json::value_t::array: {
            constexpr size_t max_listed = 4;
            const bool all_scalars = std::all_of(v.begin(), v.end(), [](const Json& e) {
                return e.is_primitive();
            });
            if (nested || v.size() > max_listed || !all_scalars)
                return v.empty() ? "an empty array"
                                 : fmt::format("an array of {} item{}", v.size(), v.size() == 1 ? "" : "s");
            std::string out = "[";
            for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + describe(v[i], true);
            return out + "]";
        }
        case Json::value_t::object: return "an object";
        case Json::value_t::binary: return "binary data";
        case Json::value_t::discarded: return "nothing";
    }
    return "something unknown";
}

/// 1-based line and column of the character at 0-based `offset` in `text`.
std::pair<size_t, size_t> line_column(const std::string& text, size_t offset) {
    offset = std::min(offset, text.size());
    size_t line = 1, line_start = 0;
    for (size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    return {line, offset - line_start + 1};
}

/// nlohmann's message without its "[json.exception...] parse error at ...: "
/// prefix (we print our own position).
std::string parser_reason(const std::string& what) {
    const size_t at = what.find("parse error");
    if (at != std::string::npos) {
        const size_t colon = what.find(": ", at);
        if (colon != std::string::npos) return what.substr(colon + 2);
    }
    const size_t bracket = what.find("] ");
    return bracket == std::string::npos ? what : what.substr(bracket + 2);
}

/// Builds the DOM from nlohmann's SAX events, refusing what plain JSON
/// parsing would let through or report without a place:
///  - a key repeated in one object (nlohmann would silently keep one of them,
///    so half of what the user wrote would be ignored);
///  - a number too large for a double (nlohmann reports out_of_range 406
///    without a position).
/// Both need the JSON path of the place being parsed: one frame per open
/// object or array.
///
/// Why not Json::parse with a parser callback (which this replaces): its DOM
/// builder, at the end of every object, scans the whole enclosing container
/// for values the callback discarded. Under the "surfaces" array that is
/// one scan of the surfaces read so far per surface, O(N^2): 10^6 surfaces
/// took minutes where the plain parse takes seconds. Here every event costs
/// O(1) (amortized), plus the duplicate-key test, so the parse is linear in
/// the text.
class DomBuilder {
public:
    DomBuilder(Json& root, const std::string& file, const std::string& text)
        : m_root(root), m_file(file), m_text(text) {}

    // ---- the SAX interface (nlohmann/detail/meta/is_sax.hpp) ----
    bool null() { return value(Json(nullptr)); }
    bool boolean(bool b) { return value(Json(b)); }
    bool number_integer(Json::number_integer_t x) { return value(Json(x)); }
    bool number_unsigned(Json::number_unsigned_t x) { return value(Json(x)); }
    bool number_float(Json::number_float_t x, const Json::string_t&) { return value(Json(x)); }
    bool string(Json::string_t& s) { return value(Json(std::move(s))); }
    bool binary(Json::binary_t& b) { return value(Json::binary(std::move(b))); }

    bool start_object(std::size_t) { return open(Json(Json::value_t::object)); }
    bool start_array(std::size_t) { return open(Json(Json::value_t::array)); }
    bool end_object() { return end_container(); }
    bool end_array() { return end_container(); }

    /// A key of the innermost (open) object: refused if already there, else
    /// appended with a null value that the next event replaces.
    bool key(Json::string_t& k) {
        Frame& top = m_stack.back();
        top.key = k;  // the path names the key, repeated or not
        auto& object = top.container->get_ref<Json::object_t&>();
        if (has_key(top, object, k))
            throw InputError(m_file, current_path(),
                             fmt::format("duplicate key \"{}\": each key may appear once per object", shorten(k)));
        if (top.key_set) top.key_set->insert(k);
        // Appended directly: ordered_map's own insert would search all keys
        // again (O(k) per key, O(k^2) per object), and the key is known new.
        static_cast<Json::object_t::Container&>(object).emplace_back(std::move(k), Json());
        top.slot = &object.back().second;
        return true;
    }

    bool parse_error(std::size_t, const std::string&, const Json::parse_error& e) {
        // e.byte counts the characters read, the offending one included.
        const auto [line, column] = line_column(m_text, e.byte > 0 ? e.byte - 1 : 0);
        throw InputError(m_file, "", fmt::format("malformed JSON at line {}, column {}: {}", line, column,
                                                 parser_reason(e.what())));
    }
    bool parse_error(std::size_t, const std::string& token, const Json::out_of_range& e) {
        if (e.id != 406) throw e;
        // "number overflow parsing '1e999'": the number is the value being
        // parsed in the innermost open object or array, and `token` its text.
        throw InputError(m_file, current_path(),
                         fmt::format("expected a finite number, found {} (too large for a double)",
                                     shorten(token.empty() ? "a number" : token)));
    }
    bool parse_error(std::size_t, const std::string&, const Json::exception& e) {
        throw InputError(m_file, current_path(), parser_reason(e.what()));
    }

private:
    /// Objects with more keys than this test repeats with a hash set, built
    /// when the object reaches this size; smaller ones compare with each key.
    static constexpr size_t linear_key_search = 8;

    struct Frame {
        Json* container = nullptr;  // the open object or array, in its parent
        bool is_object = false;
        std::string key;            // object: key of the value being parsed
        Json* slot = nullptr;       // object: where that value goes
        size_t index = 0;           // array: index of the value being parsed
        std::unique_ptr<std::unordered_set<std::string>> key_set;  // object: keys, once many
    };

    bool has_key(Frame& top, const Json::object_t& object, const std::string& k) {
        if (top.key_set) return top.key_set->count(k) > 0;
        if (object.size() < linear_key_search)
            return std::any_of(object.begin(), object.end(), [&k](const auto& item) { return item.first == k; });
        top.key_set = std::make_unique<std::unordered_set<std::string>>();
        for (const auto& item : object) top.key_set->insert(item.first);
        return top.key_set->count(k) > 0;
    }

    /// Puts a new value where the innermost open container expects it
    /// (the slot of the last key, or the end of the array; the root if none)
    /// and returns where it now lives. That address stays valid while the
    /// value is open: its parent grows only after it is complete.
    Json* place(Json&& v) {
        if (m_stack.empty()) {
            m_root = std::move(v);
            return &m_root;
        }
        Frame& top = m_stack.back();
        if (top.is_object) {
            *top.slot = std::move(v);
            return top.slot;
        }
        auto& array = top.container->get_ref<Json::array_t&>();
        array.push_back(std::move(v));
        return &array.back();
    }

    bool open(Json&& container) {
        Frame f;
        f.is_object = container.is_object();
        f.container = place(std::move(container));
        m_stack.push_back(std::move(f));
        return true;
    }

    bool value(Json&& v) {
        place(std::move(v));
        value_done();
        return true;
    }

    bool end_container() {
        m_stack.pop_back();
        value_done();
        return true;
    }

    /// The value at the top is complete: an array moves on to its next index.
    void value_done() {
        if (!m_stack.empty() && !m_stack.back().is_object) ++m_stack.back().index;
    }

    std::string current_path() const {
        std::string path;
        for (const Frame& f : m_stack) path = f.is_object ? key_path(path, f.key) : index_path(path, f.index);
        return path;
    }

    Json& m_root;
    const std::string& m_file;
    const std::string& m_text;
    std::vector<Frame> m_stack;
};

/// Parses the text into a DOM (DomBuilder), or throws InputError.
Json parse_json(const std::string& text, const std::string& file) {
    Json root;
    DomBuilder builder(root, file, text);
    Json::sax_parse(text, &builder);
    return root;
}

// ---- overlapping segments ---------------------------------------------------

/// Largest |coordinate| of a segment's endpoints.
double magnitude(const Segment& g) {
    return std::max({std::abs(g.a.x), std::abs(g.a.y), std::abs(g.b.x), std::abs(g.b.y)});
}

/// Points off a line by a few ulps of the coordinates are on it; a sliver
/// 3 wide at 1e15 (24 ulps) is real geometry and is kept.
constexpr double overlap_rounding = 4 * std::numeric_limits<double>::epsilon();

/// The refusal rule for one ordered pair, g before h in SPEC order: h lies
/// on g's line (both ends within rounding of it) and overlaps g over more
/// than rounding. Returns the overlap length, or nothing. Only g's line is
/// tested (the rule is not symmetric at the level of rounding), so callers
/// pass the earlier segment first.
std::optional<double> lies_on(const Segment& g, const Segment& h) {
    const double L = g.length();
    const double tol =
        overlap_rounding * (std::max(magnitude(g), magnitude(h)) + std::max(L, h.length()));
    // On g's line (distance within rounding) ...
    if (std::abs(orient(g.a, g.b, h.a)) > tol * L || std::abs(orient(g.a, g.b, h.b)) > tol * L) return {};
    // ... and overlapping it over more than rounding.
    const Vec2 d = (g.b - g.a) / L;
    const double u0 = dot(h.a - g.a, d), u1 = dot(h.b - g.a, d);
    const double overlap = std::min(L, std::max(u0, u1)) - std::max(0.0, std::min(u0, u1));
    if (overlap <= tol) return {};
    return overlap;
}

/// Finds the first segment s (in SPEC order) on which some later segment t
/// lies (lies_on(s, t)), in O(N log N) for any arrangement that is not
/// itself within a few ulps of such an overlap.
///
/// A bounding-box search (every segment against the boxes it touches) is
/// quadratic for long slanted segments: the boxes of a venetian blind of
/// parallel diagonal slats, or of a fan of rays, all overlap one another.
/// What lies_on needs is much narrower, and that is what is searched:
///
///  1. Bounds. Let T = 4 eps (largest |coordinate| + longest segment): no
///     pair's tolerance exceeds it. Allowing for the rounding of orient and
///     dot (about 3 eps |u| |v| and 6 eps |v|, |v| <= 2.9 x largest
///     |coordinate|), lies_on(s, t) implies, exactly:
///      - both ends of t within 3.3 T of s's line, so the two directions
///        differ by at most asin(6.5 T / |t|) (undirected, modulo a half
///        turn); window() bounds that, from above, for either length;
///      - some point of t within 5.5 T of segment s.
///  2. Directions. Segments are put in length classes (floor(log2 length):
///     at most 56, since lengths span less than 2e16) and, within a class,
///     sorted by direction in [0, pi) and cut into groups spanning at most
///     4 T / 2^class radians. In a frame turned to its group's mean
///     direction every member is within 4 T of horizontal end to end: the
///     group is a set of thin, nearly horizontal segments there, held in a
///     cluster hierarchy (engine/hierarchy.h) when it has more than a few.
///  3. Queries. For s, in SPEC order, each class is searched over the
///     directions within max(window(|s|), window(2^class)) of s's (binary
///     search over the groups' direction ranges, wrapping at pi), and each
///     group found over the box of s, turned into the group's frame and
///     padded by 16 T (5.5 T plus the rounding of both turns). Every t > s
///     found there is tested with lies_on itself. The first s with a hit ends
///     the search.
///
/// Nothing that lies_on would refuse is left out: each filter is implied by
/// it, with margins above the rounding. Parallel families (walls of a
/// Manhattan scene, slats, collinear chains) are separated by the hierarchy
/// of their group, different directions by the direction search. What is
/// searched in vain: pairs within about 16 T of lying on each other, and,
/// for a segment much longer than a class, that class's segments within its
/// window of parallel and within (its length x that window) of its line.
/// Only near-degenerate scenes have those in numbers.
class OverlapFinder {
public:
    explicit OverlapFinder(const std::vector<Segment>& segments) : m_segments(segments) {
        const size_t n = segments.size();
        double largest = 0, longest = 0;
        m_length.resize(n);
        m_angle.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const Segment& g = segments[i];
            m_length[i] = g.length();
            largest = std::max(largest, magnitude(g));
            longest = std::max(longest, m_length[i]);
            // Undirected direction in [0, pi).
            double angle = std::atan2(g.b.y - g.a.y, g.b.x - g.a.x);
            if (angle < 0) angle += std::numbers::pi;
            if (angle >= std::numbers::pi) angle -= std::numbers::pi;
            m_angle[i] = angle;
        }
        m_T = overlap_rounding * (largest + longest);
        build();
    }

    /// The first s (SPEC order) with a later t that lies on it, and the
    /// first such t; nothing if no segment lies on another.
    ///
    /// The segments in blocks, on every thread: each block stops at its
    /// first s with a partner, and a block is skipped once a block before
    /// it has one; the lowest block with one holds the answer, the same as
    /// one thread's search in order (a 10^6-segment forest: 2.3 s of its
    /// 8 s load on one thread).
    std::optional<std::pair<size_t, size_t>> first() const {
        const size_t n = m_segments.size();
        constexpr size_t block = 4096;
        const long blocks = static_cast<long>((n + block - 1) / block);
        std::vector<std::pair<size_t, size_t>> found(static_cast<size_t>(blocks), {n, n});
        std::atomic<long> lowest{blocks};  // the lowest block known to hold an s with a partner
#pragma omp parallel if (blocks > 1)
        {
            std::vector<int32_t> stack;
#pragma omp for schedule(dynamic, 1)
            for (long b = 0; b < blocks; ++b) {
                if (b > lowest.load(std::memory_order_relaxed)) continue;
                const size_t end = std::min(n, static_cast<size_t>(b + 1) * block);
                for (size_t s = static_cast<size_t>(b) * block; s < end; ++s) {
                    size_t partner = n;
                    visit_candidates(s, stack, [&](size_t t) {
                        if (t > s && t < partner && lies_on(m_segments[s], m_segments[t])) partner = t;
                    });
                    if (partner < n) {
                        found[static_cast<size_t>(b)] = {s, partner};
                        long seen = lowest.load();
                        while (b < seen && !lowest.compare_exchange_weak(seen, b)) {
                        }
                        break;
                    }
                }
            }
        }
        for (const auto& f : found)
            if (f.first < n) return f;
        return std::nullopt;
    }

private:
    /// Marks a direction window that takes in every direction.
    static constexpr double any_direction = std::numbers::pi / 2;

    struct Group {
        double angle_lo = 0, angle_hi = 0;  // members' directions (sorted)
        double cos = 1, sin = 0;            // the frame: turned by -(mean direction)
        size_t begin = 0, end = 0;          // members are m_members[begin, end)
        int tree = -1;                      // index into m_trees, or -1: scan the members
    };
    struct Class {
        double window = 0;  // window() of the class's shortest possible length
        size_t begin = 0, end = 0;  // its groups, m_groups[begin, end), by direction
    };

    /// Upper bound on how far the direction of a segment of this length may
    /// be from that of a segment it lies on or that lies on it (step 1):
    /// asin(z) <= 1.05 z for z <= 0.5, plus the rounding of atan2.
    double window(double length) const {
        const double z = 8 * m_T / length;
        return z >= 0.5 ? any_direction : 1.2 * z + 16 * std::numeric_limits<double>::epsilon();
    }

    static Vec2 turn(Vec2 p, const Group& g) { return {g.cos * p.x + g.sin * p.y, g.cos * p.y - g.sin * p.x}; }

    void build() {
        const size_t n = m_segments.size();
        std::vector<int> cls(n);
        for (size_t i = 0; i < n; ++i) cls[i] = std::ilogb(m_length[i]);
        std::vector<int32_t> order(n);
        for (size_t i = 0; i < n; ++i) order[i] = static_cast<int32_t>(i);
        std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
            return cls[a] != cls[b] ? cls[a] < cls[b] : m_angle[a] < m_angle[b];
        });
        m_members = order;
        m_turned.resize(n);
        m_boxes.resize(n);

        for (size_t first = 0; first < n;) {
            const int c = cls[static_cast<size_t>(order[first])];
            size_t last = first;
            while (last < n && cls[static_cast<size_t>(order[last])] == c) ++last;
            const double shortest = std::ldexp(1.0, c);
            Class k;
            k.window = window(shortest);
            k.begin = m_groups.size();
            // Group width: members (shorter than 2 shortest) then stay within
            // 4 T of their group's axis. A class whose window takes in every
            // direction is one group, unturned: its segments are a few T long.
            const double width = k.window >= any_direction ? std::numbers::pi : 4 * m_T / shortest;
            for (size_t g = first; g < last;) {
                Group group;
                group.begin = g;
                group.angle_lo = m_angle[static_cast<size_t>(order[g])];
                size_t e = g;
                while (e < last && m_angle[static_cast<size_t>(order[e])] - group.angle_lo <= width) ++e;
                group.end = e;
                group.angle_hi = m_angle[static_cast<size_t>(order[e - 1])];
                if (width < std::numbers::pi) {
                    const double axis = 0.5 * (group.angle_lo + group.angle_hi);
                    group.cos = std::cos(axis);
                    group.sin = std::sin(axis);
                }
                for (size_t m = g; m < e; ++m) {
                    const Segment& s = m_segments[static_cast<size_t>(order[m])];
                    m_turned[m] = {turn(s.a, group), turn(s.b, group)};
                    m_boxes[m] = Box{};
                    m_boxes[m].add(m_turned[m]);
                }
                if (e - g > linear_group) {
                    m_trees.emplace_back(
                        std::vector<Segment>(m_turned.begin() + static_cast<std::ptrdiff_t>(g),
                                             m_turned.begin() + static_cast<std::ptrdiff_t>(e)),
                        2);
                    group.tree = static_cast<int>(m_trees.size() - 1);
                }
                m_groups.push_back(group);
                g = e;
            }
            k.end = m_groups.size();
            m_classes.push_back(k);
            first = last;
        }
    }

    /// Calls on_candidate(t) for every segment t that the bounds of step 1
    /// do not rule out as lying on s or s on it (s itself among them).
    template <class OnCandidate>
    void visit_candidates(size_t s, std::vector<int32_t>& stack, OnCandidate&& on_candidate) const {
        const double angle = m_angle[s], own = window(m_length[s]);
        for (const Class& k : m_classes) {
            const double w = std::max(own, k.window);
            const auto range = [&](double lo, double hi) { visit_range(k, lo, hi, s, stack, on_candidate); };
            if (w >= any_direction) {
                range(-1.0, 4.0);
            } else if (angle - w < 0) {  // the window wraps around 0 = pi
                range(angle - w + std::numbers::pi, 4.0);
                range(-1.0, angle + w);
            } else if (angle + w >= std::numbers::pi) {
                range(angle - w, 4.0);
                range(-1.0, angle + w - std::numbers::pi);
            } else {
                range(angle - w, angle + w);
            }
        }
    }

    /// The groups of class k with a member direction in [lo, hi].
    template <class OnCandidate>
    void visit_range(const Class& k, double lo, double hi, size_t s, std::vector<int32_t>& stack,
                     OnCandidate&& on_candidate) const {
        const auto begin = m_groups.begin() + static_cast<std::ptrdiff_t>(k.begin);
        const auto end = m_groups.begin() + static_cast<std::ptrdiff_t>(k.end);
        // Groups partition the class's sorted directions, so angle_hi grows too.
        auto it = std::partition_point(begin, end, [lo](const Group& g) { return g.angle_hi < lo; });
        for (; it != end && it->angle_lo <= hi; ++it) visit_group(*it, s, stack, on_candidate);
    }

    template <class OnCandidate>
    void visit_group(const Group& group, size_t s, std::vector<int32_t>& stack, OnCandidate&& on_candidate) const {
        const Segment& g = m_segments[s];
        Box box;
        box.add(turn(g.a, group));
        box.add(turn(g.b, group));
        const double pad = 16 * m_T;
        box.lo -= Vec2{pad, pad};
        box.hi += Vec2{pad, pad};
        const auto meets = [&box](const Box& b) {
            return !(b.hi.x < box.lo.x || b.lo.x > box.hi.x || b.hi.y < box.lo.y || b.lo.y > box.hi.y);
        };
        if (group.tree < 0) {
            for (size_t m = group.begin; m < group.end; ++m)
                if (meets(m_boxes[m])) on_candidate(static_cast<size_t>(m_members[m]));
            return;
        }
        m_trees[static_cast<size_t>(group.tree)].query(
            meets,
            [&](int k, const Segment&) {
                const size_t m = group.begin + static_cast<size_t>(k);
                if (meets(m_boxes[m])) on_candidate(static_cast<size_t>(m_members[m]));
            },
            stack);
    }

    /// Groups up to this size are scanned rather than given a hierarchy.
    static constexpr size_t linear_group = 8;

    const std::vector<Segment>& m_segments;
    std::vector<double> m_length, m_angle;
    double m_T = 0;
    std::vector<int32_t> m_members;   // segment numbers by class, then direction
    std::vector<Segment> m_turned;    // m_members' segments in their group's frame
    std::vector<Box> m_boxes;         // and their boxes there
    std::vector<Group> m_groups;      // by class, then direction
    std::vector<Class> m_classes;     // by length
    std::vector<Hierarchy> m_trees;
};

// ---- simple polygons ---------------------------------------------------------

/// Thrown inside the sweep below when a test cannot be decided with margin
/// (or finds the polygon not simple): the sweep gives up, and the all-pairs
/// test decides.
struct SweepUndecided {};

/// Sign of orient(a, b, c) when rounding cannot have changed it, else 0.
/// orient's error is below about 3.1 eps |b - a| |c - a| (the differences
/// round, then cross rounds once); the margin here is five times that.
int clear_sign(Vec2 a, Vec2 b, Vec2 c) {
    const Vec2 u = b - a, v = c - a;
    const double o = cross(u, v);
    const double bound = 16 * std::numeric_limits<double>::epsilon() * (std::abs(u.x) + std::abs(u.y)) *
                         (std::abs(v.x) + std::abs(v.y));
    return o > bound ? 1 : o < -bound ? -1 : 0;
}

/// Shamos-Hoey sweep over the edges of a closed polygon (points q): edges
/// enter the status (ordered bottom to top at the sweep line) at their
/// lexicographically smaller end and leave at the other; each edge is tested
/// against its neighbours whenever it gets new ones. Non-neighbouring edges
/// that cross are neighbours in the status just before the leftmost crossing,
/// so that one is found; every order and crossing decision is a clear_sign,
/// so with exact arithmetic the same decisions would be made. Besides, each
/// vertex must lie at least `clearance` from the lines of the edges just
/// above and below it in the status. Throws SweepUndecided otherwise.
/// O(n log n).
class PolygonSweep {
public:
    PolygonSweep(const std::vector<Vec2>& q, double clearance)
        : m_q(q), m_n(q.size()), m_clearance(clearance), m_status(Order{this}) {}

    void run() {
        std::vector<size_t> events(m_n);
        for (size_t k = 0; k < m_n; ++k) events[k] = k;
        std::sort(events.begin(), events.end(), [this](size_t a, size_t b) { return before(m_q[a], m_q[b]); });
        m_where.assign(m_n, m_status.end());
        for (const size_t k : events) {
            const Vec2 v = m_q[k];
            const size_t incident[2] = {(k + m_n - 1) % m_n, k};
            // Edges ending at v leave; their neighbours meet.
            for (const size_t e : incident) {
                if (!before(other_end(e, k), v)) continue;
                auto it = m_where[e];
                auto next = std::next(it);
                const bool has_below = it != m_status.begin(), has_above = next != m_status.end();
                const size_t below = has_below ? *std::prev(it) : 0, above = has_above ? *next : 0;
                m_status.erase(it);
                if (has_below && has_above) test(below, above);
            }
            // v clear of the edges just below and above it (none is incident).
            m_point = v;
            const auto it = m_status.lower_bound(PointKey{});
            if (it != m_status.end()) require_clearance(*it, v);
            if (it != m_status.begin()) require_clearance(*std::prev(it), v);
            // Edges starting at v enter; each meets its new neighbours.
            for (const size_t e : incident) {
                if (before(other_end(e, k), v)) continue;
                m_inserting = e;
                const auto placed = m_status.insert(e).first;
                m_inserting = none;
                m_where[e] = placed;
                if (placed != m_status.begin()) test(*std::prev(placed), e);
                if (std::next(placed) != m_status.end()) test(e, *std::next(placed));
            }
        }
    }

private:
    static constexpr size_t none = std::numeric_limits<size_t>::max();
    struct PointKey {};  // stands for m_point in status searches

    /// The sweep order on points: by x, then y.
    static bool before(Vec2 a, Vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

    Vec2 start(size_t e) const { return m_q[e]; }
    Vec2 end(size_t e) const { return m_q[(e + 1) % m_n]; }
    Vec2 other_end(size_t e, size_t vertex) const { return e == vertex ? end(e) : start(e); }
    Vec2 lo(size_t e) const { return before(start(e), end(e)) ? start(e) : end(e); }
    Vec2 hi(size_t e) const { return before(start(e), end(e)) ? end(e) : start(e); }

    /// +1 when edge x (entering at m_point) goes above edge y (in the status), -1 below.
    int side(size_t x, size_t y) const {
        // Two edges entering at one vertex: the one whose far end is above the other.
        const int s = lo(y) == lo(x) ? clear_sign(lo(y), hi(y), hi(x)) : clear_sign(lo(y), hi(y), lo(x));
        if (s == 0) throw SweepUndecided{};  // touching, folded, or too close to tell
        return s;
    }

    struct Order {
        using is_transparent = void;
        const PolygonSweep* sweep;
        bool operator()(size_t a, size_t b) const {
            if (a == sweep->m_inserting && b != a) return sweep->side(a, b) < 0;
            if (b == sweep->m_inserting && a != b) return sweep->side(b, a) > 0;
            throw SweepUndecided{};  // only the entering edge is ever compared
        }
        // Edge e below the point / the point below edge e.
        bool operator()(size_t e, PointKey) const { return sweep->point_side(e) > 0; }
        bool operator()(PointKey, size_t e) const { return sweep->point_side(e) < 0; }
    };

    int point_side(size_t e) const {
        const int s = clear_sign(lo(e), hi(e), m_point);
        if (s == 0) throw SweepUndecided{};
        return s;
    }

    void require_clearance(size_t e, Vec2 v) const {
        const Vec2 a = lo(e), b = hi(e);
        const double margin = m_clearance * norm(b - a) * (1 + 1e-6);
        const Vec2 u = b - a, w = v - a;
        const double bound = 16 * std::numeric_limits<double>::epsilon() * (std::abs(u.x) + std::abs(u.y)) *
                             (std::abs(w.x) + std::abs(w.y));
        if (!(std::abs(cross(u, w)) > margin + bound)) throw SweepUndecided{};
    }

    /// Edges i and j have just become neighbours in the status.
    void test(size_t i, size_t j) const {
        if ((i + 1) % m_n == j || (j + 1) % m_n == i) {
            // Polygon neighbours u -> v -> w share v; they must not fold back
            // onto each other along one line: w clearly off the line u v, or
            // clearly on the far side of v (a straight continuation).
            const size_t first = (i + 1) % m_n == j ? i : j, second = first == i ? j : i;
            const Vec2 u = start(first), v = end(first), w = end(second);
            if (clear_sign(u, v, w) != 0) return;
            const Vec2 a = u - v, b = w - v;
            const double bound = 16 * std::numeric_limits<double>::epsilon() * (std::abs(a.x) + std::abs(a.y)) *
                                 (std::abs(b.x) + std::abs(b.y));
            if (!(dot(a, b) < -bound)) throw SweepUndecided{};
            return;
        }
        // Disjoint when one edge is clearly on one side of the other's line
        // (an end may be on that line, outside the edge: collinear pieces of
        // one wall); crossing when each clearly straddles the other's line.
        const int o1 = clear_sign(start(i), end(i), start(j)), o2 = clear_sign(start(i), end(i), end(j));
        const int o3 = clear_sign(start(j), end(j), start(i)), o4 = clear_sign(start(j), end(j), end(i));
        if ((o1 != 0 && o1 == o2) || (o3 != 0 && o3 == o4)) return;
        throw SweepUndecided{};  // they cross, touch, or come too close to tell
    }

    const std::vector<Vec2>& m_q;
    const size_t m_n;
    const double m_clearance;
    std::set<size_t, Order> m_status;
    std::vector<std::set<size_t, Order>::iterator> m_where;  // each edge's place in the status
    size_t m_inserting = none;
    Vec2 m_point;
};

/// True when the closed polygon p certainly passes the all-pairs test of
/// SceneReader::check_simple (no pair of edges it would find meeting, with
/// its own rounding); false when that cannot be shown quickly, and the
/// all-pairs test must decide. O(n log n).
///
/// That test works in floating point, so besides pairs that meet it may
/// refuse pairs that come within rounding of meeting: roughly, a vertex
/// within r = 9 eps x (largest |coordinate|) of the line of an edge it is
/// not on, inside that edge's box, or two edges nearly on one line. Such a
/// vertex lies within a few r of the edge itself, or of one of its ends.
/// So the polygon is accepted here when, with R = 256 eps x largest
/// |coordinate| (about 28 r):
///  - no two vertices are within R of each other (a grid of cells of side
///    R, sorted, each vertex against its 3 x 3 cells);
///  - a PolygonSweep in x, and another with the polygon turned a quarter
///    turn, finish: no crossing, no folding, and every vertex further than
///    R from the lines of the edges just above and below it. An edge within
///    a few r of a vertex, and spanning it in the sweep direction in which
///    the edge is the flatter (slope at most 1), lies within 1.5 x that
///    distance vertically of it; the edge just above or below the vertex is
///    at least that near, so it would have been refused. (If it does not
///    span the vertex, the vertex is within a few r of one of its ends.)
/// Far below 1e-100 the sweep's products could underflow: no answer there.
bool polygon_clearly_simple(const std::vector<Vec2>& p) {
    double largest = 0;
    for (const Vec2 q : p) largest = std::max({largest, std::abs(q.x), std::abs(q.y)});
    if (!(largest >= 1e-100)) return false;
    const double clearance = 256 * std::numeric_limits<double>::epsilon() * largest;

    // Vertices apart: cell indices stay below 2^45 (|x| / clearance).
    struct Cell {
        std::int64_t x, y;
        size_t vertex;
        bool operator<(const Cell& o) const { return x != o.x ? x < o.x : y < o.y; }
    };
    std::vector<Cell> cells;
    cells.reserve(p.size());
    for (size_t k = 0; k < p.size(); ++k)
        cells.push_back({static_cast<std::int64_t>(std::floor(p[k].x / clearance)),
                         static_cast<std::int64_t>(std::floor(p[k].y / clearance)), k});
    std::sort(cells.begin(), cells.end());
    for (const Cell& c : cells)
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy) {
                const auto [from, to] = std::equal_range(cells.begin(), cells.end(), Cell{c.x + dx, c.y + dy, 0});
                for (auto it = from; it != to; ++it)
                    if (it->vertex != c.vertex && !(distance(p[it->vertex], p[c.vertex]) > clearance)) return false;
            }

    std::vector<Vec2> turned(p.size());
    for (size_t k = 0; k < p.size(); ++k) turned[k] = {p[k].y, -p[k].x};  // exact, keeps orientation
    try {
        PolygonSweep(p, clearance).run();
        PolygonSweep(turned, clearance).run();
    } catch (const SweepUndecided&) {
        return false;
    }
    return true;
}

/// Which range a channel value must lie in.
enum class ChannelKind { Reflectance, Emission };

/// Reads a parsed document into a Scene, or throws InputError at the first
/// fault in file order. Nothing is kept from a document that fails.
class SceneReader {
public:
    explicit SceneReader(const std::string& file) : m_file(file) {}

    Scene read(const Json& root) {
        Scene scene;
        scene.file = m_file;
        if (!root.is_object())
            fail("", fmt::format("expected a JSON object {{\"flatrad\": 1, \"materials\": ..., \"surfaces\": ...}}, "
                                 "found {}",
                                 describe(root)));

        const Json& version = require(root, "flatrad", "");
        if (!version.is_number() || version.get<double>() != 1.0)
            fail("flatrad", fmt::format("expected the format version 1, found {}", describe(version)));

        if (const Json* name = optional(root, "name")) {
            if (!name->is_string()) fail("name", fmt::format("expected a string, found {}", describe(*name)));
            scene.name = name->get<std::string>();
        } else {
            scene.name = std::filesystem::path(m_file).stem().string();
        }

        if (const Json* description = optional(root, "description"); description && !description->is_string())
            fail("description", fmt::format("expected a string (free text), found {}", describe(*description)));
        note_unknown_keys(root, {"flatrad", "name", "description", "materials", "surfaces"}, "");
        read_materials(require(root, "materials", ""), scene);
        read_surfaces(require(root, "surfaces", ""), scene);
        check_no_overlaps(scene);
        scene.warnings = std::move(m_warnings);
        if (m_unknown_keys > max_scene_warnings) {
            const size_t more = m_unknown_keys - max_scene_warnings;
            scene.warnings.push_back(fmt::format("and {} more unknown key{}, ignored", more, more == 1 ? "" : "s"));
        }
        return scene;
    }

private:
    [[noreturn]] void fail(const std::string& path, const std::string& message) const {
        throw InputError(m_file, path, message);
    }

    /// Records the keys of `object` (at `path`) that are not among `known`
    /// (Scene::warnings): they are ignored, as the format allows, but said.
    void note_unknown_keys(const Json& object, std::initializer_list<std::string_view> known,
                           const std::string& path) const {
        if (!object.is_object()) return;
        for (const auto& item : object.items()) {
            const std::string& key = item.key();
            if (std::find(known.begin(), known.end(), key) != known.end()) continue;
            if (++m_unknown_keys > max_scene_warnings) continue;
            std::string line = fmt::format("{}: unknown key, ignored", key_path(path, printable_key(key)));
            if (const auto meant = likely_meant(key, known)) line += fmt::format(" (did you mean \"{}\"?)", *meant);
            m_warnings.push_back(std::move(line));
        }
    }

    /// The known key nearest to `key` when it is within max_edits of it
    /// (insertions, deletions, substitutions; letters compared without case),
    /// the first in `known`'s order on ties.
    static std::optional<std::string_view> likely_meant(const std::string& key,
                                                        std::initializer_list<std::string_view> known) {
        std::optional<std::string_view> best;
        size_t best_edits = std::numeric_limits<size_t>::max();
        for (std::string_view k : known) {
            const size_t d = edit_distance(key, k, max_edits(k) + 1);
            if (d <= max_edits(k) && d < best_edits) {
                best_edits = d;
                best = k;
            }
        }
        return best;
    }

    /// How far a misspelling of `key` may be: one edit for keys of four
    /// letters or fewer ("note" is not "name"), two for longer ones.
    static size_t max_edits(std::string_view key) { return key.size() <= 4 ? 1 : 2; }

    /// A key as it may be shown in one line: control characters escaped
    /// (\n, \u001b, ...: a key must not start a line of its own), then
    /// shortened as other echoed text is.
    static std::string printable_key(std::string_view key) {
        std::string out;
        for (const char c : key) {
            const auto u = static_cast<unsigned char>(c);
            if (u < 0x20 || u == 0x7f)
                out += c == '\n' ? std::string("\\n") : c == '\t' ? std::string("\\t") : fmt::format("\\u{:04x}", u);
            else
                out += c;
        }
        return shorten(std::move(out));
    }

    /// Levenshtein distance between a and b, or `cap` when it is at least
    /// that (one row of the table; keys are short).
    static size_t edit_distance(std::string_view a, std::string_view b, size_t cap) {
        if ((a.size() > b.size() ? a.size() - b.size() : b.size() - a.size()) >= cap) return cap;
        auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
        std::vector<size_t> row(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            size_t diagonal = row[0];
            row[0] = i;
            for (size_t j = 1; j <= b.size(); ++j) {
                const size_t above = row[j];
                row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1)});
                diagonal = above;
            }
        }
        return std::min(row[b.size()], cap);
    }

    const Json& require(const Json& object, const char* key, const std::string& object_path) const {
        const auto it = object.find(key);
        if (it == object.end()) fail(key_path(object_path, key), "missing required key" + misspelt_hint(object, {key}));
        return *it;
    }

    /// " (found \"KEY\": misspelt?)" for the first key of `object` that
    /// likely_meant takes for one of the missing `keys`, else "": a misspelt
    /// required key is then named where the error is.
    static std::string misspelt_hint(const Json& object, std::initializer_list<std::string_view> keys) {
        if (!object.is_object()) return "";
        for (const auto& item : object.items())
            if (std::find(keys.begin(), keys.end(), item.key()) == keys.end() && likely_meant(item.key(), keys))
                return fmt::format(" (found \"{}\": misspelt?)", printable_key(item.key()));
        return "";
    }

    static const Json* optional(const Json& object, const char* key) {
        const auto it = object.find(key);
        return it == object.end() ? nullptr : &*it;
    }

    double finite_number(const Json& v, const std::string& path, std::string_view expected) const {
        if (!v.is_number() || !std::isfinite(v.get<double>()))
            fail(path, fmt::format("expected {}, found {}", expected, describe(v)));
        return v.get<double>();
    }

    // ---- materials -------------------------------------------------------

    void read_materials(const Json& materials, Scene& scene) {
        if (!materials.is_object())
            fail("materials", fmt::format("expected an object mapping names to {{\"reflectance\", \"emission\"}}, "
                                          "found {}",
                                          describe(materials)));

        // Read every value as written; scalars are broadcast once the channel
        // count (the common length of all arrays) is known.
        struct Raw {
            std::vector<double> reflectance, emission;
        };
        std::vector<Raw> raw;
        for (const auto& item : materials.items()) {
            const std::string path = key_path("materials", item.key());
            const Json& m = item.value();
            if (!m.is_object())
                fail(path, fmt::format("expected an object {{\"reflectance\": ..., \"emission\": ...}}, found {}",
                                       describe(m)));
            note_unknown_keys(m, {"reflectance", "emission"}, path);
            Material material;
            material.name = item.key();
            scene.materials.push_back(material);
            Raw values;
            if (const Json* r = optional(m, "reflectance"))
                values.reflectance = read_channels(*r, key_path(path, "reflectance"), ChannelKind::Reflectance);
            if (const Json* e = optional(m, "emission"))
                values.emission = read_channels(*e, key_path(path, "emission"), ChannelKind::Emission);
            raw.push_back(std::move(values));
        }

        scene.channels = static_cast<int>(m_channels.value_or(1));
        const auto broadcast = [&scene](const std::vector<double>& v) {
            if (v.empty()) return std::vector<double>(static_cast<size_t>(scene.channels), 0.0);  // default 0
            if (v.size() == 1) return std::vector<double>(static_cast<size_t>(scene.channels), v[0]);
            return v;
        };
        for (size_t i = 0; i < raw.size(); ++i) {
            scene.materials[i].reflectance = broadcast(raw[i].reflectance);
            scene.materials[i].emission = broadcast(raw[i].emission);
        }
    }

    /// A number or an array of 1 or 3 numbers, each in range. Returns a
    /// single value for a number (to be broadcast) and the array otherwise.
    std::vector<double> read_channels(const Json& v, const std::string& path, ChannelKind kind) {
        const auto check_range = [&](double x, const std::string& at) {
            if (kind == ChannelKind::Reflectance && !(x >= 0.0 && x <= 1.0))
                fail(at, fmt::format("expected a reflectance in [0, 1], found {}", describe_number(x)));
            if (kind == ChannelKind::Emission && !(x >= 0.0))
                fail(at, fmt::format("expected an emission >= 0, found {}", describe_number(x)));
        };
        const std::string_view what =
            kind == ChannelKind::Reflectance ? "a finite reflectance" : "a finite emission";

        if (v.is_number()) {
            const double x = finite_number(v, path, what);
            check_range(x, path);
            return {x};
        }
        if (!v.is_array())
            fail(path, fmt::format("expected a number or an array of 1 or 3 channel values, found {}", describe(v)));
        if (v.size() != 1 && v.size() != 3)
            fail(path, fmt::format("expected 1 or 3 channel values, found {}", describe(v)));
        std::vector<double> values;
        for (size_t c = 0; c < v.size(); ++c) {
            const std::string at = index_path(path, c);
            const double x = finite_number(v[c], at, what);
            check_range(x, at);
            values.push_back(x);
        }
        // Every array in a scene has the same length (SPEC, "Scene file").
        if (!m_channels) {
            m_channels = v.size();
            m_channels_path = path;
        } else if (*m_channels != v.size()) {
            fail(path, fmt::format("expected {} channel values like {}, found {}", *m_channels, m_channels_path,
                                   v.size()));
        }
        return values;
    }

    // ---- surfaces --------------------------------------------------------

    void read_surfaces(const Json& surfaces, Scene& scene) const {
        if (!surfaces.is_array())
            fail("surfaces", fmt::format("expected an array of surfaces, found {}", describe(surfaces)));
        if (surfaces.empty()) fail("surfaces", "a scene needs at least one surface, found an empty array");
        check_memory(surfaces);

        std::unordered_map<std::string, size_t> material_index;
        for (size_t m = 0; m < scene.materials.size(); ++m) material_index.emplace(scene.materials[m].name, m);
        std::unordered_map<std::string, size_t> seen_names;
        seen_names.reserve(surfaces.size());  // (no rehash of 10^6 names as they come)

        for (size_t i = 0; i < surfaces.size(); ++i) {
            const std::string path = index_path("surfaces", i);
            const Json& s = surfaces[i];
            if (!s.is_object())
                fail(path, fmt::format("expected a surface object {{\"name\", \"material\", \"points\" or "
                                       "\"circle\", ...}}, found {}",
                                       describe(s)));
            note_unknown_keys(s, {"name", "material", "points", "circle", "closed", "side"}, path);
            Surface surface;

            // Name, unique in the scene.
            const Json& name = require(s, "name", path);
            if (!name.is_string() || name.get<std::string>().empty())
                fail(key_path(path, "name"), fmt::format("expected a non-empty string, found {}", describe(name)));
            surface.name = name.get<std::string>();
            if (const auto [it, inserted] = seen_names.emplace(surface.name, i); !inserted)
                fail(key_path(path, "name"), fmt::format("duplicate surface name \"{}\" (also surfaces[{}])",
                                                         shorten(surface.name), it->second));

            // Material, by name.
            const Json& material = require(s, "material", path);
            if (!material.is_string())
                fail(key_path(path, "material"),
                     fmt::format("expected a material name (a string), found {}", describe(material)));
            const auto found = material_index.find(material.get<std::string>());
            if (found == material_index.end())
                fail(key_path(path, "material"), fmt::format("unknown material \"{}\"; known: {}",
                                                             shorten(material.get<std::string>()),
                                                             known_materials(scene)));
            surface.material = static_cast<int>(found->second);

            // Shape: points or circle, never both.
            const Json* points = optional(s, "points");
            const Json* circle = optional(s, "circle");
            if (points && circle) fail(path, "expected either \"points\" or \"circle\", found both");
            if (!points && !circle)
                fail(key_path(path, "points"), "missing required key (a surface needs \"points\" or \"circle\")" +
                                                   misspelt_hint(s, {"points", "circle"}));
            surface.is_circle = circle != nullptr;

            if (const Json* closed = optional(s, "closed")) {
                if (!closed->is_boolean())
                    fail(key_path(path, "closed"), fmt::format("expected true or false, found {}", describe(*closed)));
                if (surface.is_circle && !closed->get<bool>())
                    fail(key_path(path, "closed"), "a circle is always closed, found false");
                surface.closed = closed->get<bool>();
            }
            if (surface.is_circle) surface.closed = true;

            surface.side = read_side(s, path, surface.closed);
            surface.points = surface.is_circle ? circle_points(*circle, key_path(path, "circle"))
                                               : polyline_points(*points, key_path(path, "points"), surface.closed);

            // Winding: which geometric side of a segment is "in". A circle is
            // counter-clockwise by construction.
            bool counter_clockwise = true;
            if (surface.closed && !surface.is_circle)
                counter_clockwise = polygon_winding(surface.points, key_path(path, "points"), surface.side);

            add_segments_and_patches(surface, static_cast<int>(i), counter_clockwise, scene);
            scene.surfaces.push_back(std::move(surface));
        }
        check_length_range(scene);
    }

    /// Refuses, before anything is built, a scene whose segments would
    /// need more memory than scene_memory_limit_bytes, at the surface that
    /// takes it over, saying how much. Counts what each surface asks for
    /// (points, or a circle's segments); malformed entries count 0 here and
    /// are refused by the full reading that follows.
    void check_memory(const Json& surfaces) const {
        double total = 0;
        for (size_t i = 0; i < surfaces.size(); ++i) {
            const Json& s = surfaces[i];
            if (!s.is_object()) continue;
            double count = 0;
            std::string where = index_path("surfaces", i);
            if (const Json* points = optional(s, "points"); points && points->is_array()) {
                count = static_cast<double>(points->size());
                where = key_path(where, "points");
            } else if (const Json* circle = optional(s, "circle"); circle && circle->is_object()) {
                const Json* n = optional(*circle, "segments");
                if (n && n->is_number() && std::isfinite(n->get<double>()))
                    count = std::clamp(n->get<double>(), 0.0, max_circle_segments);
                where = key_path(key_path(where, "circle"), "segments");
            }
            total += count;
            const double bytes = scene_memory_bytes(total);
            if (bytes > scene_memory_limit_bytes) {
                constexpr double gib = 1024.0 * 1024 * 1024;
                fail(where, fmt::format("the scene would have {:.0f} segments by this surface, which would need "
                                        "{:.1f} GiB to hold; the limit is {:.0f} GiB (use fewer or coarser "
                                        "surfaces)",
                                        total, bytes / gib, scene_memory_limit_bytes / gib));
            }
        }
    }

    /// Refuses a scene whose shortest segment is below 1 / max_length_range
    /// of its extent, naming that segment.
    void check_length_range(const Scene& scene) const {
        size_t shortest = 0;
        for (size_t k = 1; k < scene.segments.size(); ++k)
            if (scene.segments[k].seg.length() < scene.segments[shortest].seg.length()) shortest = k;
        const double length = scene.segments[shortest].seg.length(), extent = scene.extent();
        if (extent <= max_length_range * length) return;
        const SceneSegment& s = scene.segments[shortest];
        const Surface& surface = scene.surfaces[static_cast<size_t>(s.surface)];
        const std::string base = index_path("surfaces", static_cast<size_t>(s.surface));
        const std::string where =
            surface.is_circle ? key_path(base, "circle")
                              : index_path(key_path(base, "points"),
                                           static_cast<size_t>(s.index + 1) % surface.points.size());
        fail(where, fmt::format("segment {} is {:g} long, {:.2g} times shorter than the scene's extent {:g}: "
                                "beyond the {:g} range of lengths that double precision resolves here (make it "
                                "longer, or the scene smaller)",
                                s.index, length, extent / length, extent, max_length_range));
    }

    static std::string known_materials(const Scene& scene) {
        if (scene.materials.empty()) return "none";
        std::string out;
        for (const Material& m : scene.materials) out += (out.empty() ? "" : ", ") + m.name;
        return shorten(out);
    }

    Side read_side(const Json& s, const std::string& path, bool closed) const {
        const std::string at = key_path(path, "side");
        const Json* side = optional(s, "side");
        if (!side) {
            if (closed)
                fail(at, "missing required key (a closed shape needs \"side\": \"in\", \"out\" or \"both\")" +
                             misspelt_hint(s, {"side"}));
            return Side::Left;
        }
        if (!side->is_string())
            fail(at, fmt::format("expected one of \"left\", \"right\", \"both\", \"in\", \"out\", found {}",
                                 describe(*side)));
        const std::string word = side->get<std::string>();
        Side value;
        if (word == "left") value = Side::Left;
        else if (word == "right") value = Side::Right;
        else if (word == "both") value = Side::Both;
        else if (word == "in") value = Side::In;
        else if (word == "out") value = Side::Out;
        else
            fail(at, fmt::format("expected one of \"left\", \"right\", \"both\", \"in\", \"out\", found {}",
                                 describe(*side)));

        if (closed && (value == Side::Left || value == Side::Right))
            fail(at, fmt::format("a closed shape is lit \"in\", \"out\" or \"both\", found \"{}\"", word));
        if (!closed && (value == Side::In || value == Side::Out))
            fail(at, fmt::format("an open polyline is lit \"left\", \"right\" or \"both\", found \"{}\" "
                                 "(add \"closed\": true for a polygon)",
                                 word));
        return value;
    }

    Vec2 read_point(const Json& v, const std::string& path) const {
        const auto bad = [&] { fail(path, fmt::format("expected [x, y] with finite numbers, found {}", describe(v))); };
        if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) bad();
        const Vec2 p{v[0].get<double>(), v[1].get<double>()};
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) bad();
        if (std::abs(p.x) > max_coordinate || std::abs(p.y) > max_coordinate)
            fail(path, fmt::format("expected coordinates within +-{:g}, found {}", max_coordinate, describe(v)));
        return p;
    }

    /// Points of a polyline or polygon, a closing repeat dropped, every
    /// segment of non-zero length.
    std::vector<Vec2> polyline_points(const Json& v, const std::string& path, bool closed) const {
        if (!v.is_array()) fail(path, fmt::format("expected an array of [x, y] points, found {}", describe(v)));
        std::vector<Vec2> points;
        points.reserve(v.size());
        for (size_t k = 0; k < v.size(); ++k) points.push_back(read_point(v[k], index_path(path, k)));

        // A closed shape may repeat its first point at the end; read it as absent.
        if (closed && points.size() >= 2 && points.back() == points.front()) points.pop_back();
        if (!closed && points.size() < 2)
            fail(path, fmt::format("expected at least two points, found {}", points.size()));
        if (closed && points.size() < 3)
            fail(path, fmt::format("a closed shape needs at least three points (a last point equal to the first "
                                   "does not count), found {}",
                                   points.size()));

        // Zero-length segments. Distinct points can still be too close for a
        // length (the squared difference underflows), which is as bad.
        for (size_t k = 1; k < points.size(); ++k)
            if (!(distance(points[k - 1], points[k]) > 0))
                fail(index_path(path, k),
                     points[k] == points[k - 1]
                         ? fmt::format("zero-length segment: point {} equals point {}", k, k - 1)
                         : fmt::format("segment from point {} is too short to measure", k - 1));
        if (closed && !(distance(points.back(), points.front()) > 0))
            fail(index_path(path, points.size() - 1),
                 fmt::format("zero-length closing segment: point {} equals point 0 (only one closing repeat is "
                             "dropped)",
                             points.size() - 1));
        return points;
    }

    /// Points c + r (cos(2 pi k / n), sin(2 pi k / n)), k = 0..n-1:
    /// counter-clockwise from angle 0 (SPEC).
    std::vector<Vec2> circle_points(const Json& circle, const std::string& path) const {
        if (!circle.is_object())
            fail(path, fmt::format("expected {{\"center\": [x, y], \"radius\": r, \"segments\": n}}, found {}",
                                   describe(circle)));
        note_unknown_keys(circle, {"center", "radius", "segments"}, path);
        const Vec2 center = read_point(require(circle, "center", path), key_path(path, "center"));

        const std::string radius_path = key_path(path, "radius");
        const double radius = finite_number(require(circle, "radius", path), radius_path, "a finite radius > 0");
        if (!(radius > 0)) fail(radius_path, fmt::format("expected a radius > 0, found {}", describe_number(radius)));
        if (radius > max_coordinate)
            fail(radius_path, fmt::format("expected a radius up to {:g}, found {}", max_coordinate, radius));

        const std::string segments_path = key_path(path, "segments");
        const double n_real = finite_number(require(circle, "segments", path), segments_path,
                                            "a whole number of segments >= 3");
        if (std::floor(n_real) != n_real || n_real < 3)
            fail(segments_path,
                 fmt::format("expected a whole number of segments >= 3, found {}", describe_number(n_real)));
        if (n_real > max_circle_segments)
            fail(segments_path, fmt::format("expected at most {} segments, found {}",
                                            static_cast<long>(max_circle_segments), describe_number(n_real)));
        const int n = static_cast<int>(n_real);

        // Rounding the points to doubles moves each by up to about
        // eps * max(|center|, radius). While that stays well below the
        // sagitta r (1 - cos(2 pi / n)) (how far a point sits off the chord
        // of its neighbours) the polygon stays convex, hence simple and
        // counter-clockwise; beyond it, a tiny circle far from the origin
        // could come out flattened or tangled.
        const double s = std::sin(std::numbers::pi / n);
        const double sagitta = 2 * radius * s * s;
        const double rounding = std::numeric_limits<double>::epsilon() *
                                std::max({std::abs(center.x), std::abs(center.y), radius});
        if (!(sagitta > circle_rounding_factor * rounding))
            fail(path, fmt::format("radius {} is too small for {} segments around center [{}, {}]: rounding "
                                   "would distort the polygon (use fewer segments, or move the scene nearer "
                                   "the origin)",
                                   radius, n, center.x, center.y));

        std::vector<Vec2> points;
        points.reserve(static_cast<size_t>(n));
        for (int k = 0; k < n; ++k) points.push_back(center + radius * unit_circle_point(k, n));
        return points;
    }

    /// Point k of n on the unit circle. Quarter turns are exact (cos(pi/2)
    /// would round to 6e-17), so a circle with n divisible by 4 stays
    /// mirror-symmetric about both axes where it matters most.
    static Vec2 unit_circle_point(int k, int n) {
        const long quarter = 4L * k;
        if (quarter % n == 0) {
            switch (quarter / n) {
                case 0: return {1, 0};
                case 1: return {0, 1};
                case 2: return {-1, 0};
                case 3: return {0, -1};
                default: break;
            }
        }
        const double angle = 2 * std::numbers::pi * k / n;
        return {std::cos(angle), std::sin(angle)};
    }

    /// True when the closed polygon winds counter-clockwise (positive
    /// shoelace area), so that its interior is on the left of travel.
    /// For side in/out the polygon must be simple with an area whose sign
    /// survives rounding; for "both" nothing is required and a zero or
    /// unreliable area counts as counter-clockwise (only the in/out labels of
    /// the two patches depend on it).
    bool polygon_winding(const std::vector<Vec2>& p, const std::string& path, Side side) const {
        // Shoelace sum about p[0]: small vectors, less cancellation.
        double twice_area = 0, rounding = 0;
        for (size_t k = 1; k + 1 < p.size(); ++k) {
            const Vec2 u = p[k] - p[0], v = p[k + 1] - p[0];
            twice_area += cross(u, v);
            rounding += norm(u) * norm(v);
        }
        if (side == Side::Both) return twice_area >= 0;

        const double bound = winding_rounding_factor * static_cast<double>(p.size()) *
                             std::numeric_limits<double>::epsilon() * rounding;
        if (!(std::abs(twice_area) > bound))
            fail(path, fmt::format("side \"{}\" needs a simple polygon of non-zero area; these points enclose "
                                   "none (or too little to tell inside from outside)",
                                   side_name(side)));
        check_simple(p, path, side);
        return twice_area > 0;
    }

    /// Refuses a polygon that crosses or touches itself: non-neighbouring
    /// edges must not meet at all, neighbouring edges only at their shared
    /// vertex (a fold back along the same line counts as touching).
    /// polygon_clearly_simple accepts in O(n log n) what this test would
    /// accept with room to spare. Otherwise, the test itself: edges sorted
    /// by their left end and swept in x as a broad phase, the orientation
    /// tests deciding. That is O(n^2) at worst (many edges spanning the
    /// whole x range), but only polygons that are refused, or that come
    /// within about 1e-13 (relative) of touching themselves, get here; the
    /// first pair it finds is the one named.
    void check_simple(const std::vector<Vec2>& p, const std::string& path, Side side) const {
        if (polygon_clearly_simple(p)) return;
        const size_t n = p.size();
        struct Edge {
            Box box;
            size_t index;
        };
        std::vector<Edge> edges;
        edges.reserve(n);
        for (size_t k = 0; k < n; ++k) {
            Edge e{{}, k};
            e.box.add(p[k]);
            e.box.add(p[(k + 1) % n]);
            edges.push_back(e);
        }
        std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) { return a.box.lo.x < b.box.lo.x; });

        const auto edge_name = [n](size_t k) { return fmt::format("segment {} (points {} -> {})", k, k, (k + 1) % n); };
        for (size_t a = 0; a < n; ++a) {
            for (size_t b = a + 1; b < n && edges[b].box.lo.x <= edges[a].box.hi.x; ++b) {
                if (edges[b].box.lo.y > edges[a].box.hi.y || edges[a].box.lo.y > edges[b].box.hi.y) continue;
                const size_t i = std::min(edges[a].index, edges[b].index);
                const size_t j = std::max(edges[a].index, edges[b].index);
                const Vec2 a0 = p[i], a1 = p[(i + 1) % n], b0 = p[j], b1 = p[(j + 1) % n];
                bool bad = false;
                if (j == i + 1) bad = folds_back(a0, a1, b1);           // share a1 == b0
                else if (i == 0 && j == n - 1) bad = folds_back(a1, a0, b0);  // share a0 == b1
                else bad = segments_meet(a0, a1, b0, b1);
                if (bad)
                    fail(path, fmt::format("side \"{}\" needs a simple polygon, but {} meets {}", side_name(side),
                                           edge_name(i), edge_name(j)));
            }
        }
    }

    /// Neighbouring edges u -> v and v -> w overlap beyond v when w lies on the
    /// line through u and v on the same side of v as u.
    static bool folds_back(Vec2 u, Vec2 v, Vec2 w) { return orient(u, v, w) == 0 && dot(u - v, w - v) > 0; }

    /// p lies in the bounding box of [a, b] (enough once p is known to be on its line).
    static bool within(Vec2 a, Vec2 b, Vec2 p) {
        return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
               p.y <= std::max(a.y, b.y);
    }

    /// Closed segments [a, b] and [c, d] share at least one point: a proper
    /// crossing, or an endpoint of one lying on the other.
    static bool segments_meet(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
        const double o1 = orient(a, b, c), o2 = orient(a, b, d);
        const double o3 = orient(c, d, a), o4 = orient(c, d, b);
        const auto opposite = [](double x, double y) { return (x < 0 && y > 0) || (x > 0 && y < 0); };
        if (opposite(o1, o2) && opposite(o3, o4)) return true;
        return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
               (o4 == 0 && within(c, d, b));
    }

    // Two segments on one line overlapping over a positive length put two
    // surfaces in the same place: whatever is in front sees both (a lit
    // patch or a black unlit side twice), so row sums of F exceed 1 and a
    // stiff scene solves to negative radiosity (found by the fuzzer). Such
    // a scene is refused; segments meeting end to end, or crossing, are fine.
    // OverlapFinder finds the first offending segment s in O(N log N); the
    // one named as lying on it is then found as the all-pairs search over
    // the cluster hierarchy that it replaces did (the first t > s in that
    // hierarchy's order), so messages are unchanged. That search can only
    // miss a pair lies_on accepts by a hair (it tests leaf boxes, padded
    // by s's rounding alone); then the first such t is named.
    void check_no_overlaps(const Scene& scene) const {
        const std::vector<Segment> geometry = scene.segment_geometry();
        if (geometry.size() < 2) return;
        const auto found = OverlapFinder(geometry).first();
        if (!found) return;
        const size_t s = found->first;
        size_t t = found->second;

        const Segment& g = geometry[s];
        const Hierarchy hierarchy(geometry, 2);
        std::vector<int32_t> stack;
        Box box;
        box.add(g);
        const double pad = overlap_rounding * (magnitude(g) + g.length());
        box.lo -= Vec2{pad, pad};
        box.hi += Vec2{pad, pad};
        bool named = false;
        hierarchy.query(
            [&](const Box& b) {
                return !named &&
                       !(b.hi.x < box.lo.x || b.lo.x > box.hi.x || b.hi.y < box.lo.y || b.lo.y > box.hi.y);
            },
            [&](int k, const Segment& h) {
                if (named || k <= static_cast<int>(s) || !lies_on(g, h)) return;
                t = static_cast<size_t>(k);
                named = true;
            },
            stack);

        const double overlap = *lies_on(g, geometry[t]);
        const SceneSegment& a = scene.segments[s];
        const SceneSegment& b = scene.segments[t];
        fail(fmt::format("surfaces[{}].points[{}]", b.surface, b.index),
             fmt::format("segment {} of surface \"{}\" lies on segment {} of surface \"{}\" over a "
                         "length of {:g}: two surfaces in one place would each be seen twice; "
                         "remove the overlap (segments may meet end to end or cross)",
                         b.index, scene.surfaces[static_cast<size_t>(b.surface)].name, a.index,
                         scene.surfaces[static_cast<size_t>(a.surface)].name, overlap));
    }

    /// Appends the surface's segments and patches in SPEC numbering: segment
    /// by segment in point order (closing segment last), and per segment the
    /// left (or in) patch before the right (or out) one.
    static void add_segments_and_patches(Surface& surface, int surface_index, bool counter_clockwise, Scene& scene) {
        const size_t n = surface.points.size();
        const size_t count = surface.closed ? n : n - 1;

        // Which geometric side each side word lights. For a closed shape the
        // interior is on the left of travel when it winds counter-clockwise.
        const bool in_is_left = counter_clockwise;
        bool lit_left = false, lit_right = false;
        switch (surface.side) {
            case Side::Left: lit_left = true; break;
            case Side::Right: lit_right = true; break;
            case Side::Both: lit_left = lit_right = true; break;
            case Side::In: (in_is_left ? lit_left : lit_right) = true; break;
            case Side::Out: (in_is_left ? lit_right : lit_left) = true; break;
        }

        surface.first_segment = static_cast<int>(scene.segments.size());
        surface.segment_count = static_cast<int>(count);
        for (size_t k = 0; k < count; ++k) {
            SceneSegment s;
            s.seg = {surface.points[k], surface.points[(k + 1) % n]};
            s.surface = surface_index;
            s.index = static_cast<int>(k);
            s.lit_left = lit_left;
            s.lit_right = lit_right;
            const int segment_index = static_cast<int>(scene.segments.size());
            scene.segments.push_back(s);

            const auto add_patch = [&](bool left) {
                Patch patch;
                patch.segment = segment_index;
                patch.surface = surface_index;
                patch.material = surface.material;
                patch.lit_left = left;
                patch.side = surface.closed ? (left == in_is_left ? Side::In : Side::Out)
                                            : (left ? Side::Left : Side::Right);
                patch.length = s.seg.length();
                scene.patches.push_back(patch);
            };
            // "Left (or in) before right (or out)": for a clockwise polygon the
            // in patch is the right one, so it comes first.
            const bool first_left = surface.closed ? in_is_left : true;
            if (first_left ? lit_left : lit_right) add_patch(first_left);
            if (first_left ? lit_right : lit_left) add_patch(!first_left);
        }
    }

    const std::string& m_file;
    // Scene::warnings while reading (the const readers note what they skip).
    mutable std::vector<std::string> m_warnings;
    mutable size_t m_unknown_keys = 0;  // every one, also those past max_scene_warnings
    std::optional<size_t> m_channels;  // length of the first channel array seen
    std::string m_channels_path;       // where it was seen, for messages
};

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& file_label) {
    const Json root = parse_json(json_text, file_label);
    return SceneReader(file_label).read(root);
}

Scene load_scene(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError(path, "", "cannot read the scene file: it is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int err = errno;
        throw InputError(path, "", fmt::format("cannot open the scene file: {}",
                                               std::generic_category().message(err)));
    }
    std::ostringstream text;
    text << in.rdbuf();  // an empty file sets failbit on `text`; the parser reports it
    if (in.bad()) throw InputError(path, "", "cannot read the scene file: read error");
    return parse_scene(text.str(), path);
}

}  // namespace flatrad
