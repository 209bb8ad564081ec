#pragma once
// Arithmetic on several contacts at once. The pair kernel is written once for a lane type V:
// `double` (one contact; 3-vectors are Eigen's Vec3) or `Lanes2` (two contacts side by side,
// one SSE2 register per quantity; 3-vectors are Lanes3). Every operation is the IEEE operation
// of each lane — no fused multiply-add, no reassociation, the operands in the order the scalar
// code uses — so a contact gets bit for bit the same result in either lane of a Lanes2 as it
// gets alone as a double. Branches of the scalar code become `select`s that compute both sides.
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "dem/core/types.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace grainflow {

// Two doubles in one vector register (GCC/Clang vector extension: +, -, *, / per lane, and a
// scalar operand is applied to both lanes). A comparison gives a Mask2 (all bits set or clear).
using Lanes2 = double __attribute__((vector_size(16)));
using Mask2 = decltype(Lanes2{} < Lanes2{});  // 64-bit integer lanes

inline Lanes2 lane_sqrt(Lanes2 a) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(a);
#else
  return Lanes2{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
inline Lanes2 select(Mask2 m, Lanes2 a, Lanes2 b) { return m ? a : b; }
inline bool any(Mask2 m) { return (m[0] | m[1]) != 0; }
// std::max(a, 0.0) lane by lane: a unless a < 0 (a NaN stays NaN).
inline Lanes2 max0(Lanes2 a) { return select(a < 0.0, Lanes2{0.0, 0.0}, a); }

inline double lane_sqrt(double a) { return std::sqrt(a); }
inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline double max0(double a) { return std::max(a, 0.0); }

// A 3-vector of lanes, with the Eigen operations the kernel uses, component by component in
// Eigen's order (dot and squared norm as (x + y) + z, the cross product as Eigen writes it).
struct Lanes3 {
  Lanes2 x, y, z;
};
inline Lanes3 operator+(const Lanes3& a, const Lanes3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Lanes3 operator-(const Lanes3& a, const Lanes3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Lanes3 operator-(const Lanes3& a) { return {-a.x, -a.y, -a.z}; }
inline Lanes3 operator*(Lanes2 s, const Lanes3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline Lanes3 operator*(const Lanes3& a, Lanes2 s) { return {a.x * s, a.y * s, a.z * s}; }
inline Lanes3 operator/(const Lanes3& a, Lanes2 s) { return {a.x / s, a.y / s, a.z / s}; }
inline Lanes3 operator*(double s, const Lanes3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline Lanes3 operator*(const Lanes3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Lanes3& operator+=(Lanes3& a, const Lanes3& b) { return a = a + b; }
inline Lanes3& operator-=(Lanes3& a, const Lanes3& b) { return a = a - b; }
inline Lanes3& operator*=(Lanes3& a, Lanes2 s) { return a = a * s; }
inline Lanes2 dot(const Lanes3& a, const Lanes3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
inline Lanes2 squared_norm(const Lanes3& a) { return dot(a, a); }
inline Lanes3 cross(const Lanes3& a, const Lanes3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Lanes3 select(Mask2 m, const Lanes3& a, const Lanes3& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

inline double dot(const Vec3& a, const Vec3& b) { return a.dot(b); }
inline double squared_norm(const Vec3& a) { return a.squaredNorm(); }
inline Vec3 cross(const Vec3& a, const Vec3& b) { return a.cross(b); }
inline Vec3 select(bool m, const Vec3& a, const Vec3& b) { return m ? a : b; }

// The 3-vector of a lane type, and its zero.
template <class V>
using V3 = std::conditional_t<std::is_same_v<V, double>, Vec3, Lanes3>;
template <class V>
V3<V> zero3() {
  if constexpr (std::is_same_v<V, double>)
    return Vec3::Zero();
  else
    return Lanes3{V{0.0, 0.0}, V{0.0, 0.0}, V{0.0, 0.0}};
}

// Two contacts' values into the lanes of one, and back.
inline Lanes2 pack(double a, double b) { return Lanes2{a, b}; }
inline Lanes3 pack(const Vec3& a, const Vec3& b) {
  return {Lanes2{a[0], b[0]}, Lanes2{a[1], b[1]}, Lanes2{a[2], b[2]}};
}
inline Vec3 lane(const Lanes3& a, int k) { return Vec3(a.x[k], a.y[k], a.z[k]); }

}  // namespace grainflow
