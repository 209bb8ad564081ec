#pragma once
// Arithmetic on several contacts at once. The pair kernel is written once for a lane type V:
// `double` (one contact; 3-vectors are Eigen's Vec3), or Lanes2 / Lanes4 (two or four contacts
// side by side, one vector per quantity; 3-vectors are Lanes3<V>). Every operation is the IEEE
// operation of each lane — no fused multiply-add, no reassociation, the operands in the order
// the scalar code uses — so a contact gets bit for bit the same result in any lane of any
// width as it gets alone as a double. Branches of the scalar code become `select`s that
// compute both sides.
//
// Why lanes: a touching pair's force is one long chain of dependent operations (a square root,
// a division, the spring's rotation with another of each, the Hertz coefficients with two more
// square roots), about 150 cycles from the positions to the force, and one pair's chain fills
// the processor's reorder window, so consecutive pairs hardly overlap. Lanes run several
// pairs' chains in the same instructions.
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "dem/core/types.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__AVX__)
#include <immintrin.h>
#endif

// Every function here is inlined: that a Lanes4 would be passed in AVX registers by an
// out-of-line call, and in memory without AVX, does not matter.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace grainflow {

// Vectors of doubles (GCC/Clang vector extension: +, -, *, / per lane, and a scalar operand
// is applied to every lane). Without AVX a Lanes4 is two SSE2 registers, with AVX one. A
// comparison gives a mask of 64-bit integers, all bits set or clear.
using Lanes2 = double __attribute__((vector_size(16)));
using Lanes4 = double __attribute__((vector_size(32)));
using Mask2 = decltype(Lanes2{} < Lanes2{});

// 2K contacts as K Lanes2: K independent chains of SSE2 instructions side by side in one
// instruction stream, which the processor overlaps (GCC's own Lanes4 without AVX moves its
// halves through memory).
template <int K>
struct Lanes2xK {
  Lanes2 part[K];
  double operator[](int k) const { return part[k / 2][k % 2]; }
};
template <int K>
struct Mask2xK {
  Mask2 part[K];
};
#define GRAINFLOW_LANES2XK(op, R)                                                              \
  template <int K>                                                                             \
  [[gnu::always_inline]] inline R<K> operator op(const Lanes2xK<K>& a, const Lanes2xK<K>& b) { \
    R<K> r;                                                                                    \
    _Pragma("GCC unroll 8") for (int q = 0; q < K; ++q) r.part[q] = a.part[q] op b.part[q];    \
    return r;                                                                                  \
  }                                                                                            \
  template <int K>                                                                             \
  [[gnu::always_inline]] inline R<K> operator op(const Lanes2xK<K>& a, double b) {             \
    R<K> r;                                                                                    \
    _Pragma("GCC unroll 8") for (int q = 0; q < K; ++q) r.part[q] = a.part[q] op b;            \
    return r;                                                                                  \
  }                                                                                            \
  template <int K>                                                                             \
  [[gnu::always_inline]] inline R<K> operator op(double a, const Lanes2xK<K>& b) {             \
    R<K> r;                                                                                    \
    _Pragma("GCC unroll 8") for (int q = 0; q < K; ++q) r.part[q] = a op b.part[q];            \
    return r;                                                                                  \
  }
GRAINFLOW_LANES2XK(+, Lanes2xK)
GRAINFLOW_LANES2XK(-, Lanes2xK)
GRAINFLOW_LANES2XK(*, Lanes2xK)
GRAINFLOW_LANES2XK(/, Lanes2xK)
GRAINFLOW_LANES2XK(<, Mask2xK)
GRAINFLOW_LANES2XK(>, Mask2xK)
GRAINFLOW_LANES2XK(==, Mask2xK)
#undef GRAINFLOW_LANES2XK
template <int K>
[[gnu::always_inline]] inline Lanes2xK<K> operator-(const Lanes2xK<K>& a) {
  Lanes2xK<K> r;
  for (int q = 0; q < K; ++q) r.part[q] = -a.part[q];
  return r;
}
using Lanes2x2 = Lanes2xK<2>;

template <class V>
struct IsLanes2xK : std::false_type {};
template <int K>
struct IsLanes2xK<Lanes2xK<K>> : std::true_type {};
template <class V>
concept LaneVector = std::is_same_v<V, Lanes2> || std::is_same_v<V, Lanes4> || IsLanes2xK<V>::value;
template <class V>
inline constexpr int lane_count = std::is_same_v<V, double> ? 1 : sizeof(V) / sizeof(double);

