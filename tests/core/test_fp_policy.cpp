// test_fp_policy.cpp - the floating-point policy of the build (CMakeLists.txt:
// -ffp-contract=off, no -ffast-math, no FMA) that makes every path agree bit
// for bit.
//
// What this proves
// ----------------
// * The compiler was not told to relax IEEE semantics: __FAST_MATH__ and
//   __FINITE_MATH_ONLY__ are not defined, FMA instructions are not enabled
//   (__FMA__), float and double are IEEE 754 (is_iec559), and subnormals are
//   neither flushed to zero nor treated as zero at run time (MXCSR FTZ/DAZ).
// * a * b + c computed through the lane types - ScalarLanes and SimdLanes,
//   float and double, and through the lane layer's dot() and cross() - is the
//   separately rounded fl(fl(a * b) + c), on inputs chosen so that a fused
//   multiply-add gives a different answer (a = b = 1 + 2^-12 for float,
//   1 + 2^-27 for double, c = -fl(a * b): unfused 0, fused 2^-24 / 2^-54).
//   The scalar and SIMD lanes agree bit for bit on them.
// * The compiled library (not only this test's translation unit) performs
//   no contraction: on contacts where v' = v + jn * inv_m rounds differently
//   when fused, the scalar and SIMD paths of the library return the
//   separately rounded value, bit for bit, and not the fused one.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/solve.hpp"
#include "lanes.hpp"
#include "support/isa_test.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

namespace d = collide::detail;

static_assert(std::numeric_limits<float>::is_iec559, "float must be IEEE 754 binary32");
static_assert(std::numeric_limits<double>::is_iec559, "double must be IEEE 754 binary64");

TEST(FpPolicy, CompilerFlagsKeepIeeeSemantics) {
#if defined(__FAST_MATH__)
  ADD_FAILURE() << "__FAST_MATH__ is defined: the build must not use -ffast-math";
#endif
#if defined(__FINITE_MATH_ONLY__) && __FINITE_MATH_ONLY__
  ADD_FAILURE() << "__FINITE_MATH_ONLY__ is set: NaN and inf must keep their meaning";
#endif
#if defined(__FMA__) || defined(__FMA4__)
  ADD_FAILURE() << "FMA instructions are enabled (-mfma or an -march that implies it)";
#endif
  EXPECT_TRUE(std::numeric_limits<float>::has_denorm == std::denorm_present);
  EXPECT_TRUE(std::numeric_limits<double>::has_denorm == std::denorm_present);
}

TEST(FpPolicy, SubnormalsAreNotFlushed) {
#if defined(__SSE__)
  const unsigned csr = _mm_getcsr();
  EXPECT_EQ(csr & 0x8000u, 0u) << "MXCSR flush-to-zero is set";
  EXPECT_EQ(csr & 0x0040u, 0u) << "MXCSR denormals-are-zero is set";
#endif
  volatile float tiny = std::numeric_limits<float>::denorm_min();
  volatile float one = 1.0f;
  EXPECT_EQ(tiny * one, std::numeric_limits<float>::denorm_min());
  volatile double dtiny = std::numeric_limits<double>::min();
  volatile double half = 0.5;
  EXPECT_EQ(dtiny * half, std::numeric_limits<double>::min() / 2);
  EXPECT_NE(dtiny * half, 0.0);
  // Through the SIMD lanes as well.
  using V = d::SimdLanes<float>;
  const V r = V(tiny) * V(one);
  for (std::size_t l = 0; l < V::size(); ++l) EXPECT_EQ(r[l], std::numeric_limits<float>::denorm_min());
}

/// a, b with fl(a * b) != a * b, and c = -fl(a * b): unfused 0, fused the
/// rounding error of the product.
template <class T>
struct FmaWitness {
  T a, b, c;
};
template <class T>
FmaWitness<T> witness() {
  // a = b = 1 + 2^-k with 2k > mantissa bits: a*b = 1 + 2^(1-k) + 2^-2k, and
  // 2^-2k is below half an ulp of 1, so fl(a*b) = 1 + 2^(1-k).
  const int k = std::is_same_v<T, float> ? 12 : 27;
  volatile T a = T(1) + std::ldexp(T(1), -k);
  volatile T p = a * a;
  return {a, a, -p};
}

