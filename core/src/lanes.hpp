// lanes.hpp - the private, width-generic lane type the kernels are written in.
//
// Design notes
// ------------
// The physics is written once (contact_kernel.hpp) over a lane type V that
// holds W values of float or double. Two lane types exist:
//   * ScalarLanes<T>: std::experimental::simd with the scalar ABI, W = 1;
//   * SimdLanes<T>:   std::experimental::simd with the native ABI of the
//     ISA the file is compiled for (SSE2: 4 float / 2 double; AVX2: 8 / 4;
//     AVX-512: 16 / 8).
// Both are the same class template, so one kernel body instantiates for both
// with no second copy of the math. std::experimental::simd (GCC's libstdc++,
// Parallelism TS 2) was chosen over hand-written intrinsics and over Eigen
// fixed-size arrays because it is width-generic by construction, has masks and
// `where`, costs no dependency, and runs as fast as raw AVX2 intrinsics and
// Eigen fixed-size arrays on the same arithmetic (bench/lane_layer.cpp
// measures the three; docs/decisions/0003-the-lane-layer.md has the figures).
//
// AVX2 has gathers but no scatters, and its vgatherdps is slower on AMD
// cores than W scalar loads and inserts (docs/decisions/0003-the-lane-layer.md
// has the measurement), so gather() is a generator constructor (W scalar
// loads) and scatter() W scalar stores.
//
// Floating point: every operation here is an IEEE add, sub, mul, div, sqrt,
// min or compare, each correctly rounded; with -ffp-contract=off nothing is
// fused, so a lane computes bit for bit what the scalar path computes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <experimental/simd>
#include <limits>
#include <type_traits>
#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

// The inline namespace every kernel template lives in: the ISA the including
// file is compiled for (the kernel units of kernel/loops.hpp are compiled
// once per ISA with COLLIDE_KERNEL_NS=sse2, avx2, avx512; see
// core/CMakeLists.txt). Templates of one
// ISA thus never share a mangled name with those of another, and the linker
// cannot hand a narrower path a copy compiled for a wider ISA. Code that is not
// a per-ISA kernel (tests, benchmarks) gets `host`, its own target's lanes.
#ifndef COLLIDE_KERNEL_NS
#define COLLIDE_KERNEL_NS host
#endif

// Everything a kernel body calls is forced inline: GCC's heuristics give up
// on functions that take several 8-lane structs, and an out-of-line call
// passes them through memory, which the kernel pays for on every group
// (gather_bodies out of line: docs/decisions/0003-the-lane-layer.md). Two
// exceptions, each measured: load_streams_out_of_line (kernel/loops.hpp),
// where three kinds of loads met inside the law and made it spill (decision
// 0035), and the double accurate law (contact_kernel.hpp, decision 0032). The
// loops are functions of their own, one per choice of the table, never inlined.
#define COLLIDE_LANE_INLINE inline __attribute__((always_inline))
// The same for the lambdas a kernel passes to its field visitors.
#define COLLIDE_LANE_LAMBDA __attribute__((always_inline))

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

namespace stdx = std::experimental;

template <class T>
using ScalarLanes = stdx::simd<T, stdx::simd_abi::scalar>;
template <class T>
using SimdLanes = stdx::native_simd<T>;

/// b where the mask is false, a where it is true.
template <class V>
COLLIDE_LANE_INLINE V select(const typename V::mask_type& m, const V& a, const V& b) {
  V r = b;
  stdx::where(m, r) = a;
  return r;
}

/// W consecutive values starting at p.
template <class V>
COLLIDE_LANE_INLINE V load(const typename V::value_type* p) {
  return V(p, stdx::element_aligned);
}

template <class V>
COLLIDE_LANE_INLINE void store(const V& v, typename V::value_type* p) {
  v.copy_to(p, stdx::element_aligned);
}

/// base[idx[0]], ..., base[idx[W-1]].
template <class V, class Index>
COLLIDE_LANE_INLINE V gather(const typename V::value_type* base, const Index* idx) {
  return V([&](auto lane) { return base[idx[lane]]; });
}

/// base[idx[l]] = v[l] for every lane l whose `write` is true.
template <class V, class Index>
COLLIDE_LANE_INLINE void scatter(const V& v, typename V::value_type* base, const Index* idx,
                                 const typename V::mask_type& write) {
  for (std::size_t l = 0; l < V::size(); ++l) {
    if (write[l]) base[idx[l]] = v[l];
  }
}

