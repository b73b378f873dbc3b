// test_sliding_direction.cpp - sliding_direction() of contact_kernel.hpp:
// |ut| and the friction direction t for any finite sliding velocity ut.
//
// What this proves
// ----------------
// * Power-of-two scaling changes no bits: for ut of moderate size and every
//   k with ut * 2^k inside the normal range (float k in [-100, 100], double
//   k in [-900, 900], which crosses both scaling thresholds), |ut * 2^k| is
//   exactly |ut| * 2^k and the unit vector is bit for bit the same. So a
//   lane's result does not depend on whether it was scaled.
// * Accuracy over the whole finite range, subnormal speeds included: |ut|
//   within 2 eps of a long double evaluation (relative; for subnormal speeds
//   within the spacing of the subnormals), and t = unit / scaled_length a
//   unit vector along ut to 4 eps.
// * A NaN or inf component gives a NaN or inf scaled length (the kernel's
//   "does not slide"), and a zero ut a zero length.
// * The scalar and SIMD lanes give the same bits for each lane.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "contact_kernel.hpp"
#include "support/isa_test.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

namespace d = collide::detail;

template <class T>
struct Direction {
  T unit[3];
  T scaled_length;
  T speed;
};

template <class V>
Direction<typename V::value_type> direction_in(const typename V::value_type (&ut)[3], std::size_t lane = 0) {
  using T = typename V::value_type;
  const d::Vec3<V> u{V(ut[0]), V(ut[1]), V(ut[2])};
  const d::SlidingDirection<V> s = d::sliding_direction(u);
  return Direction<T>{
      {T(s.unit.x[lane]), T(s.unit.y[lane]), T(s.unit.z[lane])}, T(s.scaled_length[lane]), T(s.speed[lane])};
}

template <class T>
T random_component(std::mt19937_64& rng) {
  std::uniform_real_distribution<T> dist(T(-1), T(1));
  return dist(rng);
}

template <class T>
void expect_scaling_changes_no_bits(int k_max) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const T ut[3] = {random_component<T>(rng), random_component<T>(rng), random_component<T>(rng)};
    const Direction<T> base = direction_in<d::ScalarLanes<T>>(ut);
    for (int k = -k_max; k <= k_max; k += 7) {
      const T scaled[3] = {std::ldexp(ut[0], k), std::ldexp(ut[1], k), std::ldexp(ut[2], k)};
      const Direction<T> s = direction_in<d::ScalarLanes<T>>(scaled);
      ASSERT_TRUE(same_bits(s.speed, std::ldexp(base.speed, k))) << "trial " << trial << " k " << k;
      const T t_base = base.unit[0] / base.scaled_length;
      const T t_scaled = s.unit[0] / s.scaled_length;
      ASSERT_TRUE(same_bits(t_base, t_scaled)) << "trial " << trial << " k " << k;
    }
  }
}

TEST(SlidingDirection, PowerOfTwoScalingChangesNoBitsFloat) { expect_scaling_changes_no_bits<float>(100); }
TEST(SlidingDirection, PowerOfTwoScalingChangesNoBitsDouble) { expect_scaling_changes_no_bits<double>(900); }

template <class T>
void expect_accurate_over_the_whole_range() {
  using L = long double;
  const T eps = std::numeric_limits<T>::epsilon();
  const int lo = std::numeric_limits<T>::min_exponent - std::numeric_limits<T>::digits;  // smallest subnormal
  const int hi = std::numeric_limits<T>::max_exponent - 2;                               // |ut| stays finite
  std::mt19937_64 rng(11);
  for (int e = lo + 2; e <= hi; ++e) {
    for (int trial = 0; trial < 4; ++trial) {
      T ut[3];
      for (T& c : ut) c = std::ldexp(random_component<T>(rng), e);
      const Direction<T> s = direction_in<d::ScalarLanes<T>>(ut);
      const L exact = std::sqrt(L(ut[0]) * L(ut[0]) + L(ut[1]) * L(ut[1]) + L(ut[2]) * L(ut[2]));
      if (exact == 0) continue;
      // Relative 2 eps, or the subnormal spacing (denorm_min) when |ut| is tiny.
      const L tol = std::max(L(2) * L(eps) * exact, L(std::numeric_limits<T>::denorm_min()));
      ASSERT_LE(std::fabs(L(s.speed) - exact), tol) << "exponent " << e;
      for (int i = 0; i < 3; ++i) {
        const L t = L(s.unit[i] / s.scaled_length);
        ASSERT_LE(std::fabs(t - L(ut[i]) / exact), L(4) * L(eps)) << "exponent " << e << " component " << i;
      }
    }
  }
}