template <class T>
T unfused(T a, T b, T c) {
  volatile T p = a * b;
  volatile T s = p + c;
  return s;
}

template <class T>
void expect_witness_is_real() {
  const FmaWitness<T> w = witness<T>();
  EXPECT_EQ(unfused(w.a, w.b, w.c), T(0));
  EXPECT_NE(std::fma(w.a, w.b, w.c), T(0)) << "the inputs do not tell fused from unfused";
  EXPECT_EQ(std::fma(w.a, w.b, w.c), std::ldexp(T(1), std::is_same_v<T, float> ? -24 : -54));
}

TEST(FpPolicy, WitnessInputsDistinguishFusedFromUnfused) {
  expect_witness_is_real<float>();
  expect_witness_is_real<double>();
}

template <class V>
void expect_lanes_do_not_fuse() {
  using T = typename V::value_type;
  const FmaWitness<T> w = witness<T>();
  const T expected = unfused(w.a, w.b, w.c);
  const V a(w.a), b(w.b), c(w.c);
  const V r = a * b + c;
  for (std::size_t l = 0; l < V::size(); ++l) EXPECT_TRUE(same_bits(r[l], expected)) << "lane " << l << ": " << r[l];

  // The lane layer's dot() and cross() on the witness:
  //   dot((a, 1, 0), (b, c, 0))     = a * b + 1 * c + 0 * 0,
  //   cross((a, 1, 0), (-c, b, 0)).z = a * b - 1 * (-c),
  // both fl(a * b) + c = 0 when separately rounded, the product's rounding
  // error when fused.
  const d::Vec3<V> x{a, V(1), V(0)};
  const d::Vec3<V> y{b, c, V(0)};
  const V dt = d::dot(x, y);
  for (std::size_t l = 0; l < V::size(); ++l) EXPECT_TRUE(same_bits(dt[l], expected)) << "dot lane " << l;
  const d::Vec3<V> u{a, V(1), V(0)};
  const d::Vec3<V> v{-c, b, V(0)};
  const V cz = d::cross(u, v).z;
  for (std::size_t l = 0; l < V::size(); ++l) EXPECT_TRUE(same_bits(cz[l], expected)) << "cross lane " << l;
}

TEST(FpPolicy, LaneArithmeticIsNotContracted) {
  expect_lanes_do_not_fuse<d::ScalarLanes<float>>();
  expect_lanes_do_not_fuse<d::SimdLanes<float>>();
  expect_lanes_do_not_fuse<d::ScalarLanes<double>>();
  expect_lanes_do_not_fuse<d::SimdLanes<double>>();
}

// Random products: scalar lanes, SIMD lanes and plain separately rounded
// arithmetic agree bit for bit on a * b + c for values where fma differs.
template <class T>
void expect_random_unfused_agree() {
  using S = d::ScalarLanes<T>;
  using V = d::SimdLanes<T>;
  std::mt19937_64 g(12345);
  std::uniform_real_distribution<double> u(-10, 10);
  std::size_t discriminating = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    T a[V::size()], b[V::size()], c[V::size()];
    for (std::size_t l = 0; l < V::size(); ++l) {
      a[l] = T(u(g));
      b[l] = T(u(g));
      c[l] = T(u(g));
    }
    const V rv = d::load<V>(a) * d::load<V>(b) + d::load<V>(c);
    for (std::size_t l = 0; l < V::size(); ++l) {
      const T expected = unfused(a[l], b[l], c[l]);
      const S rs = S(a[l]) * S(b[l]) + S(c[l]);
      ASSERT_TRUE(same_bits(rv[l], expected)) << a[l] << " * " << b[l] << " + " << c[l];
      ASSERT_TRUE(same_bits(T(rs[0]), expected));
      discriminating += !same_bits(std::fma(a[l], b[l], c[l]), expected);
    }
  }
  // A good share of the random inputs would round differently if fused.
  EXPECT_GT(discriminating, 100u);
}