/// Loads 2W consecutive values p[0..2W) and splits them into the even ones
/// (p[0], p[2], ...) and the odd ones (p[1], p[3], ...): the bodies of W
/// contacts laid out as pairs (2k, 2k+1), loaded with two vector loads.
template <class V>
COLLIDE_LANE_INLINE void load_deinterleaved(const typename V::value_type* p, V& even, V& odd) {
#if defined(__AVX512F__)
  // One two-source permute per output: lane l takes element 2l (or 2l + 1)
  // of the 2W values in lo:hi.
  if constexpr (std::is_same_v<V, SimdLanes<float>> && V::size() == 16) {
    const __m512 lo = _mm512_loadu_ps(p);
    const __m512 hi = _mm512_loadu_ps(p + 16);
    const __m512i ie = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    const __m512i io = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
    even = V(_mm512_permutex2var_ps(lo, ie, hi));
    odd = V(_mm512_permutex2var_ps(lo, io, hi));
    return;
  } else if constexpr (std::is_same_v<V, SimdLanes<double>> && V::size() == 8) {
    const __m512d lo = _mm512_loadu_pd(p);
    const __m512d hi = _mm512_loadu_pd(p + 8);
    const __m512i ie = _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14);
    const __m512i io = _mm512_setr_epi64(1, 3, 5, 7, 9, 11, 13, 15);
    even = V(_mm512_permutex2var_pd(lo, ie, hi));
    odd = V(_mm512_permutex2var_pd(lo, io, hi));
    return;
  }
#endif
#if defined(__AVX2__)
  if constexpr (std::is_same_v<V, SimdLanes<float>> && V::size() == 8) {
    const __m256 lo = _mm256_loadu_ps(p);
    const __m256 hi = _mm256_loadu_ps(p + 8);
    // Per 128-bit half: evens of lo, then evens of hi; then fix the halves.
    const __m256 e = _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0));
    const __m256 o = _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1));
    even = V(_mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(e), _MM_SHUFFLE(3, 1, 2, 0))));
    odd = V(_mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(o), _MM_SHUFFLE(3, 1, 2, 0))));
    return;
  } else if constexpr (std::is_same_v<V, SimdLanes<double>> && V::size() == 4) {
    const __m256d lo = _mm256_loadu_pd(p);
    const __m256d hi = _mm256_loadu_pd(p + 4);
    even = V(_mm256_permute4x64_pd(_mm256_unpacklo_pd(lo, hi), _MM_SHUFFLE(3, 1, 2, 0)));
    odd = V(_mm256_permute4x64_pd(_mm256_unpackhi_pd(lo, hi), _MM_SHUFFLE(3, 1, 2, 0)));
    return;
  }
#endif
  even = V([&](auto lane) { return p[2 * lane]; });
  odd = V([&](auto lane) { return p[2 * lane + 1]; });
}

/// The inverse of load_deinterleaved: p[2l] = even[l], p[2l+1] = odd[l].
template <class V>
COLLIDE_LANE_INLINE void store_interleaved(const V& even, const V& odd, typename V::value_type* p) {
#if defined(__AVX512F__)
  if constexpr (std::is_same_v<V, SimdLanes<float>> && V::size() == 16) {
    const __m512 e = static_cast<__m512>(even);
    const __m512 o = static_cast<__m512>(odd);
    // Indices 0-15 pick from e, 16-31 from o.
    const __m512i lo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const __m512i hi = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
    _mm512_storeu_ps(p, _mm512_permutex2var_ps(e, lo, o));
    _mm512_storeu_ps(p + 16, _mm512_permutex2var_ps(e, hi, o));
    return;
  } else if constexpr (std::is_same_v<V, SimdLanes<double>> && V::size() == 8) {
    const __m512d e = static_cast<__m512d>(even);
    const __m512d o = static_cast<__m512d>(odd);
    const __m512i lo = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11);
    const __m512i hi = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
    _mm512_storeu_pd(p, _mm512_permutex2var_pd(e, lo, o));
    _mm512_storeu_pd(p + 8, _mm512_permutex2var_pd(e, hi, o));
    return;
  }
#endif
#if defined(__AVX2__)
  if constexpr (std::is_same_v<V, SimdLanes<float>> && V::size() == 8) {
    const __m256 e =
        _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(static_cast<__m256>(even)), _MM_SHUFFLE(3, 1, 2, 0)));
    const __m256 o =
        _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(static_cast<__m256>(odd)), _MM_SHUFFLE(3, 1, 2, 0)));
    _mm256_storeu_ps(p, _mm256_unpacklo_ps(e, o));
    _mm256_storeu_ps(p + 8, _mm256_unpackhi_ps(e, o));
    return;
  } else if constexpr (std::is_same_v<V, SimdLanes<double>> && V::size() == 4) {
    const __m256d e = _mm256_permute4x64_pd(static_cast<__m256d>(even), _MM_SHUFFLE(3, 1, 2, 0));
    const __m256d o = _mm256_permute4x64_pd(static_cast<__m256d>(odd), _MM_SHUFFLE(3, 1, 2, 0));
    _mm256_storeu_pd(p, _mm256_unpacklo_pd(e, o));
    _mm256_storeu_pd(p + 4, _mm256_unpackhi_pd(e, o));
    return;
  }
#endif
  for (std::size_t l = 0; l < V::size(); ++l) {
    p[2 * l] = even[l];
    p[2 * l + 1] = odd[l];
  }
}

