// test_exact_lanes.cpp - the error-free transformations and the double-double
// arithmetic of the accurate mode (core/src/exact_lanes.hpp), on this
// binary's SIMD lanes and on the scalar lanes, against exact arithmetic.
//
// What this proves
// ----------------
// * TwoSum, FastTwoSum, Veltkamp's split and TwoProduct are error-free on
//   every lane: s = fl(a + b) and s + e = a + b exactly, p = fl(a * b) and
//   p + e = a * b exactly, hi + lo = a with hi on half the significand. For
//   float lanes "exactly" is checked in double, where these sums and
//   products are exact; for double lanes in a 113-bit type (__float128, or
//   long double where it is IEEE quad), where they are exact for the operand
//   ranges drawn here. Where neither exists the file does not compile, so
//   the double checks never drop out silently (a 64-bit significand cannot
//   hold a double-double's 106 bits).
// * Double-double +, -, * (by a double-double and by a double), / and sqrt
//   stay within the published bounds of the algorithms (u = 2^-53: the
//   accurate addition within 3u^2 of the exact result, relative, even under
//   cancellation; the products within 7u^2 and 2u^2; the division and the
//   square root within 16u^2 and 8u^2), and every result is normalised
//   (hi = fl(hi + lo)), which narrow() relies on.
// * The SIMD lanes give the same bits as the scalar lanes, lane by lane: the
//   accurate mode's answer does not depend on the ISA.
// * AccurateLanes: widen is exact and narrow rounds once to nearest.
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "exact_lanes.hpp"
#include "lanes.hpp"
#include "support/isa_test.hpp"

namespace collide::test {
namespace {

namespace d = collide::detail;

constexpr std::size_t kCount = 4096;

/// Random values m * 2^k, m uniform in [1, 2), k in [-range, range], either
/// sign: exponent gaps stay small enough for the exact checks below.
template <class T>
std::vector<T> draw(std::uint64_t seed, int range, std::size_t n = kCount) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-range, range);
  std::vector<T> out(n);
  for (T& x : out) {
    const double m = mantissa(rng) * ((rng() & 1) ? 1.0 : -1.0);
    x = static_cast<T>(std::ldexp(m, exponent(rng)));
  }
  return out;
}

template <class T>
bool same_bits(T a, T b) {
  return std::memcmp(&a, &b, sizeof a) == 0;  // NOLINT(bugprone-suspicious-memory-comparison): the bits are the point
}

/// Runs f on lanes V over whole blocks of the inputs: f(in..., out...) with
/// `outs` output arrays, each written lane by lane.
template <class V, std::size_t NIn, std::size_t NOut, class F>
void on_lanes(const std::vector<typename V::value_type>* const (&in)[NIn],
              std::vector<typename V::value_type>* const (&out)[NOut], const F& f) {
  constexpr std::size_t W = V::size();
  const std::size_t n = in[0]->size();
  for (auto* o : out) o->assign(n, typename V::value_type(0));
  for (std::size_t i = 0; i + W <= n; i += W) {
    V a[NIn];
    V r[NOut];
    for (std::size_t k = 0; k < NIn; ++k) a[k] = d::load<V>(in[k]->data() + i);
    f(a, r);
    for (std::size_t k = 0; k < NOut; ++k) d::store(r[k], out[k]->data() + i);
  }
}

// --- float lanes: exact checks in double ------------------------------------

