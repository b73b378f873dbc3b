// test_lanes.cpp - the private lane layer (core/src/lanes.hpp) that the
// kernel body is written in.
//
// What this proves
// ----------------
// * The SIMD width is what the build's instruction set promises (AVX2: 8
//   float / 4 double; SSE2: 4 / 2) and what collide::simd_width reports, and
//   the scalar lanes are 1 wide.
// * Memory helpers move bits, not values: load/store, gather (repeated
//   indices allowed), masked scatter (unmasked lanes untouched),
//   load_deinterleaved / store_interleaved (the paired-layout fast path: even
//   and odd elements of 2W consecutive values, nothing outside them written)
//   all preserve NaN payloads and -0.0; select() returns the chosen operand
//   bit for bit.
// * The vector helpers (+, -, *, hadamard, dot, cross, rotation, to_world,
//   to_body) give identical bits on the scalar and the SIMD lanes for every
//   lane, and agree with a long double evaluation to a few eps.
// * rotation(q) of a unit quaternion is orthonormal to a few eps, to_body is
//   its transpose (to_body(to_world(v)) = v to a few eps), and the identity
//   quaternion gives the identity matrix exactly.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "collide/solve.hpp"
#include "lanes.hpp"
#include "support/isa_test.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

namespace d = collide::detail;

TEST(Lanes, WidthsMatchTheInstructionSet) {
  EXPECT_EQ(d::ScalarLanes<float>::size(), 1u);
  EXPECT_EQ(d::ScalarLanes<double>::size(), 1u);
#if defined(__AVX512F__)
  EXPECT_EQ(d::SimdLanes<float>::size(), 16u);
  EXPECT_EQ(d::SimdLanes<double>::size(), 8u);
#elif defined(__AVX__)
  EXPECT_EQ(d::SimdLanes<float>::size(), 8u);
  EXPECT_EQ(d::SimdLanes<double>::size(), 4u);
#elif defined(__SSE2__)
  EXPECT_EQ(d::SimdLanes<float>::size(), 4u);
  EXPECT_EQ(d::SimdLanes<double>::size(), 2u);
#endif
  // The library's kernel for this ISA was built with the same flags.
  EXPECT_EQ(simd_width<float>(test_isa()), d::SimdLanes<float>::size());
  EXPECT_EQ(simd_width<double>(test_isa()), d::SimdLanes<double>::size());
}

/// Values with distinctive bits: NaNs with payloads, -0.0, inf, subnormals.
template <class T>
std::vector<T> special_values(std::size_t n) {
  std::vector<T> out(n);
  using U = std::conditional_t<std::is_same_v<T, float>, std::uint32_t, std::uint64_t>;
  for (std::size_t i = 0; i < n; ++i) {
    switch (i % 6) {
      case 0: {
        U bits;
        const T nan = std::numeric_limits<T>::quiet_NaN();
        std::memcpy(&bits, &nan, sizeof bits);
        bits |= static_cast<U>(i + 1);  // a payload per element
        std::memcpy(&out[i], &bits, sizeof bits);
        break;
      }
      case 1:
        out[i] = T(-0.0);
        break;
      case 2:
        out[i] = std::numeric_limits<T>::denorm_min() * T(i + 1);
        break;
      case 3:
        out[i] = -std::numeric_limits<T>::infinity();
        break;
      default:
        out[i] = T(i) * T(1.25) - T(7);
        break;
    }
  }
  return out;
}

template <class V>
void expect_memory_helpers() {
  using T = typename V::value_type;
  constexpr std::size_t W = V::size();
  const std::vector<T> src = special_values<T>(4 * W + 6);

  // load / store.
  std::vector<T> dst(src.size(), T(42));
  d::store(d::load<V>(src.data() + 3), dst.data() + 3);
  for (std::size_t i = 0; i < dst.size(); ++i) {
    const bool inside = i >= 3 && i < 3 + W;
    EXPECT_TRUE(same_bits(dst[i], inside ? src[i] : T(42))) << "store element " << i;
  }

  // gather with repeated and descending indices.
  std::uint32_t idx[W];
  for (std::size_t l = 0; l < W; ++l) idx[l] = static_cast<std::uint32_t>(l % 2 ? 4 * W - l : 5);
  const V g = d::gather<V>(src.data(), idx);
  for (std::size_t l = 0; l < W; ++l) EXPECT_TRUE(same_bits(T(g[l]), src[idx[l]])) << "gather lane " << l;

  // masked scatter: only masked lanes write.
  std::uint32_t out_idx[W];
  for (std::size_t l = 0; l < W; ++l) out_idx[l] = static_cast<std::uint32_t>(2 * W - 1 - l);
  const V lane_mod3([](auto lane) { return T(lane % 3); });
  const typename V::mask_type mask = lane_mod3 != V(1);
  std::vector<T> sc(2 * W, T(-1));
  d::scatter(d::load<V>(src.data()), sc.data(), out_idx, mask);
  for (std::size_t l = 0; l < W; ++l) {
    EXPECT_TRUE(same_bits(sc[out_idx[l]], l % 3 != 1 ? src[l] : T(-1))) << "scatter lane " << l;
  }

  // select picks operands bit for bit.
  const V a = d::load<V>(src.data());
  const V b = d::load<V>(src.data() + W);
  const V s = d::select(mask, a, b);
  for (std::size_t l = 0; l < W; ++l) {
    EXPECT_TRUE(same_bits(T(s[l]), l % 3 != 1 ? src[l] : src[W + l])) << "select lane " << l;
  }

  // load_deinterleaved / store_interleaved.
  for (const std::size_t offset : {std::size_t(0), std::size_t(1), std::size_t(5)}) {
    V even, odd;
    d::load_deinterleaved(src.data() + offset, even, odd);
    for (std::size_t l = 0; l < W; ++l) {
      EXPECT_TRUE(same_bits(T(even[l]), src[offset + 2 * l])) << "even lane " << l << " offset " << offset;
      EXPECT_TRUE(same_bits(T(odd[l]), src[offset + 2 * l + 1])) << "odd lane " << l << " offset " << offset;
    }
    std::vector<T> back(src.size(), T(13));
    d::store_interleaved(even, odd, back.data() + offset);
    for (std::size_t i = 0; i < back.size(); ++i) {
      const bool inside = i >= offset && i < offset + 2 * W;
      EXPECT_TRUE(same_bits(back[i], inside ? src[i] : T(13))) << "interleaved element " << i;
    }
  }
}

