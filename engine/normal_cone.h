#pragma once
/// The directions a group of surfaces faces: the smallest arc of the circle
/// of directions holding every member's normal (a "normal cone", in 2D an
/// angular interval). It tells where a sum of cosine lobes is linear:
/// sum_i w_i cos+(n_i . u) = (sum_i w_i n_i) . u exactly wherever every
/// n_i . u >= 0 (faces_all), and is 0 wherever every n_i . u <= 0
/// (faces_none); both are asked for every direction between two convex
/// regions given by their corners.
/// Used by the hierarchical solver's directional model (solver/directional.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <numbers>

#include "engine/geometry.h"

namespace flatrad {

struct NormalCone {
    double lo = 0;      ///< start angle of the arc (radians, [0, 2 pi))
    double width = -1;  ///< counter-clockwise extent; < 0: empty (no member)

    bool empty() const { return width < 0; }

    static double angle_of(Vec2 n) {
        double a = std::atan2(n.y, n.x);
        return a < 0 ? a + 2 * std::numbers::pi : a;
    }
    static NormalCone of(Vec2 n) { return {angle_of(n), 0.0}; }

    /// The smallest arc holding both (it starts where one of them starts).
    static NormalCone merge(const NormalCone& a, const NormalCone& b) {
        if (a.empty()) return b;
        if (b.empty()) return a;
        constexpr double two_pi = 2 * std::numbers::pi;
        auto ccw = [&](double from, double to) {  // counter-clockwise angle from -> to, in [0, 2 pi)
            const double d = std::fmod(to - from, two_pi);
            return d < 0 ? d + two_pi : d;
        };
        const double wa = std::max(a.width, ccw(a.lo, b.lo) + b.width);
        const double wb = std::max(b.width, ccw(b.lo, a.lo) + a.width);
        NormalCone c = wa <= wb ? NormalCone{a.lo, wa} : NormalCone{b.lo, wb};
        if (c.width >= two_pi) c = {0.0, two_pi};
        return c;
    }

    /// The arc's two end normals (equal for one member).
    std::pair<Vec2, Vec2> ends() const {
        return {{std::cos(lo), std::sin(lo)}, {std::cos(lo + width), std::sin(lo + width)}};
    }

    /// Every member faces (n . (t - f) >= 0) from every point f of the
    /// convex hull of `from` to every point t of the hull of `to`. Checked
    /// at the arc's two end normals and the points' differences: the
    /// condition is linear in n and in t - f, and an arc narrower than pi
    /// lies in the half circle of any w its two ends are positive on.
    template <size_t A, size_t B>
    bool faces_all(const std::array<Vec2, A>& from, const std::array<Vec2, B>& to) const {
        return !empty() && width < std::numbers::pi && all_signed(ends(), from, to, 1.0);
    }
    /// No member faces any point of `to` from any point of `from` (an empty
    /// cone faces nothing).
    template <size_t A, size_t B>
    bool faces_none(const std::array<Vec2, A>& from, const std::array<Vec2, B>& to) const {
        return empty() || (width < std::numbers::pi && all_signed(ends(), from, to, -1.0));
    }

    /// Whether every member faces direction u, and by how much: the
    /// smallest n . u over the members (the sine of the angle u can turn,
    /// either way, before a member stops facing it); negative when some
    /// member does not face u, or the arc is pi or wider (no direction is
    /// faced by all). n . u is concave in the angle over an arc narrower
    /// than pi inside the facing half circle, so its minimum is at an end.
    double facing_margin(Vec2 u) const {
        if (empty() || !(width < std::numbers::pi)) return -1;
        return margin(ends(), u);
    }

    /// For members that all face u (facing_margin(u) >= 0): over the
    /// directions u' within `delta` of u, how far a sum of lobes sum_i w_i
    /// cos+(n_i . u') (w_i >= 0) can leave its linear part (sum_i w_i n_i)
    /// . u', per unit of |sum_i w_i n_i|. A member of margin m turns away
    /// by at most sin(delta - m); the total weight is at most |sum_i w_i
    /// n_i| / cos(width / 2), every normal being within width / 2 of the
    /// arc's middle. 0 when every member faces every such u'; negative when
    /// not every member faces u.
    double linear_departure(Vec2 u, double delta) const { return departure(facing_margin(u), delta); }

    /// The three answers above between regions `from` and `to`, for the
    /// direction u between them and a spread delta, with the arc's ends
    /// computed once (the hierarchical solver asks them for every link).
    struct Facing {
        bool none = true;        ///< faces_none(from, to)
        bool all = false;        ///< faces_all(from, to)
        double departure = -1;   ///< linear_departure(u, delta)
    };
    template <size_t A, size_t B>
    Facing facing(const std::array<Vec2, A>& from, const std::array<Vec2, B>& to, Vec2 u, double delta) const {
        Facing f;
        if (empty()) return f;
        f.none = false;
        if (!(width < std::numbers::pi)) return f;
        const std::pair<Vec2, Vec2> e = ends();
        f.none = all_signed(e, from, to, -1.0);
        f.all = all_signed(e, from, to, 1.0);
        f.departure = departure(margin(e, u), delta);
        return f;
    }

private:
    static double margin(const std::pair<Vec2, Vec2>& e, Vec2 u) { return std::min(dot(e.first, u), dot(e.second, u)); }
    double departure(double m, double delta) const {
        if (!(m >= 0)) return -1;
        const double turn = std::clamp(delta - std::asin(std::min(1.0, m)), 0.0, 0.5 * std::numbers::pi);
        return std::sin(turn) / std::cos(0.5 * width);
    }
    template <size_t A, size_t B>
    static bool all_signed(const std::pair<Vec2, Vec2>& e, const std::array<Vec2, A>& from, const std::array<Vec2, B>& to,
                           double sign) {
        const auto [n0, n1] = e;
        for (const Vec2 f : from)
            for (const Vec2 t : to) {
                const Vec2 w = t - f;
                if (!(sign * dot(n0, w) >= 0 && sign * dot(n1, w) >= 0)) return false;
            }
        return true;
    }
};

}  // namespace flatrad