TEST(FpPolicy, ScalarAndSimdLanesAgreeWhereFmaWouldNot) {
  expect_random_unfused_agree<float>();
  expect_random_unfused_agree<double>();
}

// The library itself: head-on contacts (lever arms parallel to n, no spin,
// n = +x, so |n|^2 = 1 exactly) where the rigid kernel computes, in this
// order (contact_kernel.hpp, fast_normal_impulse),
//   vn = va - vb, K = (1/ma + 1/mb) + 0 + 0, jn = -((1 + e) vn) / K
//   (float: the sum, the product and the quotient in double, rounded once),
//   va' = va + jn * (1/ma),  vb' = vb - jn * (1/mb).
// The last two are multiply-adds. Inputs are drawn until fusing them would
// change va'; the library must return the separately rounded value.
template <class T>
void expect_library_unfused(Path path) {
  SCOPED_TRACE(std::string(type_name<T>()) + " " + to_string(path));
  std::mt19937_64 g(777);
  std::uniform_real_distribution<double> u(0.5, 5);
  BodyBuffer<T> bodies;
  ContactBuffer<T> contacts;
  std::vector<T> expect_va, expect_vb, fused_va;
  const std::size_t n = 4 * 8 + 3;  // full groups and a tail
  while (contacts.size() < n) {
    BodyRecord<T> a, b;
    a.m = T(u(g));
    b.m = T(u(g));
    a.p[0] = 1;
    b.p[0] = -1;
    a.v[0] = -T(u(g));
    b.v[0] = T(u(g));
    const T e = T(u(g) / 5);
    // What the kernel will compute, separately rounded.
    const T inv_ma = T(1) / a.m, inv_mb = T(1) / b.m;
    volatile T vn = a.v[0] - b.v[0];
    volatile T jn;
    if constexpr (std::is_same_v<T, float>) {
      volatile double k = (double(inv_ma) + double(inv_mb)) * 1.0;
      volatile double num = (1.0 + double(e)) * double(vn);
      jn = static_cast<float>(-num / k);
    } else {
      volatile T k = inv_ma + inv_mb;
      volatile T num = (T(1) + e) * vn;
      jn = -num / k;
    }
    const T va = unfused(T(jn), inv_ma, a.v[0]);
    const T vb = unfused(-T(jn), inv_mb, b.v[0]);  // vb - jn*inv_mb: -(jn*inv_mb) + vb
    const T fa = std::fma(T(jn), inv_ma, a.v[0]);
    if (same_bits(va, fa)) continue;  // not discriminating
    const auto ia = static_cast<BodyIndex>(bodies.size());
    bodies.push_back(a);
    bodies.push_back(b);
    // The stored inverse mass must be the one used above.
    ASSERT_TRUE(same_bits(std::as_const(bodies).view().inv_mass[ia], inv_ma));
    ContactRecord<T> c;
    c.a = ia;
    c.b = ia + 1;
    c.n[0] = 1, c.n[1] = 0, c.n[2] = 0;
    c.e = e;
    contacts.push_back(c);
    expect_va.push_back(va);
    expect_vb.push_back(vb);
    fused_va.push_back(fa);
  }
  kernel_solve(bodies, contacts.view(), options_for(path, 1));
  const BodyView<const T> out = std::as_const(bodies).view();
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_TRUE(same_bits(out.v.x[2 * k], expect_va[k]))
        << "contact " << k << ": va' = " << out.v.x[2 * k] << ", separately rounded " << expect_va[k] << ", fused "
        << fused_va[k];
    EXPECT_TRUE(same_bits(out.v.x[2 * k + 1], expect_vb[k])) << "contact " << k;
  }
}

TEST(FpPolicy, LibraryDoesNotContract) {
  for (const Path path : {Path::scalar, Path::simd}) {
    expect_library_unfused<float>(path);
    expect_library_unfused<double>(path);
  }
}

}  // namespace
}  // namespace collide::test
