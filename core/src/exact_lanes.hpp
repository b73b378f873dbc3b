// exact_lanes.hpp - the wider lanes the accurate mode evaluates the law in,
// and the error-free transformations that build them, written once over the
// lane type of lanes.hpp.
//
// Design notes
// ------------
// The accurate mode (collide::Accuracy::accurate) runs the one kernel body of
// contact_kernel.hpp on wider lanes and rounds the results once:
//   * float  lanes -> double lanes of the same width (stdx::rebind_simd_t):
//     products of two floats are exact in double, and 29 more bits absorb
//     the cancellation of every family we know (grazing 1e-7, needles 1e-12,
//     levers 1e4) with room to spare;
//   * double lanes -> DoubleDouble<V>, an unevaluated sum hi + lo of two
//     doubles (about 106 bits), built from the error-free transformations
//     below.
// Error-free transformations (Knuth's TwoSum, Dekker's FastTwoSum, Veltkamp's
// split and Dekker's TwoProduct) use only IEEE add, sub and mul, each
// correctly rounded: no FMA (the build forbids contraction, and the SSE2
// baseline has none), so every lane, the scalar tail and every ISA compute
// the same bits. The double-double arithmetic is the "accurate" variant
// (two TwoSums per addition, as in Li et al.'s QD library, ieee_add), whose
// relative error stays within a few 2^-106 even when the operands cancel -
// the sloppy one-TwoSum variant does not, and cancellation is the point.
//
// Range: Veltkamp's split multiplies by 2^27 + 1, so double-double products
// need operands below about 2^996 in magnitude; every finite input the law
// meets in practice is far inside, and the lo part of values below about
// 2^-969 loses bits to underflow (the result is then as good as double).
#pragma once

#include <cstddef>
#include <type_traits>

#include "lanes.hpp"