TEST(Lanes, MemoryHelpersMoveBitsScalar) {
  expect_memory_helpers<d::ScalarLanes<float>>();
  expect_memory_helpers<d::ScalarLanes<double>>();
}
TEST(Lanes, MemoryHelpersMoveBitsSimd) {
  expect_memory_helpers<d::SimdLanes<float>>();
  expect_memory_helpers<d::SimdLanes<double>>();
}

using LD = long double;

template <class T>
struct Inputs {
  std::array<T, 3> a, b;
  std::array<T, 4> q;  // unit in T
};

template <class T>
std::vector<Inputs<T>> random_inputs(std::size_t n) {
  std::mt19937_64 g(4321);
  std::uniform_real_distribution<double> u(-3, 3);
  std::normal_distribution<double> nd;
  std::vector<Inputs<T>> out(n);
  for (auto& in : out) {
    for (int i = 0; i < 3; ++i) {
      in.a[i] = T(u(g));
      in.b[i] = T(u(g));
    }
    double q[4], s = 0;
    for (double& x : q) {
      x = nd(g);
      s += x * x;
    }
    for (int i = 0; i < 4; ++i) in.q[i] = T(q[i] / std::sqrt(s));
  }
  return out;
}

/// Everything the vector helpers compute for one set of inputs, per lane.
template <class V>
struct Outputs {
  using T = typename V::value_type;
  std::vector<std::array<T, 27>> lanes;
};

template <class V>
Outputs<V> evaluate(const std::vector<Inputs<typename V::value_type>>& in) {
  using T = typename V::value_type;
  constexpr std::size_t W = V::size();
  Outputs<V> out;
  out.lanes.resize(in.size());
  for (std::size_t base = 0; base + W <= in.size(); base += W) {
    auto field = [&](auto get) { return V([&](auto l) { return get(in[base + l]); }); };
    const d::Vec3<V> a{field([](const Inputs<T>& x) { return x.a[0]; }),
                       field([](const Inputs<T>& x) { return x.a[1]; }),
                       field([](const Inputs<T>& x) { return x.a[2]; })};
    const d::Vec3<V> b{field([](const Inputs<T>& x) { return x.b[0]; }),
                       field([](const Inputs<T>& x) { return x.b[1]; }),
                       field([](const Inputs<T>& x) { return x.b[2]; })};
    const d::Mat3<V> m =
        d::rotation(field([](const Inputs<T>& x) { return x.q[0]; }), field([](const Inputs<T>& x) { return x.q[1]; }),
                    field([](const Inputs<T>& x) { return x.q[2]; }), field([](const Inputs<T>& x) { return x.q[3]; }));
    const d::Vec3<V> sum = a + b, diff = a - b, scaled = a * b.x, had = d::hadamard(a, b), cr = d::cross(a, b);
    const V dt = d::dot(a, b);
    const d::Vec3<V> world = d::to_world(m, a), body = d::to_body(m, a);
    for (std::size_t l = 0; l < W; ++l) {
      out.lanes[base + l] = {sum.x[l],     sum.y[l],     sum.z[l],    diff.x[l], diff.y[l],    diff.z[l],
                             scaled.x[l],  scaled.y[l],  scaled.z[l], had.x[l],  had.y[l],     had.z[l],
                             cr.x[l],      cr.y[l],      cr.z[l],     dt[l],     world.x[l],   world.y[l],
                             world.z[l],   body.x[l],    body.y[l],   body.z[l], m.r[0][0][l], m.r[1][1][l],
                             m.r[2][2][l], m.r[0][1][l], m.r[2][0][l]};
    }
  }
  return out;
}