TEST(SlidingDirection, AccurateFromSubnormalToHugeFloat) { expect_accurate_over_the_whole_range<float>(); }
TEST(SlidingDirection, AccurateFromSubnormalToHugeDouble) { expect_accurate_over_the_whole_range<double>(); }

template <class T>
void expect_non_finite_and_zero() {
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T inf = std::numeric_limits<T>::infinity();
  const T with_nan[3] = {T(1), nan, T(0)};
  EXPECT_TRUE(std::isnan(direction_in<d::ScalarLanes<T>>(with_nan).scaled_length));
  const T with_inf[3] = {-inf, T(1), T(0)};
  EXPECT_FALSE(direction_in<d::ScalarLanes<T>>(with_inf).scaled_length < inf);
  const T zero[3] = {T(0), T(-0.0), T(0)};
  EXPECT_EQ(direction_in<d::ScalarLanes<T>>(zero).scaled_length, T(0));
  // Finite components whose |ut| overflows: the length is finite once scaled,
  // the speed is inf (the kernel then applies jt = mu jn).
  const T max = std::numeric_limits<T>::max();
  const T big[3] = {max, max, T(0)};
  const Direction<T> s = direction_in<d::ScalarLanes<T>>(big);
  EXPECT_TRUE(std::isfinite(s.scaled_length));
  EXPECT_EQ(s.speed, inf);
}

TEST(SlidingDirection, NonFiniteAndZeroFloat) { expect_non_finite_and_zero<float>(); }
TEST(SlidingDirection, NonFiniteAndZeroDouble) { expect_non_finite_and_zero<double>(); }

template <class T>
void expect_lanes_agree() {
  using V = d::SimdLanes<T>;
  constexpr std::size_t W = V::size();
  std::mt19937_64 rng(13);
  T in[3][W];
  const int exponents[] = {-149, -130, -70, -20, 0, 20, 70, 120};
  for (std::size_t l = 0; l < W; ++l) {
    const int e = exponents[l % 8] * (sizeof(T) == 8 ? 6 : 1);
    for (auto& c : in) c[l] = std::ldexp(random_component<T>(rng), e);
  }
  const d::Vec3<V> u{V([&](auto l) { return in[0][l]; }), V([&](auto l) { return in[1][l]; }),
                     V([&](auto l) { return in[2][l]; })};
  const d::SlidingDirection<V> wide = d::sliding_direction(u);
  for (std::size_t l = 0; l < W; ++l) {
    const T ut[3] = {in[0][l], in[1][l], in[2][l]};
    const Direction<T> one = direction_in<d::ScalarLanes<T>>(ut);
    EXPECT_TRUE(same_bits(one.speed, T(wide.speed[l]))) << "lane " << l;
    EXPECT_TRUE(same_bits(one.scaled_length, T(wide.scaled_length[l]))) << "lane " << l;
    EXPECT_TRUE(same_bits(one.unit[0], T(wide.unit.x[l]))) << "lane " << l;
  }
}

TEST(SlidingDirection, ScalarAndSimdLanesAgreeFloat) { expect_lanes_agree<float>(); }
TEST(SlidingDirection, ScalarAndSimdLanesAgreeDouble) { expect_lanes_agree<double>(); }

}  // namespace
}  // namespace collide::test