template <class V>
void check_float_transformations() {
  using T = typename V::value_type;
  static_assert(std::is_same_v<T, float>);
  const std::vector<float> a = draw<float>(1, 12), b = draw<float>(2, 12);
  std::vector<float> s, e, p, pe, hi, lo;
  on_lanes<V, 2, 2>({&a, &b}, {&s, &e}, [](const V* x, V* r) { d::two_sum(x[0], x[1], r[0], r[1]); });
  on_lanes<V, 2, 2>({&a, &b}, {&p, &pe}, [](const V* x, V* r) { d::two_product(x[0], x[1], r[0], r[1]); });
  on_lanes<V, 1, 2>({&a}, {&hi, &lo}, [](const V* x, V* r) { d::split(x[0], r[0], r[1]); });
  for (std::size_t i = 0; i < a.size(); ++i) {
    // float sums with exponent gaps below 29 and float products are exact in double.
    ASSERT_TRUE(same_bits(s[i], a[i] + b[i])) << i;
    ASSERT_EQ(double(s[i]) + double(e[i]), double(a[i]) + double(b[i])) << i;
    ASSERT_TRUE(same_bits(p[i], a[i] * b[i])) << i;
    ASSERT_EQ(double(p[i]) + double(pe[i]), double(a[i]) * double(b[i])) << i;
    ASSERT_EQ(hi[i] + lo[i], a[i]) << i;
    // hi has at most 12 significant bits: its low 12 bits of 24 are zero.
    std::uint32_t bits;
    std::memcpy(&bits, &hi[i], sizeof bits);
    ASSERT_EQ(bits & 0xFFFu, 0u) << i;
  }
}

TEST(ExactLanes, FloatTransformationsAreErrorFreeOnTheSimdLanes) { check_float_transformations<d::SimdLanes<float>>(); }
TEST(ExactLanes, FloatTransformationsAreErrorFreeOnTheScalarLanes) {
  check_float_transformations<d::ScalarLanes<float>>();
}

TEST(ExactLanes, FloatWidensExactlyAndNarrowsOnceToNearest) {
  using V = d::SimdLanes<float>;
  using A = d::AccurateLanes<V>;
  constexpr std::size_t W = V::size();
  const std::vector<float> a = draw<float>(3, 40);
  const std::vector<double> wide = draw<double>(4, 40);
  for (std::size_t i = 0; i + W <= a.size(); i += W) {
    const auto w = A::widen(d::load<V>(a.data() + i));
    const V n = A::narrow(d::load<typename A::type>(wide.data() + i));
    for (std::size_t k = 0; k < W; ++k) {
      ASSERT_EQ(double(w[k]), double(a[i + k]));
      ASSERT_TRUE(same_bits(float(n[k]), static_cast<float>(wide[i + k])));
    }
  }
}

// --- double lanes: exact checks in 113 bits ---------------------------------

#if defined(__SIZEOF_FLOAT128__)
using F128 = __float128;  // GCC and clang on x86-64
#elif LDBL_MANT_DIG >= 113
using F128 = long double;  // IEEE quad (aarch64, riscv64, s390x Linux)
#else
#error "test_exact_lanes needs a 113-bit type (__float128 or an IEEE quad long double) to check double lanes exactly"
#endif
constexpr double kU = 0x1p-53;  // unit roundoff of double

F128 exact(double hi, double lo) { return F128(hi) + F128(lo); }

/// |x - y| / |y| as a double (0 when both are 0).
double relative(F128 x, F128 y) {
  if (y == 0) return x == 0 ? 0.0 : INFINITY;
  const F128 r = (x - y) / y;
  return std::fabs(static_cast<double>(r));
}

template <class V>
void check_double_transformations() {
  const std::vector<double> a = draw<double>(5, 25), b = draw<double>(6, 25);
  std::vector<double> s, e, fs, fe, p, pe, hi, lo;
  on_lanes<V, 2, 2>({&a, &b}, {&s, &e}, [](const V* x, V* r) { d::two_sum(x[0], x[1], r[0], r[1]); });
  // FastTwoSum needs |a| >= |b|: the larger first.
  on_lanes<V, 2, 2>({&a, &b}, {&fs, &fe}, [](const V* x, V* r) {
    const auto swap = d::stdx::abs(x[0]) < d::stdx::abs(x[1]);
    d::fast_two_sum(d::select(swap, x[1], x[0]), d::select(swap, x[0], x[1]), r[0], r[1]);
  });
  on_lanes<V, 2, 2>({&a, &b}, {&p, &pe}, [](const V* x, V* r) { d::two_product(x[0], x[1], r[0], r[1]); });
  on_lanes<V, 1, 2>({&a}, {&hi, &lo}, [](const V* x, V* r) { d::split(x[0], r[0], r[1]); });
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(same_bits(s[i], a[i] + b[i])) << i;
    ASSERT_TRUE(exact(s[i], e[i]) == F128(a[i]) + F128(b[i])) << i;
    ASSERT_TRUE(same_bits(fs[i], a[i] + b[i])) << i;
    ASSERT_TRUE(exact(fs[i], fe[i]) == F128(a[i]) + F128(b[i])) << i;
    ASSERT_TRUE(same_bits(p[i], a[i] * b[i])) << i;
    ASSERT_TRUE(exact(p[i], pe[i]) == F128(a[i]) * F128(b[i])) << i;
    ASSERT_EQ(hi[i] + lo[i], a[i]) << i;
    std::uint64_t bits;
    std::memcpy(&bits, &hi[i], sizeof bits);
    ASSERT_EQ(bits & ((std::uint64_t{1} << 26) - 1), 0u) << i;  // hi: at most 27 of 53 bits
  }
}

