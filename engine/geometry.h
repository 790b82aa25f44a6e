#pragma once
/// 2D points, vectors, segments and boxes, with the robust small formulas the
/// kernels lean on (STYLE.md, "Keeping the numerics honest").
///
/// Conventions: a segment [a, b] has direction b - a; its *left* side is the
/// side of left_normal() = rot90(b - a), counter-clockwise. Every oriented
/// patch in flatrad is stored so that its lit side is on the left.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace flatrad {

struct Vec2 {
    double x = 0, y = 0;

    constexpr Vec2() = default;
    constexpr Vec2(double x_, double y_) : x(x_), y(y_) {}

    constexpr Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
    constexpr Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
    constexpr Vec2 operator-() const { return {-x, -y}; }
    constexpr Vec2 operator*(double s) const { return {x * s, y * s}; }
    constexpr Vec2 operator/(double s) const { return {x / s, y / s}; }
    constexpr Vec2& operator+=(Vec2 o) { x += o.x; y += o.y; return *this; }
    constexpr Vec2& operator-=(Vec2 o) { x -= o.x; y -= o.y; return *this; }
    constexpr bool operator==(const Vec2&) const = default;
};

constexpr Vec2 operator*(double s, Vec2 v) { return {s * v.x, s * v.y}; }

inline double dot(Vec2 u, Vec2 v) { return u.x * v.x + u.y * v.y; }

/// a*b - c*d with one rounding error (Kahan's FMA trick): the 2D cross
/// product and orientation tests cancel badly without it.
inline double difference_of_products(double a, double b, double c, double d) {
    const double cd = c * d;
    const double err = std::fma(-c, d, cd);
    const double dop = std::fma(a, b, -cd);
    return dop + err;
}

/// z-component of u x v, positive when v is counter-clockwise from u.
inline double cross(Vec2 u, Vec2 v) { return difference_of_products(u.x, v.y, u.y, v.x); }

inline double norm_squared(Vec2 v) { return v.x * v.x + v.y * v.y; }
/// |v|; coordinates stay within 1e-150..1e150 (the scene reader refuses
/// nothing finite, but squares of anything in 1e-9..1e9 are far from
/// overflow and underflow), so no scaling is needed.
inline double norm(Vec2 v) { return std::sqrt(norm_squared(v)); }
inline double distance(Vec2 u, Vec2 v) { return norm(u - v); }
inline Vec2 rot90(Vec2 v) { return {-v.y, v.x}; }  // counter-clockwise
inline Vec2 lerp(Vec2 a, Vec2 b, double t) { return a + (b - a) * t; }

/// Orientation of c relative to the directed line a -> b: > 0 left, < 0 right.
inline double orient(Vec2 a, Vec2 b, Vec2 c) { return cross(b - a, c - a); }

struct Segment {
    Vec2 a, b;

    Vec2 direction() const { return b - a; }
    double length() const { return distance(a, b); }
    Vec2 midpoint() const { return (a + b) * 0.5; }
    /// Unit normal on the left of a -> b.
    Vec2 left_normal() const {
        const Vec2 d = b - a;
        return rot90(d) / norm(d);
    }
    Segment reversed() const { return {b, a}; }
};

/// Axis-aligned box; empty() until something is added.
struct Box {
    Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    Vec2 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};

    bool empty() const { return lo.x > hi.x; }
    void add(Vec2 p) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    void add(const Box& b) {
        if (b.empty()) return;
        add(b.lo);
        add(b.hi);
    }
    void add(const Segment& s) { add(s.a); add(s.b); }
    Vec2 center() const { return (lo + hi) * 0.5; }
    Vec2 extent() const { return hi - lo; }
    double diagonal() const { return empty() ? 0.0 : norm(hi - lo); }
    /// Whether p lies in the closed box.
    bool holds(Vec2 p) const { return lo.x <= p.x && p.x <= hi.x && lo.y <= p.y && p.y <= hi.y; }
};

/// The bounding box of one segment.
inline Box box_of(const Segment& s) {
    Box b;
    b.add(s);
    return b;
}

/// Whether two closed boxes share no point (exact comparisons).
inline bool boxes_apart(const Box& p, const Box& q) {
    return p.hi.x < q.lo.x || q.hi.x < p.lo.x || p.hi.y < q.lo.y || q.hi.y < p.lo.y;
}

/// The part of the segment from p to q inside the closed box b: its
/// parameter range [t0, t1] along p + t (q - p), clipped from [0, 1] to
/// each axis' slab (Liang and Barsky 1984; an axis along which the segment
/// does not move needs p within the slab). False when the segment misses
/// b (t0 and t1 are then meaningless).
inline bool clip_to_box(Vec2 p, Vec2 q, const Box& b, double& t0, double& t1) {
    if (b.empty()) return false;
    t0 = 0;
    t1 = 1;
    auto clip = [&](double p0, double d, double lo, double hi) {
        if (d == 0) return p0 >= lo && p0 <= hi;
        double ta = (lo - p0) / d, tb = (hi - p0) / d;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        return t0 <= t1;
    };
    return clip(p.x, q.x - p.x, b.lo.x, b.hi.x) && clip(p.y, q.y - p.y, b.lo.y, b.hi.y);
}

/// Whether the segment from p to q meets the closed box b.
inline bool segment_meets_box(Vec2 p, Vec2 q, const Box& b) {
    double t0, t1;
    return clip_to_box(p, q, b, t0, t1);
}

}  // namespace flatrad