/// sqrt and min of lanes. The kernel body calls these rather than stdx::sqrt
/// and stdx::min, so that the accurate mode's double-double lanes
/// (exact_lanes.hpp) can bring their own. The minimum is a compare and a
/// select, a when either is NaN, on every lane type: stdx::min is std::min
/// on the scalar ABI (a NaN first argument is returned) and minps/minpd on
/// the SIMD ones (the second is), so a NaN K(t) of one contact (an overflow
/// in its lever arm) gave a NaN friction impulse on one path and mu jn on
/// the other.
template <class V>
COLLIDE_LANE_INLINE V lane_sqrt(const V& x) {
  return stdx::sqrt(x);
}
template <class V>
COLLIDE_LANE_INLINE V lane_min(const V& a, const V& b) {
  return select(b < a, b, a);
}

/// x with every NaN lane replaced by one NaN, the positive quiet NaN
/// without payload. Which NaN an operation on two NaNs returns depends on
/// the order of its operands (x86 returns the first), and the compiler may
/// order the operands of + and * differently for a scalar and a vector lane
/// type: a contact whose law overflowed gave -NaN on the scalar path and
/// +NaN on the SIMD one. The law's outputs pass through this, so a NaN
/// leaves the kernel with the same bits on every path and ISA; no operation
/// of the law depends on a NaN's sign.
template <class V>
COLLIDE_LANE_INLINE V canonical_nan(const V& x) {
  using T = typename V::value_type;
  // NOLINTNEXTLINE(misc-redundant-expression): x == x is false exactly in a NaN lane
  return select(x == x, x, V(std::numeric_limits<T>::quiet_NaN()));
}

/// A 3-vector of lanes.
template <class V>
struct Vec3 {
  V x, y, z;
};

template <class V>
COLLIDE_LANE_INLINE Vec3<V> operator+(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
COLLIDE_LANE_INLINE Vec3<V> operator-(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V>
COLLIDE_LANE_INLINE Vec3<V> operator*(const Vec3<V>& a, const V& s) {
  return {a.x * s, a.y * s, a.z * s};
}
/// Component-wise product (diagonal matrix times vector).
template <class V>
COLLIDE_LANE_INLINE Vec3<V> hadamard(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class V>
COLLIDE_LANE_INLINE V dot(const Vec3<V>& a, const Vec3<V>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class V>
COLLIDE_LANE_INLINE Vec3<V> cross(const Vec3<V>& a, const Vec3<V>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class V>
COLLIDE_LANE_INLINE Vec3<V> select(const typename V::mask_type& m, const Vec3<V>& a, const Vec3<V>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

/// A rotation matrix of lanes, row-major: r[i][j].
template <class V>
struct Mat3 {
  V r[3][3];
};

/// The rotation of the quaternion (w, x, y, z) with s = 2 / |q|^2: s = 2
/// (the default) takes q to be unit; the kernels pass 2 / |q|^2, which
/// normalises q as the law says (normalised_rotation, contact_kernel.hpp).
template <class V>
COLLIDE_LANE_INLINE Mat3<V> rotation(const V& w, const V& x, const V& y, const V& z, const V& s = V(2)) {
  const V one(1);
  const V xx = x * x, yy = y * y, zz = z * z;
  const V xy = x * y, xz = x * z, yz = y * z;
  const V wx = w * x, wy = w * y, wz = w * z;
  Mat3<V> m;
  m.r[0][0] = one - s * (yy + zz);
  m.r[0][1] = s * (xy - wz);
  m.r[0][2] = s * (xz + wy);
  m.r[1][0] = s * (xy + wz);
  m.r[1][1] = one - s * (xx + zz);
  m.r[1][2] = s * (yz - wx);
  m.r[2][0] = s * (xz - wy);
  m.r[2][1] = s * (yz + wx);
  m.r[2][2] = one - s * (xx + yy);
  return m;
}

/// R v: body frame to world frame.
template <class V>
COLLIDE_LANE_INLINE Vec3<V> to_world(const Mat3<V>& m, const Vec3<V>& v) {
  return {m.r[0][0] * v.x + m.r[0][1] * v.y + m.r[0][2] * v.z, m.r[1][0] * v.x + m.r[1][1] * v.y + m.r[1][2] * v.z,
          m.r[2][0] * v.x + m.r[2][1] * v.y + m.r[2][2] * v.z};
}

/// R^T v: world frame to body frame.
template <class V>
COLLIDE_LANE_INLINE Vec3<V> to_body(const Mat3<V>& m, const Vec3<V>& v) {
  return {m.r[0][0] * v.x + m.r[1][0] * v.y + m.r[2][0] * v.z, m.r[0][1] * v.x + m.r[1][1] * v.y + m.r[2][1] * v.z,
          m.r[0][2] * v.x + m.r[1][2] * v.y + m.r[2][2] * v.z};
}

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