TEST(ExactLanes, DoubleTransformationsAreErrorFreeOnTheSimdLanes) {
  check_double_transformations<d::SimdLanes<double>>();
}
TEST(ExactLanes, DoubleTransformationsAreErrorFreeOnTheScalarLanes) {
  check_double_transformations<d::ScalarLanes<double>>();
}

/// Normalised double-doubles hi + lo with |lo| <= ulp(hi) / 2. With
/// `cancel_with`, every other value is the negation of that one's plus a
/// small perturbation, so sums cancel most of their leading bits.
struct DoubleDoubles {
  std::vector<double> hi, lo;
};

DoubleDoubles draw_dd(std::uint64_t seed, int range, const DoubleDoubles* cancel_with = nullptr) {
  const std::vector<double> h = draw<double>(seed, range), l = draw<double>(seed + 100, 0);
  std::mt19937_64 rng(seed + 200);
  DoubleDoubles out{std::vector<double>(h.size()), std::vector<double>(h.size())};
  for (std::size_t i = 0; i < h.size(); ++i) {
    double hi = h[i], lo = std::ldexp(l[i], std::ilogb(hi) - 55);
    if (cancel_with != nullptr && i % 2 == 0) {
      // -other + a perturbation of relative size 2^-10 .. 2^-100.
      const int shift = 10 + static_cast<int>(rng() % 91);
      const F128 v = -exact(cancel_with->hi[i], cancel_with->lo[i]) * (F128(1) + F128(std::ldexp(l[i], -shift)));
      hi = static_cast<double>(v);
      lo = static_cast<double>(v - F128(hi));
    }
    const double s = hi + lo;  // normalise: hi = fl(hi + lo)
    out.lo[i] = lo - (s - hi);
    out.hi[i] = s;
  }
  return out;
}

enum class Op { add, sub, mul, times, div, sqrt };

template <class V>
void run_dd(Op op, const DoubleDoubles& x, const DoubleDoubles& y, DoubleDoubles& r) {
  using DD = d::DoubleDouble<V>;
  on_lanes<V, 4, 2>({&x.hi, &x.lo, &y.hi, &y.lo}, {&r.hi, &r.lo}, [op](const V* in, V* out) {
    const DD a{in[0], in[1]}, b{in[2], in[3]};
    DD c;
    switch (op) {
      case Op::add:
        c = a + b;
        break;
      case Op::sub:
        c = a - b;
        break;
      case Op::mul:
        c = a * b;
        break;
      case Op::times:
        c = d::times(a, in[2]);
        break;
      case Op::div:
        c = a / b;
        break;
      case Op::sqrt:
        c = d::lane_sqrt(DD{d::stdx::abs(in[0]), d::select(in[0] < V(0), -in[1], in[1])});
        break;
    }
    out[0] = c.hi;
    out[1] = c.lo;
  });
}