[[gnu::always_inline]] inline Lanes2 lane_sqrt(Lanes2 a) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(a);
#else
  return Lanes2{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
[[gnu::always_inline]] inline Lanes4 lane_sqrt(Lanes4 a) {
#if defined(__AVX__)
  return _mm256_sqrt_pd(a);
#else
  const Lanes2 lo = lane_sqrt(Lanes2{a[0], a[1]}), hi = lane_sqrt(Lanes2{a[2], a[3]});
  return Lanes4{lo[0], lo[1], hi[0], hi[1]};
#endif
}
template <int K>
[[gnu::always_inline]] inline Lanes2xK<K> lane_sqrt(const Lanes2xK<K>& a) {
  Lanes2xK<K> r;
  for (int q = 0; q < K; ++q) r.part[q] = lane_sqrt(a.part[q]);
  return r;
}
template <int K>
[[gnu::always_inline]] inline Lanes2xK<K> select(const Mask2xK<K>& m, const Lanes2xK<K>& a,
                                                 const Lanes2xK<K>& b) {
  Lanes2xK<K> r;
  for (int q = 0; q < K; ++q) r.part[q] = m.part[q] ? a.part[q] : b.part[q];
  return r;
}
template <int K>
[[gnu::always_inline]] inline bool any(const Mask2xK<K>& m) {
  Mask2 r = m.part[0];
  for (int q = 1; q < K; ++q) r |= m.part[q];
  return (r[0] | r[1]) != 0;
}
template <LaneVector V, class M>
[[gnu::always_inline]] inline V select(M m, V a, V b) {
  return m ? a : b;
}
template <class M>
[[gnu::always_inline]] inline bool any(M m) {
  bool r = false;
  for (int k = 0; k < static_cast<int>(sizeof(M) / 8); ++k) r |= m[k] != 0;
  return r;
}
// std::max(a, 0.0) lane by lane: a unless a < 0 (a NaN stays NaN).
template <LaneVector V>
[[gnu::always_inline]] inline V max0(V a) {
  return select(a < 0.0, V{}, a);
}

inline double lane_sqrt(double a) { return std::sqrt(a); }
inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline double max0(double a) { return std::max(a, 0.0); }

// A 3-vector of lanes, with the Eigen operations the kernel uses, component by component in
// Eigen's order (dot and squared norm as (x + y) + z, the cross product as Eigen writes it).
template <LaneVector V>
struct Lanes3 {
  V x, y, z;
};
#define GRAINFLOW_LANES3(op)                                                                    \
  template <LaneVector V>                                                                       \
  [[gnu::always_inline]] inline Lanes3<V> operator op(const Lanes3<V>& a, const Lanes3<V>& b) { \
    return {a.x op b.x, a.y op b.y, a.z op b.z};                                                \
  }
GRAINFLOW_LANES3(+)
GRAINFLOW_LANES3(-)
#undef GRAINFLOW_LANES3
template <LaneVector V>
[[gnu::always_inline]] inline Lanes3<V> operator-(const Lanes3<V>& a) {
  return {-a.x, -a.y, -a.z};
}
template <LaneVector V, class S>
[[gnu::always_inline]] inline Lanes3<V> operator*(S s, const Lanes3<V>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <LaneVector V, class S>
[[gnu::always_inline]] inline Lanes3<V> operator*(const Lanes3<V>& a, S s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <LaneVector V, class S>
[[gnu::always_inline]] inline Lanes3<V> operator/(const Lanes3<V>& a, S s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <LaneVector V>
[[gnu::always_inline]] inline Lanes3<V>& operator+=(Lanes3<V>& a, const Lanes3<V>& b) {
  return a = a + b;
}
template <LaneVector V>
[[gnu::always_inline]] inline Lanes3<V>& operator-=(Lanes3<V>& a, const Lanes3<V>& b) {
  return a = a - b;
}
template <LaneVector V, class S>
[[gnu::always_inline]] inline Lanes3<V>& operator*=(Lanes3<V>& a, S s) {
  return a = a * s;
}
template <LaneVector V>
[[gnu::always_inline]] inline V dot(const Lanes3<V>& a, const Lanes3<V>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
template <LaneVector V>
[[gnu::always_inline]] inline V squared_norm(const Lanes3<V>& a) {
  return dot(a, a);
}
template <LaneVector V>
[[gnu::always_inline]] inline Lanes3<V> cross(const Lanes3<V>& a, const Lanes3<V>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <LaneVector V, class M>
[[gnu::always_inline]] inline Lanes3<V> select(M m, const Lanes3<V>& a, const Lanes3<V>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

inline double dot(const Vec3& a, const Vec3& b) { return a.dot(b); }
inline double squared_norm(const Vec3& a) { return a.squaredNorm(); }
inline Vec3 cross(const Vec3& a, const Vec3& b) { return a.cross(b); }
inline Vec3 select(bool m, const Vec3& a, const Vec3& b) { return m ? a : b; }

// The 3-vector of a lane type, and its zero.
template <class V>
struct V3Of {
  using type = Lanes3<V>;
};
template <>
struct V3Of<double> {
  using type = Vec3;
};
template <class V>
using V3 = typename V3Of<V>::type;
template <class V>
[[gnu::always_inline]] inline V3<V> zero3() {
  if constexpr (std::is_same_v<V, double>)
    return Vec3::Zero();
  else
    return Lanes3<V>{V{}, V{}, V{}};
}

// The values of W contacts into the lanes of one: get(l) gives lane l's value.
template <class V, class Get>
[[gnu::always_inline]] inline V gather(Get get) {
  if constexpr (std::is_same_v<V, Lanes2>) {
    return V{get(0), get(1)};
  } else if constexpr (std::is_same_v<V, Lanes4>) {
    return V{get(0), get(1), get(2), get(3)};
  } else {
    V r;
#pragma GCC unroll 8
    for (int q = 0; q < lane_count<V> / 2; ++q) r.part[q] = Lanes2{get(2 * q), get(2 * q + 1)};
    return r;
  }
}
template <class V, class Get>
[[gnu::always_inline]] inline Lanes3<V> gather3(Get get) {
  return {gather<V>([&](int l) { return get(l)[0]; }), gather<V>([&](int l) { return get(l)[1]; }),
          gather<V>([&](int l) { return get(l)[2]; })};
}
template <LaneVector V>
[[gnu::always_inline]] inline V broadcast(double a) {
  return gather<V>([a](int) { return a; });
}
template <LaneVector V>
[[gnu::always_inline]] inline Vec3 lane(const Lanes3<V>& a, int k) {
  return Vec3(a.x[k], a.y[k], a.z[k]);
}

}  // namespace grainflow

#pragma GCC diagnostic pop