template <class T>
void expect_vector_helpers() {
  const std::size_t n = std::size_t{8} * 500;
  const auto in = random_inputs<T>(n);
  const Outputs<d::ScalarLanes<T>> s = evaluate<d::ScalarLanes<T>>(in);
  const Outputs<d::SimdLanes<T>> v = evaluate<d::SimdLanes<T>>(in);
  const LD eps = std::numeric_limits<T>::epsilon();
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t f = 0; f < 27; ++f) {
      ASSERT_TRUE(same_bits(s.lanes[k][f], v.lanes[k][f])) << "input " << k << " output " << f;
    }
    // Against long double.
    const auto& x = in[k];
    const LD a[3] = {x.a[0], x.a[1], x.a[2]}, b[3] = {x.b[0], x.b[1], x.b[2]};
    const LD w = x.q[0], qx = x.q[1], qy = x.q[2], qz = x.q[3];
    const LD R[3][3] = {{1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)},
                        {2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)},
                        {2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)}};
    LD expect[27];
    for (int i = 0; i < 3; ++i) {
      expect[i] = a[i] + b[i];
      expect[3 + i] = a[i] - b[i];
      expect[6 + i] = a[i] * b[0];
      expect[9 + i] = a[i] * b[i];
      expect[16 + i] = R[i][0] * a[0] + R[i][1] * a[1] + R[i][2] * a[2];
      expect[19 + i] = R[0][i] * a[0] + R[1][i] * a[1] + R[2][i] * a[2];
    }
    expect[12] = a[1] * b[2] - a[2] * b[1];
    expect[13] = a[2] * b[0] - a[0] * b[2];
    expect[14] = a[0] * b[1] - a[1] * b[0];
    expect[15] = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    expect[22] = R[0][0], expect[23] = R[1][1], expect[24] = R[2][2], expect[25] = R[0][1], expect[26] = R[2][0];
    // Absolute tolerance: a few eps of the magnitudes involved (|a|, |b| <= 3*sqrt(3)).
    for (std::size_t f = 0; f < 27; ++f) {
      const LD scale = f >= 22 ? 1 : f >= 16 ? 6 : f >= 6 ? 30 : 6;
      ASSERT_LE(std::fabs(LD(s.lanes[k][f]) - expect[f]), 8 * eps * scale) << "input " << k << " output " << f;
    }
  }
}

TEST(Lanes, VectorHelpersAgreeAcrossWidthsAndWithLongDouble) {
  expect_vector_helpers<float>();
  expect_vector_helpers<double>();
}

template <class T>
void expect_rotation_properties() {
  using V = d::SimdLanes<T>;
  const auto in = random_inputs<T>(V::size() * 200);
  const LD eps = std::numeric_limits<T>::epsilon();
  for (std::size_t base = 0; base < in.size(); base += V::size()) {
    auto q = [&](int i) { return V([&](auto l) { return in[base + l].q[i]; }); };
    const d::Mat3<V> m = d::rotation(q(0), q(1), q(2), q(3));
    for (std::size_t l = 0; l < V::size(); ++l) {
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          LD dotp = 0;
          for (int k = 0; k < 3; ++k) dotp += LD(m.r[i][k][l]) * LD(m.r[j][k][l]);
          ASSERT_NEAR(static_cast<double>(dotp), i == j ? 1.0 : 0.0, static_cast<double>(16 * eps));
        }
      }
    }
    const d::Vec3<V> v{q(1) * V(3), q(2) - V(1), q(0) + q(3)};
    const d::Vec3<V> back = d::to_body(m, d::to_world(m, v));
    for (std::size_t l = 0; l < V::size(); ++l) {
      ASSERT_NEAR(back.x[l], v.x[l], 32 * eps);
      ASSERT_NEAR(back.y[l], v.y[l], 32 * eps);
      ASSERT_NEAR(back.z[l], v.z[l], 32 * eps);
    }
  }
  // Identity.
  const d::Mat3<V> id = d::rotation(V(1), V(0), V(0), V(0));
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (std::size_t l = 0; l < V::size(); ++l) EXPECT_EQ(id.r[i][j][l], i == j ? T(1) : T(0));
    }
  }
  const d::Vec3<V> v{V(T(1.5)), V(T(-2.25)), V(T(0.125))};
  const d::Vec3<V> w = d::to_world(id, v);
  for (std::size_t l = 0; l < V::size(); ++l) {
    EXPECT_EQ(w.x[l], T(1.5));
    EXPECT_EQ(w.y[l], T(-2.25));
    EXPECT_EQ(w.z[l], T(0.125));
  }
}

TEST(Lanes, RotationIsOrthonormalAndToBodyIsItsTranspose) {
  expect_rotation_properties<float>();
  expect_rotation_properties<double>();
}

}  // namespace
}  // namespace collide::test