F128 exact_result(Op op, std::size_t i, const DoubleDoubles& x, const DoubleDoubles& y) {
  const F128 a = exact(x.hi[i], x.lo[i]), b = exact(y.hi[i], y.lo[i]);
  switch (op) {
    case Op::add:
      return a + b;
    case Op::sub:
      return a - b;
    case Op::mul:
      return a * b;
    case Op::times:
      return a * F128(y.hi[i]);
    case Op::div:
      return a / b;
    case Op::sqrt: {
      // Newton on |a| in F128 from the double root: quadratic, 3 steps
      // are far past 113 bits.
      const F128 m = a < 0 ? -a : a;
      F128 s = F128(std::sqrt(static_cast<double>(m)));
      for (int k = 0; k < 3; ++k) s = (s + m / s) / 2;
      return s;
    }
  }
  return 0;
}

/// The published bound of each operation, in units of u^2.
double bound_u2(Op op) {
  switch (op) {
    case Op::add:
    case Op::sub:
      return 3;
    case Op::mul:
      return 7;
    case Op::times:
      return 2;
    case Op::div:
      return 16;
    case Op::sqrt:
      return 8;
  }
  return 0;
}

const char* name(Op op) {
  static const char* const names[] = {"add", "sub", "mul", "times", "div", "sqrt"};
  return names[static_cast<int>(op)];
}

class DoubleDoubleOps : public ::testing::TestWithParam<Op> {};

TEST_P(DoubleDoubleOps, WithinTheBoundNormalisedAndTheSameOnEveryLane) {
  const Op op = GetParam();
  const DoubleDoubles x = draw_dd(7, 25);
  // Sums and differences meet cancellation half the time.
  const DoubleDoubles y =
      op == Op::add ? draw_dd(8, 25, &x) : op == Op::sub ? [&] {
        DoubleDoubles neg = x;
        for (double& v : neg.hi) v = -v;
        for (double& v : neg.lo) v = -v;
        return draw_dd(8, 25, &neg);
      }()
                                                         : draw_dd(8, 25);
  DoubleDoubles simd, scalar;
  run_dd<d::SimdLanes<double>>(op, x, y, simd);
  run_dd<d::ScalarLanes<double>>(op, x, y, scalar);
  double worst = 0;
  for (std::size_t i = 0; i < x.hi.size(); ++i) {
    ASSERT_TRUE(same_bits(simd.hi[i], scalar.hi[i]) && same_bits(simd.lo[i], scalar.lo[i]))
        << name(op) << ": lane " << i << " differs from the scalar lanes";
    ASSERT_EQ(simd.hi[i], simd.hi[i] + simd.lo[i]) << name(op) << ": not normalised at " << i;
    const double err = relative(exact(simd.hi[i], simd.lo[i]), exact_result(op, i, x, y)) / (kU * kU);
    worst = std::fmax(worst, err);
    ASSERT_LE(err, bound_u2(op)) << name(op) << " at " << i << ": " << err << " u^2";
  }
  // The bound is not vacuous: the drawn values reach errors above 0.
  EXPECT_GT(worst, 0.0) << name(op);
  RecordProperty("worst_u2", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(AllOps, DoubleDoubleOps,
                         ::testing::Values(Op::add, Op::sub, Op::mul, Op::times, Op::div, Op::sqrt),
                         [](const ::testing::TestParamInfo<Op>& info) { return std::string(name(info.param)); });

TEST(ExactLanes, DoubleNarrowsToTheHighWord) {
  using V = d::SimdLanes<double>;
  using A = d::AccurateLanes<V>;
  const DoubleDoubles x = draw_dd(9, 25);
  for (std::size_t i = 0; i + V::size() <= x.hi.size(); i += V::size()) {
    const V h = d::load<V>(x.hi.data() + i);
    const auto w = A::widen(h);
    const V n = A::narrow(typename A::type{h, d::load<V>(x.lo.data() + i)});
    for (std::size_t k = 0; k < V::size(); ++k) {
      ASSERT_TRUE(same_bits(double(w.hi[k]), x.hi[i + k]) && double(w.lo[k]) == 0.0);
      // Normalised, so the high word is hi + lo rounded to nearest.
      ASSERT_TRUE(same_bits(double(n[k]), static_cast<double>(exact(x.hi[i + k], x.lo[i + k]))));
    }
  }
}

}  // namespace
}  // namespace collide::test
