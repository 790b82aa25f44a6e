#include "engine/connectivity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/connected_components.hpp>

#include "engine/compensated_sum.h"
#include "engine/error.h"
#include "engine/hierarchy.h"

namespace flatrad {

namespace {

// ---- certified predicates ----------------------------------------------------
//
// Each predicate returns a sign only when rounding cannot have changed it;
// otherwise "unsure" (0), and every caller turns unsure into "not proven".

// orient(a, b, c) = cross(b - a, c - a) is computed from two rounded
// differences (relative error u = eps / 2 each) and Kahan's FMA difference
// of products (about 1.5 u of the result), so it is within 3.5 u P of the
// exact value, P = |ux vy| + |uy vx| the sum of the magnitudes of the two
// products. 8 eps = 16 u leaves a margin of more than 4. The same bound
// serves dot products (two rounded differences, two products, one sum).
// Relative, so it does not depend on the scene's size or position.
constexpr double rounding_bound = 8 * std::numeric_limits<double>::epsilon();

/// +1 if c is certainly left of a -> b, -1 if certainly right, 0 if unsure
/// (on the line or within rounding of it).
int orient_sign(Vec2 a, Vec2 b, Vec2 c) {
    const Vec2 u = b - a, v = c - a;
    const double o = cross(u, v);
    const double bound = rounding_bound * (std::abs(u.x * v.y) + std::abs(u.y * v.x));
    return o > bound ? 1 : (o < -bound ? -1 : 0);
}

/// The closed segments s and e certainly have no point in common. False
/// when they cross, touch, overlap, or it is too close to call.
bool certainly_disjoint(const Segment& s, const Segment& e) {
    if (boxes_apart(box_of(s), box_of(e))) return true;  // exact comparisons
    // One segment strictly on one side of the other's line. For collinear
    // segments this never fires, but collinear segments with overlapping
    // boxes do meet, so nothing disjoint is missed except when unsure.
    const int d1 = orient_sign(e.a, e.b, s.a), d2 = orient_sign(e.a, e.b, s.b);
    if (d1 != 0 && d1 == d2) return true;
    const int d3 = orient_sign(s.a, s.b, e.a), d4 = orient_sign(s.a, s.b, e.b);
    return d3 != 0 && d3 == d4;
}

/// Segments [v, x] and [v, w], which share the vertex v, certainly meet
/// nowhere else: w is certainly off the line v x, or the two leave v at
/// certainly more than a right angle (collinear pieces of a straight wall).
bool meet_only_at_vertex(Vec2 v, Vec2 x, Vec2 w) {
    if (orient_sign(v, x, w) != 0) return true;
    const Vec2 p = x - v, q = w - v;
    const double d = dot(p, q);
    return d < -rounding_bound * (std::abs(p.x * q.x) + std::abs(p.y * q.y));
}

// ---- hierarchy traversal with early exit --------------------------------------

/// Visits, depth first, the segments of `tree` whose node boxes pass
/// `box_test`; stops as soon as `visit(local index)` returns true, and
/// then returns true.
template <class BoxTest, class Visit>
bool find_in(const Hierarchy& tree, BoxTest&& box_test, Visit&& visit, std::vector<int32_t>& stack) {
    if (tree.nodes().empty()) return false;
    stack.clear();
    stack.push_back(tree.root());
    while (!stack.empty()) {
        const ClusterNode& n = tree.node(stack.back());
        stack.pop_back();
        if (!box_test(n.box)) continue;
        if (n.leaf()) {
            for (int32_t k = n.first; k < n.first + n.count; ++k)
                if (visit(static_cast<int>(tree.order()[static_cast<size_t>(k)]))) return true;
        } else {
            stack.push_back(n.child[1]);
            stack.push_back(n.child[0]);
        }
    }
    return false;
}

// ---- one loop's segments, indexed ---------------------------------------------

// Loops up to this many segments are scanned whole (a room, a table top, a
// 24-segment circle): below a few dozen a scan is cheaper than a tree walk.
constexpr size_t loop_scan_limit = 32;

/// A loop's segments as traversed (edge k from polygon[k] to polygon[k+1]),
/// with a cluster hierarchy over them when the loop is large.
class LoopEdges {
public:
    /// The loop's edge_tree when it has one, else one built here (for a loop
    /// of more than loop_scan_limit edges).
    explicit LoopEdges(const SceneLoop& loop) : m_polygon(&loop.polygon), m_tree(loop.edge_tree) {
        const size_t n = loop.polygon.size();
        if (!m_tree && n > loop_scan_limit) {
            std::vector<Segment> edges(n);
            for (size_t k = 0; k < n; ++k) edges[k] = edge(static_cast<int>(k));
            m_tree = std::make_shared<const Hierarchy>(edges, 4);
        }
    }
    const std::shared_ptr<const Hierarchy>& tree() const { return m_tree; }
    int size() const { return static_cast<int>(m_polygon->size()); }
    Segment edge(int k) const {
        const auto& p = *m_polygon;
        return {p[static_cast<size_t>(k)], p[(static_cast<size_t>(k) + 1) % p.size()]};
    }
    /// Calls visit(k) for the edges whose boxes pass box_test (and maybe a
    /// few more) until it returns true; returns whether it did.
    template <class BoxTest, class Visit>
    bool find(BoxTest&& box_test, Visit&& visit, std::vector<int32_t>& stack) const {
        if (m_tree) return find_in(*m_tree, box_test, visit, stack);
        for (int k = 0; k < size(); ++k)
            if (box_test(box_of(edge(k))) && visit(k)) return true;
        return false;
    }

private:
    const std::vector<Vec2>* m_polygon;
    std::shared_ptr<const Hierarchy> m_tree;  // null: scan the edges
};

/// Certified simple (SceneLoop::simple): every pair of segments whose boxes
/// overlap is checked, consecutive pairs for meeting only at their shared
/// vertex, the others for having no point in common.
bool certify_simple(const SceneLoop& loop, const LoopEdges& edges, std::vector<int32_t>& stack) {
    const int n = edges.size();
    if (n < 3) return false;  // two segments between the same two vertices enclose nothing
    const auto& p = loop.polygon;
    for (int k = 0; k < n; ++k) {
        const Segment ek = edges.edge(k);
        const Box bk = box_of(ek);
        const int next = (k + 1) % n, prev = (k + n - 1) % n;
        const bool bad = edges.find([&](const Box& b) { return !boxes_apart(b, bk); },
                                    [&](int j) {
                                        if (j == k) return false;
                                        if (j == next)  // shares polygon[next], the end of ek
                                            return !meet_only_at_vertex(p[static_cast<size_t>(next)], ek.a,
                                                                        edges.edge(j).b);
                                        if (j == prev)  // shares polygon[k], the start of ek
                                            return !meet_only_at_vertex(ek.a, ek.b, edges.edge(j).a);
                                        return !certainly_disjoint(ek, edges.edge(j));
                                    },
                                    stack);
        if (bad) return false;
    }
    return true;
}

/// +1 / -1 / 0 as SceneLoop::orientation, for a simple loop: the turn at the
/// lowest (then leftmost) vertex, which is strictly convex in a simple polygon.
int certify_orientation(const SceneLoop& loop) {
    const auto& p = loop.polygon;
    const size_t n = p.size();
    size_t low = 0;
    for (size_t k = 1; k < n; ++k)
        if (p[k].y < p[low].y || (p[k].y == p[low].y && p[k].x < p[low].x)) low = k;
    return orient_sign(p[(low + n - 1) % n], p[low], p[(low + 1) % n]);
}

/// Crossing number of the ray from c towards +x against the loop, odd
/// meaning inside. nullopt when unsure: c on the loop, or a crossing too
/// close to call. Half-open rule: an edge counts when exactly one endpoint
/// is strictly above c, so a vertex on the ray's line counts once or twice,
/// consistently, with exact comparisons.
std::optional<bool> inside_loop(Vec2 c, const LoopEdges& edges, std::vector<int32_t>& stack) {
    int crossings = 0;
    bool unsure = false;
    edges.find([&](const Box& b) { return b.hi.x >= c.x && b.lo.y <= c.y && b.hi.y >= c.y; },
               [&](int k) {
                   const Segment e = edges.edge(k);
                   if ((e.a.y > c.y) != (e.b.y > c.y)) {
                       const int side = orient_sign(e.a, e.b, c);
                       if (side == 0) return unsure = true;
                       // An upward edge passes right of c when c is on its left.
                       if ((e.b.y > e.a.y) == (side > 0)) ++crossings;
                       return false;
                   }
                   // Not straddling: it can hold c only at an endpoint or
                   // along its length if it lies on the ray's line.
                   const bool on = e.a == c || e.b == c ||
                                   (e.a.y == c.y && e.b.y == c.y && std::min(e.a.x, e.b.x) <= c.x &&
                                    c.x <= std::max(e.a.x, e.b.x));
                   return unsure = on;
               },
               stack);
    if (unsure) return std::nullopt;
    return crossings % 2 == 1;
}

/// Segment s is certainly disjoint from every segment of the loop.
bool apart_from_loop(const Segment& s, const LoopEdges& edges, std::vector<int32_t>& stack) {
    const Box bs = box_of(s);
    return !edges.find([&](const Box& b) { return !boxes_apart(b, bs); },
                       [&](int k) { return !certainly_disjoint(s, edges.edge(k)); }, stack);
}

}  // namespace

// ---- the graph ------------------------------------------------------------------

Connectivity scene_connectivity(const Scene& scene) {
    Connectivity cx;
    const size_t n = scene.segments.size();
    cx.segment_vertex.assign(2 * n, -1);

    // 1. Vertices: sort the 2N endpoints and merge exactly equal ones.
    //    Exact equality, no tolerance, because (a) a closed polygon's closing
    //    segment and a circle's consecutive segments reuse the very same
    //    stored point, and two polylines the user joins by writing the same
    //    coordinates parse to the same double, so real joints are exact;
    //    (b) merging points that are merely close would call a loop closed
    //    across a gap that light can pass through, and a proof of "no
    //    escape" must not rest on that, while a missed merge only costs a
    //    "not proven"; (c) equality is transitive, a tolerance is not (a
    //    chain of near points would merge points far apart). -0.0 and 0.0
    //    compare equal, so they merge.
    struct End {
        Vec2 p;
        uint32_t id;  // 2 * segment + (0 for a, 1 for b)
    };
    std::vector<End> ends(2 * n);
    for (size_t s = 0; s < n; ++s) {
        ends[2 * s] = {scene.segments[s].seg.a, static_cast<uint32_t>(2 * s)};
        ends[2 * s + 1] = {scene.segments[s].seg.b, static_cast<uint32_t>(2 * s + 1)};
    }
    std::sort(ends.begin(), ends.end(), [](const End& u, const End& v) {
        return u.p.x < v.p.x || (u.p.x == v.p.x && u.p.y < v.p.y);
    });
    int groups = 0;
    for (size_t k = 0; k < ends.size(); ++k) {
        if (k > 0 && !(ends[k].p == ends[k - 1].p)) ++groups;
        cx.segment_vertex[ends[k].id] = groups;
    }
    if (!ends.empty()) ++groups;
    std::vector<End>().swap(ends);
    // Renumber vertices by first appearance in segment order, so that the
    // graph is built and searched in memory order (twice as fast at 10^6).
    std::vector<int> renumber(static_cast<size_t>(groups), -1);
    int vertices = 0;
    for (int& v : cx.segment_vertex) {
        int& r = renumber[static_cast<size_t>(v)];
        if (r < 0) r = vertices++;
        v = r;
    }
    cx.vertex_count = vertices;

    // 2. The endpoint graph (edge = segment) and its connected components.
    struct EdgeSegment {
        int segment;
    };
    using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::undirectedS, boost::no_property,
                                        EdgeSegment, boost::no_property, boost::vecS>;
    Graph graph(static_cast<size_t>(vertices));
    for (size_t s = 0; s < n; ++s)
        boost::add_edge(static_cast<size_t>(cx.segment_vertex[2 * s]), static_cast<size_t>(cx.segment_vertex[2 * s + 1]),
                        EdgeSegment{static_cast<int>(s)}, graph);
    std::vector<int> component(static_cast<size_t>(vertices));
    const int components = vertices ? boost::connected_components(graph, component.data()) : 0;
    cx.vertex_degree.resize(static_cast<size_t>(vertices));
    for (int v = 0; v < vertices; ++v)
        cx.vertex_degree[static_cast<size_t>(v)] = static_cast<int>(boost::degree(static_cast<size_t>(v), graph));

    // 3. Objects, numbered by their lowest segment.
    std::vector<int> object_of_component(static_cast<size_t>(components), -1);
    cx.segment_object.resize(n);
    for (size_t s = 0; s < n; ++s) {
        int& obj = object_of_component[static_cast<size_t>(component[static_cast<size_t>(cx.segment_vertex[2 * s])])];
        if (obj < 0) {
            obj = static_cast<int>(cx.objects.size());
            cx.objects.emplace_back();
        }
        cx.segment_object[s] = obj;
        cx.objects[static_cast<size_t>(obj)].segments.push_back(static_cast<int>(s));
    }

    // 4. Loops: objects whose every vertex has degree 2, which makes a
    //    connected object one cycle. Walk it from its first segment.
    std::vector<char> all_degree_two(cx.objects.size(), 1);
    for (int v = 0; v < vertices; ++v)
        if (cx.vertex_degree[static_cast<size_t>(v)] != 2)
            all_degree_two[static_cast<size_t>(object_of_component[static_cast<size_t>(component[static_cast<size_t>(v)])])] = 0;
    std::vector<int32_t> stack;
    for (size_t o = 0; o < cx.objects.size(); ++o) {
        if (!all_degree_two[o]) continue;
        SceneObject& obj = cx.objects[o];
        SceneLoop loop;
        loop.object = static_cast<int>(o);
        const size_t m = obj.segments.size();
        loop.segments.reserve(m);
        loop.forward.reserve(m);
        loop.polygon.reserve(m);
        int s = obj.segments.front();
        int v = cx.segment_vertex[2 * static_cast<size_t>(s)];  // start at s.a, go forward
        for (size_t step = 0; step < m; ++step) {
            const bool fwd = cx.segment_vertex[2 * static_cast<size_t>(s)] == v;
            const Segment& g = scene.segments[static_cast<size_t>(s)].seg;
            loop.segments.push_back(s);
            loop.forward.push_back(fwd ? 1 : 0);
            loop.polygon.push_back(fwd ? g.a : g.b);
            loop.box.add(g);
            v = cx.segment_vertex[2 * static_cast<size_t>(s) + (fwd ? 1 : 0)];  // the far end
            // The other segment at v (by segment number: in a two-segment
            // cycle both edges join the same two vertices).
            int next = -1;
            for (auto [e, end] = boost::out_edges(static_cast<size_t>(v), graph); e != end; ++e)
                if (graph[*e].segment != s) next = graph[*e].segment;
            FLATRAD_ASSERT(next >= 0, "a degree-2 vertex has two segments");
            s = next;
        }
        FLATRAD_ASSERT(s == obj.segments.front(), "a connected object with every degree 2 is one cycle");

        // Shoelace about the first vertex (small differences, compensated sum).
        CompensatedSum area;
        for (size_t k = 1; k + 1 < m; ++k)
            area.add(cross(loop.polygon[k] - loop.polygon[0], loop.polygon[k + 1] - loop.polygon[0]));
        loop.signed_area = 0.5 * area.value();

        const LoopEdges edges(loop);
        loop.simple = certify_simple(loop, edges, stack);
        loop.edge_tree = edges.tree();  // (escape_free_patches' tests use it again)
        loop.orientation = loop.simple ? certify_orientation(loop) : 0;
        obj.loop = static_cast<int>(cx.loops.size());
        cx.loops.push_back(std::move(loop));
    }
    return cx;
}

// ---- escape-free patches -----------------------------------------------------------

std::vector<char> escape_free_patches(const Scene& scene, const Connectivity& cx) {
    const size_t n = scene.segments.size();
    std::vector<char> result(scene.patches.size(), 0);
    if (cx.loops.empty()) return result;  // nothing closes: nothing is proven

    std::vector<LoopEdges> edges;
    edges.reserve(cx.loops.size());
    for (const SceneLoop& loop : cx.loops) edges.emplace_back(loop);

    // Where each loop segment sits in its cycle (for rule 2).
    std::vector<int> cycle_position(n, -1);
    for (const SceneLoop& loop : cx.loops)
        for (size_t k = 0; k < loop.segments.size(); ++k)
            cycle_position[static_cast<size_t>(loop.segments[k])] = static_cast<int>(k);

    // The loops' boxes, as the diagonals of a hierarchy (a node's box is
    // then the union of its loops' boxes).
    std::vector<Segment> diagonals;
    diagonals.reserve(cx.loops.size());
    for (const SceneLoop& loop : cx.loops) diagonals.push_back({loop.box.lo, loop.box.hi});
    const Hierarchy loop_tree(diagonals, 1);

    std::vector<int32_t> outer_stack, inner_stack;
    // Rule 1, per segment (both patches of a two-sided segment share it):
    // some other loop whose box holds the segment's box is certainly apart
    // from the segment and holds its first endpoint (an exact point, so no
    // rounded midpoint; with no contact the whole segment lies in one face
    // of the loop, so the endpoint decides for the midpoint too).
    std::vector<signed char> enclosed(n, -1);
    auto segment_enclosed = [&](int s) {
        signed char& memo = enclosed[static_cast<size_t>(s)];
        if (memo >= 0) return memo == 1;
        const Segment g = scene.segments[static_cast<size_t>(s)].seg;
        const Box bs = box_of(g);
        const int own = cx.objects[static_cast<size_t>(cx.segment_object[static_cast<size_t>(s)])].loop;
        const bool found = find_in(
            loop_tree,
            [&](const Box& b) { return b.lo.x <= bs.lo.x && b.lo.y <= bs.lo.y && b.hi.x >= bs.hi.x && b.hi.y >= bs.hi.y; },
            [&](int l) {
                if (l == own) return false;
                const LoopEdges& e = edges[static_cast<size_t>(l)];
                const Box& lb = cx.loops[static_cast<size_t>(l)].box;
                if (!(lb.lo.x <= bs.lo.x && lb.lo.y <= bs.lo.y && lb.hi.x >= bs.hi.x && lb.hi.y >= bs.hi.y))
                    return false;
                if (!apart_from_loop(g, e, inner_stack)) return false;
                const std::optional<bool> in = inside_loop(g.a, e, inner_stack);
                return in.value_or(false);
            },
            outer_stack);
        memo = found ? 1 : 0;
        return found;
    };

    for (size_t p = 0; p < scene.patches.size(); ++p) {
        const Patch& patch = scene.patches[p];
        const size_t s = static_cast<size_t>(patch.segment);
        // Rule 2: a side of a certified simple loop's own segment, lit
        // towards its interior (left of the traversal when the loop runs
        // counter-clockwise). The traversal's left is the file's left when
        // the segment is traversed a -> b.
        const int own = cx.objects[static_cast<size_t>(cx.segment_object[s])].loop;
        if (own >= 0) {
            const SceneLoop& loop = cx.loops[static_cast<size_t>(own)];
            if (loop.simple && loop.orientation != 0) {
                const bool fwd = loop.forward[static_cast<size_t>(cycle_position[s])] != 0;
                const bool lit_on_traversal_left = patch.lit_left == fwd;
                if (lit_on_traversal_left == (loop.orientation > 0)) {
                    result[p] = 1;
                    continue;
                }
            }
        }
        result[p] = segment_enclosed(patch.segment) ? 1 : 0;
    }
    return result;
}

std::vector<char> escape_free_patches(const Scene& scene) {
    return escape_free_patches(scene, scene_connectivity(scene));
}

bool scene_enclosed(const Scene& scene) {
    const std::vector<char> free = escape_free_patches(scene);
    return std::all_of(free.begin(), free.end(), [](char f) { return f != 0; });
}

}  // namespace flatrad