namespace collide::detail {
inline namespace COLLIDE_KERNEL_NS {

// The outputs of these may alias their inputs (fast_two_sum(s, e, s, e)
// renormalises in place), so every result is formed in locals first.

/// s + e = a + b exactly, s = fl(a + b) (Knuth; any a, b).
template <class V>
COLLIDE_LANE_INLINE void two_sum(const V& a, const V& b, V& s, V& e) {
  const V sum = a + b;
  const V bb = sum - a;
  const V err = (a - (sum - bb)) + (b - bb);
  s = sum;
  e = err;
}

/// s + e = a + b exactly when |a| >= |b| or a == 0 (Dekker).
template <class V>
COLLIDE_LANE_INLINE void fast_two_sum(const V& a, const V& b, V& s, V& e) {
  const V sum = a + b;
  const V err = b - (sum - a);
  s = sum;
  e = err;
}

/// hi + lo = a with hi holding the upper half of the significand (Veltkamp).
template <class V>
COLLIDE_LANE_INLINE void split(const V& a, V& hi, V& lo) {
  using T = typename V::value_type;
  const T factor = std::is_same_v<T, double> ? T(134217729.0) : T(4097.0);  // 2^27 + 1, 2^12 + 1
  const V c = V(factor) * a;
  hi = c - (c - a);
  lo = a - hi;
}

/// p + e = a * b exactly, p = fl(a * b) (Dekker), without FMA.
template <class V>
COLLIDE_LANE_INLINE void two_product(const V& a, const V& b, V& p, V& e) {
  const V prod = a * b;
  V ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  e = ((ah * bh - prod) + ah * bl + al * bh) + al * bl;
  p = prod;
}

/// hi + lo, normalised so that hi = fl(hi + lo): rounding to the lane's
/// precision is taking hi.
template <class V>
struct DoubleDouble {
  using value_type = typename V::value_type;
  using mask_type = typename V::mask_type;
  static constexpr std::size_t size() { return V::size(); }

  V hi, lo;

  DoubleDouble() = default;
  explicit DoubleDouble(value_type x) : hi(x), lo(value_type(0)) {}
  DoubleDouble(const V& h, const V& l) : hi(h), lo(l) {}
};

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> operator-(const DoubleDouble<V>& a) {
  return {-a.hi, -a.lo};
}

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> operator+(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  V s, e, t, f;
  two_sum(a.hi, b.hi, s, e);
  two_sum(a.lo, b.lo, t, f);
  e = e + t;
  fast_two_sum(s, e, s, e);
  e = e + f;
  fast_two_sum(s, e, s, e);
  return {s, e};
}

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> operator-(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return a + (-b);
}

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> operator*(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  V p, e;
  two_product(a.hi, b.hi, p, e);
  e = e + (a.hi * b.lo + a.lo * b.hi);
  fast_two_sum(p, e, p, e);
  return {p, e};
}

/// a times a plain double (one TwoProduct fewer than DoubleDouble * DoubleDouble).
template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> times(const DoubleDouble<V>& a, const V& b) {
  V p, e;
  two_product(a.hi, b, p, e);
  e = e + a.lo * b;
  fast_two_sum(p, e, p, e);
  return {p, e};
}

/// Long division with three partial quotients (QD's accurate division).
template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> operator/(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  const V q1 = a.hi / b.hi;
  DoubleDouble<V> r = a - times(b, q1);
  const V q2 = r.hi / b.hi;
  r = r - times(b, q2);
  const V q3 = r.hi / b.hi;
  V s, e;
  fast_two_sum(q1, q2, s, e);
  return DoubleDouble<V>{s, e} + DoubleDouble<V>{q3, V(0)};
}

template <class V>
COLLIDE_LANE_INLINE typename V::mask_type operator<(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return (a.hi < b.hi) || ((a.hi == b.hi) && (a.lo < b.lo));
}
template <class V>
COLLIDE_LANE_INLINE typename V::mask_type operator>(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return b < a;
}
template <class V>
COLLIDE_LANE_INLINE typename V::mask_type operator==(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return (a.hi == b.hi) && (a.lo == b.lo);
}
template <class V>
COLLIDE_LANE_INLINE typename V::mask_type operator!=(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return !(a == b);
}

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> select(const typename V::mask_type& m, const DoubleDouble<V>& a,
                                           const DoubleDouble<V>& b) {
  return {select(m, a.hi, b.hi), select(m, a.lo, b.lo)};
}

template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> lane_min(const DoubleDouble<V>& a, const DoubleDouble<V>& b) {
  return select(b < a, b, a);
}

/// One Newton step on the double square root; 0 for 0 (and the kernel only
/// takes square roots of sums of squares).
template <class V>
COLLIDE_LANE_INLINE DoubleDouble<V> lane_sqrt(const DoubleDouble<V>& a) {
  const V s = stdx::sqrt(a.hi);
  V p, e;
  two_product(s, s, p, e);
  const DoubleDouble<V> r = a - DoubleDouble<V>{p, e};
  const V correction = r.hi / (V(2) * s);
  V hi, lo;
  fast_two_sum(s, correction, hi, lo);
  const auto zero = a.hi == V(0);
  return {select(zero, V(0), hi), select(zero, V(0), lo)};
}

/// The lanes the accurate mode evaluates lanes V in, and the conversions:
/// widen is exact, narrow rounds once to nearest.
template <class V, class T = typename V::value_type>
struct AccurateLanes;

template <class V>
struct AccurateLanes<V, float> {
  using type = stdx::rebind_simd_t<double, V>;
  static COLLIDE_LANE_INLINE type widen(const V& v) { return stdx::static_simd_cast<type>(v); }
  static COLLIDE_LANE_INLINE V narrow(const type& w) { return stdx::static_simd_cast<V>(w); }
};

template <class V>
struct AccurateLanes<V, double> {
  using type = DoubleDouble<V>;
  static COLLIDE_LANE_INLINE type widen(const V& v) { return {v, V(0)}; }
  static COLLIDE_LANE_INLINE V narrow(const type& w) { return w.hi; }
};

}  // namespace COLLIDE_KERNEL_NS
}  // namespace collide::detail
