#include "engine/formfactor.h"

#include "engine/error.h"

#include <algorithm>
#include <limits>

namespace flatrad {

namespace {

// A cut point is computed to a few ulps of the coordinates' size; two cuts
// closer than 64 ulps of it are the same point.
constexpr double snap_tolerance = 64 * std::numeric_limits<double>::epsilon();

// |u| - |v| for two nearby vectors without subtracting large lengths:
// (|u|^2 - |v|^2) / (|u| + |v|), the numerator as (u - v).(u + v) where
// u - v is formed from the small difference directly by the caller.
double length_difference(Vec2 u, Vec2 v, Vec2 u_minus_v) {
    const double su = norm(u), sv = norm(v);
    const double s = su + sv;
    if (s == 0) return 0;
    return dot(u_minus_v, u + v) / s;
}

// Part of s on the closed left side of the directed line (p, q); nullopt when
// that part is at most a point.
std::optional<Segment> clip_left(const Segment& s, Vec2 p, Vec2 q) {
    const double oa = orient(p, q, s.a), ob = orient(p, q, s.b);
    if (oa >= 0 && ob >= 0) {
        if (oa == 0 && ob == 0) return std::nullopt;  // on the line: grazing, no exchange
        return s;
    }
    if (oa <= 0 && ob <= 0) return std::nullopt;
    // One endpoint strictly on each side: cut at the crossing, measured
    // from the nearer end (its rounding is then a few ulps of that
    // distance, not of the whole length: a cut 8 from the end of a 5e14
    // wall stays within 1e-15 instead of 0.1).
    const double t = oa / (oa - ob);
    const Vec2 x = t <= 0.5 ? lerp(s.a, s.b, t) : lerp(s.b, s.a, ob / (ob - oa));
    return oa > 0 ? Segment{s.a, x} : Segment{x, s.b};
}

// Two segments sharing the vertex o, with far ends p and q (a wedge):
// crossed minus uncrossed strings is |P| + |Q| - |P - Q| (P = p - o,
// Q = q - o). Near a flat wedge (angle -> pi) that difference cancels, and
// so does the second-difference form; instead use
//   |P| + |Q| - |P - Q| = 2 (|P||Q| + P.Q) / (|P| + |Q| + |P - Q|),
//   |P||Q| + P.Q = cross(P, Q)^2 / (|P||Q| - P.Q)  when P.Q < 0,
// in which nothing cancels at any angle.
double exchange_wedge(Vec2 o, Vec2 p, Vec2 q) {
    const Vec2 P = p - o, Q = q - o;
    const double lp = norm(P), lq = norm(Q), lpq = distance(p, q);
    const double pq = dot(P, Q);
    const double num = pq >= 0 ? lp * lq + pq : [&] {
        const double c = cross(P, Q);
        return c * c / (lp * lq - pq);
    }();
    // Sides so short that their lengths underflow to 0 (a denormal's
    // square is 0) exchange 0 to every digit a double holds (X is at most
    // the shorter side's length): not 0 / 0.
    const double den = lp + lq + lpq;
    if (!(den > 0)) return 0;
    const double S = 2 * num / den;
    return S / 2;
}

}  // namespace

double form_factor_point_segment(Vec2 x, Vec2 n, const Segment& s) {
    // sin of the angle between n and (e - x) is the component of the unit
    // vector to e along the tangent t = (n.y, -n.x); the sign convention of t
    // does not matter since we take |sin b - sin a|.
    const Vec2 t{n.y, -n.x};
    const Vec2 uc = s.a - x, ud = s.b - x;
    const double lc = norm(uc), ld = norm(ud);
    // x on an endpoint: the segment lies on a line through x and subtends no angle.
    if (lc == 0 || ld == 0) return 0;
    const double sc = dot(uc, t) / lc, sd = dot(ud, t) / ld;
    return std::abs(sd - sc) / 2;
}

std::optional<std::pair<Segment, Segment>> clip_to_lit_halfplanes(const Segment& i, const Segment& j) {
    auto ci = clip_left(i, j.a, j.b);
    if (!ci) return std::nullopt;
    auto cj = clip_left(j, i.a, i.b);
    if (!cj) return std::nullopt;
    // When the two lines cross inside both segments, each is cut at the
    // crossing, computed twice with different roundings. Make the two cuts
    // one point, so that the pair is an exact wedge (and the shaft has no
    // sliver of an edge whose orientation is rounding noise). Only a cut
    // point carries that rounding, and only of its own size: two uncut
    // endpoints are never moved (a 1e57-long wall must not pull the end of
    // a unit lamp 2 away onto its corner).
    // A cut point's rounding: a few ulps of its coordinates and of its
    // distance to the end of its segment it was measured from (clip_left).
    const auto scale = [](Vec2 x, const Segment& s) {
        return std::max(std::abs(x.x), std::abs(x.y)) + std::min(distance(x, s.a), distance(x, s.b));
    };
    const auto snaps = [&](Vec2 p, bool p_cut, const Segment& p_from, Vec2 q, bool q_cut, const Segment& q_from) {
        if (p == q || !(p_cut || q_cut)) return false;
        const double snap = snap_tolerance * ((p_cut ? scale(p, p_from) : 0.0) + (q_cut ? scale(q, q_from) : 0.0));
        return distance(p, q) <= snap;
    };
    const bool ia_cut = !(ci->a == i.a), ib_cut = !(ci->b == i.b);
    const bool ja_cut = !(cj->a == j.a), jb_cut = !(cj->b == j.b);
    if (snaps(ci->a, ia_cut, i, cj->b, jb_cut, j)) cj->b = ci->a;
    if (snaps(ci->b, ib_cut, i, cj->a, ja_cut, j)) cj->a = ci->b;
    if (ci->a == ci->b || cj->a == cj->b) return std::nullopt;
    return std::make_pair(*ci, *cj);
}

double exchange_crossed_strings(const Segment& i, const Segment& j) {
    // DESIGN.md §1: S = f(a) - f(b), f(x) = |x - c| - |x - d|, s_x = |x - c| + |x - d|,
    // g = d - c:
    //   S = [2 (g.(a - b)) s_b + (g.(2b - c - d)) (s_b - s_a)] / (s_a s_b),
    //   s_b - s_a = (|b - c| - |a - c|) + (|b - d| - |a - d|), each paired.
    // The form below subtracts nearby values only when i is the shorter
    // segment (its error is a few ulps of L_i, not of X): the exchange is
    // symmetric, so let the shorter one play i. Beside a 1e33-long wall a
    // unit segment's X would otherwise be noise of size 1e17.
    if (norm_squared(i.b - i.a) > norm_squared(j.b - j.a)) return exchange_crossed_strings(j, i);
    const Vec2 a = i.a, b = i.b, c = j.a, d = j.b;
    if (b == c) return exchange_wedge(b, a, d);
    if (a == d) return exchange_wedge(a, b, c);
    const Vec2 g = d - c, ab = a - b;
    const Vec2 ac = a - c, ad = a - d, bc = b - c, bd = b - d;
    const double s_a = norm(ac) + norm(ad);
    const double s_b = norm(bc) + norm(bd);
    if (s_a == 0 || s_b == 0) return 0;  // a degenerate segment
    // (b - c) - (a - c) = b - a exactly in meaning; use -ab for both pairs.
    const double ds = length_difference(bc, ac, -ab) + length_difference(bd, ad, -ab);
    const double num = 2 * dot(g, ab) * s_b + dot(g, bc + bd) * ds;
    const double S = num / (s_a * s_b);
    return std::max(0.0, S / 2);
}

double exchange_crossed_strings_naive(const Segment& i, const Segment& j) {
    const Vec2 a = i.a, b = i.b, c = j.a, d = j.b;
    return ((distance(a, c) + distance(b, d)) - (distance(a, d) + distance(b, c))) / 2;
}

double form_factor_unoccluded(const Segment& i, const Segment& j) {
    const double L_i = i.length();
    FLATRAD_ASSERT(L_i > 0, "form factor from a zero-length segment");
    auto clipped = clip_to_lit_halfplanes(i, j);
    if (!clipped) return 0;
    return exchange_crossed_strings(clipped->first, clipped->second) / L_i;
}

}  // namespace flatrad
