// Which patches' rows of form factors sum to 1 (solver/closed_rows.h): a
// patch whose light cannot leave the scene closes when closed loops keep it
// apart from every side that sends nothing (visible sinks, inert patches),
// or when each such side it may see is made a sender, which happens where
// some row that may see it is stiff (reflectance 0.95 or more).
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "engine/connectivity.h"
#include "engine/scene.h"
#include "solver/closed_rows.h"
#include "solver/sink_visibility.h"

using namespace flatrad;

namespace {

struct Rows {
    std::vector<char> closed, sends;  // per patch: the row closes; an inert patch is made a sender
    std::vector<char> sink_sends;     // per segment side: a visible sink made a sender
    std::vector<char> dark;           // per segment side: sends nothing (not made a sender)
};

// The rule's inputs as the hierarchical solver makes them.
Rows rows_of(const Scene& s) {
    const Connectivity conn = scene_connectivity(s);
    Rows r;
    std::vector<char> inert(s.patches.size(), 0);
    for (size_t p = 0; p < s.patches.size(); ++p) {
        const Material& m = s.materials[static_cast<size_t>(s.patches[p].material)];
        bool sends = false;
        for (double v : m.reflectance) sends = sends || v > 0;
        for (double v : m.emission) sends = sends || v > 0;
        inert[p] = sends ? 0 : 1;
    }
    const ClosedRows c = closed_rows(s, conn, escape_free_patches(s, conn), visible_sinks(s, conn), inert);
    r.closed = c.closed;
    r.sends = c.inert_sends;
    r.sink_sends = c.sink_sends;
    r.dark = visible_sinks(s, conn);
    for (size_t x = 0; x < r.dark.size(); ++x) {
        CHECK((c.sink_sends[x] == 0 || r.dark[x]));  // only visible sinks are made senders
        if (c.sink_sends[x]) r.dark[x] = 0;
    }
    for (size_t p = 0; p < s.patches.size(); ++p) {
        CHECK((c.inert_sends[p] == 0 || inert[p]));  // only inert patches are made senders
        if (inert[p] && !c.inert_sends[p])
            r.dark[2 * static_cast<size_t>(s.patches[p].segment) + (s.patches[p].lit_left ? 0 : 1)] = 1;
    }
    return r;
}

// Closed rows, or inert patches made senders, among one surface's patches.
int count_on(const Scene& s, const std::vector<char>& per_patch, const std::string& surface) {
    int n = 0;
    for (size_t p = 0; p < s.patches.size(); ++p)
        if (s.surfaces[static_cast<size_t>(s.patches[p].surface)].name == surface) n += per_patch[p];
    return n;
}
int closed_on(const Scene& s, const Rows& r, const std::string& surface) { return count_on(s, r.closed, surface); }

// w: stiff walls (0.99); m: walls below the stiffness bar (0.9).
const char* materials = R"("materials":{"w":{"reflectance":0.99},"m":{"reflectance":0.9},"l":{"emission":1},"b":{"reflectance":0}})";

Scene scene_of(const std::string& surfaces) {
    return parse_scene(std::string(R"({"flatrad":1,)") + materials + R"(,"surfaces":[)" + surfaces + "]}", "rows.json");
}

const std::string room = R"({"name":"room","material":"w","closed":true,"side":"in","points":[[0,0],[4,0],[4,3],[0,3]]})";
const std::string room2 = R"({"name":"room2","material":"w","closed":true,"side":"in","points":[[6,0],[9,0],[9,3],[6,3]]})";

// Whether segment g properly crosses the open segment p -> q (touching at an
// end does not count: the sampled points lie inside their segments).
bool blocks(const Segment& g, Vec2 p, Vec2 q) {
    const double o1 = orient(g.a, g.b, p), o2 = orient(g.a, g.b, q);
    const double o3 = orient(p, q, g.a), o4 = orient(p, q, g.b);
    return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

}  // namespace

TEST_CASE("closed rows: a lamp through a room's wall leaves the rows inside closed") {
    // The lamp's outer part sees the walls' outer sides (sinks): no row
    // closed before, for the whole scene. The loop keeps the walls' inner
    // sides apart from those sinks.
    const Scene s = scene_of(room + R"(,{"name":"lamp","material":"l","side":"both","points":[[3.5,1],[4.5,1]]})");
    const Rows r = rows_of(s);
    CHECK(closed_on(s, r, "room") == 4);
    CHECK(closed_on(s, r, "lamp") == 0);  // its outer part sees out
}

TEST_CASE("closed rows: two rooms each hide the other's outer sides") {
    // Each room's outer sides are kept as visible sinks (the other room lies
    // outside it), but no patch inside either room can see them.
    const Scene s = scene_of(room + "," + room2 + R"(,{"name":"lamp","material":"l","side":"both","points":[[1,1],[2,1]]})");
    const Rows r = rows_of(s);
    int dark = 0;
    for (char d : r.dark) dark += d;
    CHECK(dark == 8);
    CHECK(closed_on(s, r, "room") == 4);
    CHECK(closed_on(s, r, "room2") == 4);
    CHECK(closed_on(s, r, "lamp") == 2);
}

TEST_CASE("closed rows: what sends nothing in a room below the stiffness bar opens that room's rows, not the other's") {
    // Room 1's walls reflect 0.9: the sides there that send nothing stay
    // as they are, and its rows stay open. Room 2 is closed.
    const std::string room_m = R"({"name":"room","material":"m","closed":true,"side":"in","points":[[0,0],[4,0],[4,3],[0,3]]})";
    const std::string lamp2 = R"(,{"name":"lamp","material":"l","side":"both","points":[[7,1],[8,1]]})";
    for (const std::string dark : {R"(,{"name":"plate","material":"m","side":"left","points":[[1,2],[2,2]]})",
                                   R"(,{"name":"plate","material":"b","side":"both","points":[[1,2],[2,2]]})"}) {
        CAPTURE(dark);
        const Scene s = scene_of(room_m + "," + room2 + dark + lamp2);
        const Rows r = rows_of(s);
        CHECK(closed_on(s, r, "room") == 0);
        CHECK(closed_on(s, r, "room2") == 4);
        CHECK(closed_on(s, r, "lamp") == 2);
        for (char c : r.sends) CHECK(c == 0);
        for (char c : r.sink_sends) CHECK(c == 0);
    }
    // With nothing dark, every escape-free row closes, whatever it reflects.
    const Scene one = scene_of(room_m + R"(,{"name":"lamp","material":"l","side":"both","points":[[1,1],[2,1]]})");
    const Rows q = rows_of(one);
    CHECK(closed_on(one, q, "room") == 4);
    CHECK(closed_on(one, q, "lamp") == 2);
}

TEST_CASE("closed rows: in a stiff room, what sends nothing and is seen is made a sender, and the rows close") {
    const std::string lamp2 = R"(,{"name":"lamp","material":"l","side":"both","points":[[7,1],[8,1]]})";
    // A black plate in room 1: its rows close, the plate sends.
    const Scene s = scene_of(room + "," + room2 + R"(,{"name":"black","material":"b","side":"both","points":[[1,1],[2,1]]})" + lamp2);
    const Rows r = rows_of(s);
    CHECK(closed_on(s, r, "room") == 4);
    CHECK(closed_on(s, r, "room2") == 4);
    CHECK(count_on(s, r.sends, "black") == 2);
    // A one-sided plate: its back (a sink) is made a sender; the rooms'
    // outer sides, seen from no row, stay plain sinks.
    const Scene t = scene_of(room + "," + room2 + R"(,{"name":"plate","material":"w","side":"left","points":[[1,2],[2,2]]})" + lamp2);
    const Rows q = rows_of(t);
    CHECK(closed_on(t, q, "room") == 4);
    CHECK(closed_on(t, q, "room2") == 4);
    CHECK(closed_on(t, q, "plate") == 1);
    int sinks_sending = 0;
    for (char c : q.sink_sends) sinks_sending += c;
    CHECK(sinks_sending == 1);
    CHECK(q.sink_sends[2 * 8 + 1] == 1);  // segment 8 is the plate, lit on its left
}

TEST_CASE("closed rows: no closed row sees a side that sends nothing (sampled lines)") {
    // Random scenes: a room, sometimes a second one, sticks inside, outside
    // and through the walls, one-sided plates (their backs are sinks) and
    // black plates. For every closed patch and every dark side, lines
    // between random points of the two that leave the patch's lit side and
    // reach the dark side's face must each cross some other segment; one
    // free line is a closed row that sees what its links miss.
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> U(0, 1);
    int closed_total = 0, dark_total = 0, lines = 0, senders = 0;
    for (int trial = 0; trial < 60; ++trial) {
        std::string surfaces = room;
        if (U(rng) < 0.5) surfaces += "," + room2;
        const int n = 1 + static_cast<int>(U(rng) * 6);
        for (int k = 0; k < n; ++k) {
            const double x = -1 + 11 * U(rng), y = -0.5 + 4 * U(rng), a = 6.3 * U(rng), len = 0.3 + 1.5 * U(rng);
            const double r = U(rng);
            const char* material = r < 0.2 ? "b" : (r < 0.4 ? "l" : (r < 0.7 ? "w" : "m"));
            const char* side = U(rng) < 0.4 ? "left" : "both";
            surfaces += R"(,{"name":"s)" + std::to_string(k) + R"(","material":")" + material + R"(","side":")" + side +
                        R"(","points":[[)" + std::to_string(x) + "," + std::to_string(y) + "],[" +
                        std::to_string(x + len * std::cos(a)) + "," + std::to_string(y + len * std::sin(a)) + "]]}";
        }
        const Scene s = scene_of(surfaces);
        const Rows r = rows_of(s);
        for (char c : r.sends) senders += c;
        for (char c : r.sink_sends) senders += c;
        for (size_t p = 0; p < s.patches.size(); ++p) {
            if (!r.closed[p]) continue;
            ++closed_total;
            const Segment P = s.patches[p].oriented(s.segments);
            const Vec2 nP = P.left_normal();
            for (size_t x = 0; x < r.dark.size(); ++x) {
                if (!r.dark[x]) continue;
                ++dark_total;
                const size_t seg = x / 2;
                const Segment& D0 = s.segments[seg].seg;
                const Segment D = x % 2 == 0 ? D0 : D0.reversed();  // the dark side on its left
                const Vec2 nD = D.left_normal();
                for (int k = 0; k < 64; ++k) {
                    const Vec2 p0 = P.a + (0.02 + 0.96 * U(rng)) * (P.b - P.a);
                    const Vec2 q0 = D.a + (0.02 + 0.96 * U(rng)) * (D.b - D.a);
                    if (dot(q0 - p0, nP) <= 0 || dot(p0 - q0, nD) <= 0) continue;
                    ++lines;
                    bool blocked = false;
                    for (size_t g = 0; g < s.segments.size() && !blocked; ++g)
                        if (g != static_cast<size_t>(s.patches[p].segment) && g != seg) blocked = blocks(s.segments[g].seg, p0, q0);
                    CHECK_MESSAGE(blocked, "trial ", trial, " patch ", p, " sees dark side ", x);
                }
            }
        }
    }
    // The check saw closed rows facing dark sides (the rule did something),
    // and sides that send nothing made senders.
    CHECK(closed_total > 100);
    CHECK(lines > 1000);
    CHECK(senders > 10);
    MESSAGE("closed rows ", closed_total, ", pairs with a dark side ", dark_total, ", lines ", lines,
            ", sides made senders ", senders);
}
