// test_generate.cpp - the random scenes of generate.hpp.
//
// What `collide gen`, the tests and the benchmarks rely on: item k is a pure
// function of (seed, k); every contact approaches in the initial state, also
// after rounding to float; the debris scene has its ground last and on side
// b of every fourth contact; the inputs are valid scene values.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"

namespace {

template <class T>
T approach_speed(const collide::Scene<T>& scene, std::size_t k) {
  const auto b = scene.bodies.view();
  const auto c = scene.contacts.view();
  const std::size_t ia = c.a[k], ib = c.b[k];
  const T ra[3] = {c.c.x[k] - b.p.x[ia], c.c.y[k] - b.p.y[ia], c.c.z[k] - b.p.z[ia]};
  const T rb[3] = {c.c.x[k] - b.p.x[ib], c.c.y[k] - b.p.y[ib], c.c.z[k] - b.p.z[ib]};
  auto point_velocity = [&](std::size_t i, const T* r, T* out) {
    out[0] = b.v.x[i] + (b.w.y[i] * r[2] - b.w.z[i] * r[1]);
    out[1] = b.v.y[i] + (b.w.z[i] * r[0] - b.w.x[i] * r[2]);
    out[2] = b.v.z[i] + (b.w.x[i] * r[1] - b.w.y[i] * r[0]);
  };
  T ua[3], ub[3];
  point_velocity(ia, ra, ua);
  point_velocity(ib, rb, ub);
  return (ua[0] - ub[0]) * c.n.x[k] + (ua[1] - ub[1]) * c.n.y[k] + (ua[2] - ub[2]) * c.n.z[k];
}

template <class T>
void expect_valid_and_approaching(const collide::Scene<T>& scene) {
  const auto b = scene.bodies.view();
  for (std::size_t i = 0; i < b.count; ++i) {
    ASSERT_TRUE(std::isfinite(b.inv_mass[i]) && b.inv_mass[i] >= 0);
    ASSERT_NEAR(b.q.w[i] * b.q.w[i] + b.q.x[i] * b.q.x[i] + b.q.y[i] * b.q.y[i] + b.q.z[i] * b.q.z[i], 1, 1e-5);
  }
  const auto c = scene.contacts.view();
  for (std::size_t k = 0; k < c.count; ++k) {
    ASSERT_NE(c.a[k], c.b[k]);
    ASSERT_LT(c.a[k], b.count);
    ASSERT_LT(c.b[k], b.count);
    ASSERT_LT(approach_speed(scene, k), T(0)) << "contact " << k;
    ASSERT_TRUE(c.e[k] >= 0 && c.e[k] <= 1);
  }
}

TEST(SceneGenerator, PairsApproachInBothPrecisions) {
  expect_valid_and_approaching(collide::generate_pairs<double>(20000, {5, true}));
  expect_valid_and_approaching(collide::generate_pairs<float>(20000, {5, true}));
}

TEST(SceneGenerator, DebrisApproachesInitially) {
  expect_valid_and_approaching(collide::generate_debris<double>(20000, {5, false}));
  expect_valid_and_approaching(collide::generate_debris<float>(20000, {5, false}));
}

TEST(SceneGenerator, PairKIsAPureFunctionOfSeedAndK) {
  const auto scene = collide::generate_pairs<double>(1000, {9, true});
  for (const std::uint64_t k : {0u, 1u, 500u, 999u}) {
    collide::BodyRecord<double> a, b;
    collide::ContactRecord<double> c;
    collide::draw_pair({9, true}, k, a, b, c);
    const auto got = scene.contacts.record(k);
    EXPECT_EQ(got.a, 2 * k);
    EXPECT_EQ(got.b, 2 * k + 1);
    EXPECT_EQ(got.c[0], c.c[0]);
    EXPECT_EQ(got.e, c.e);
    EXPECT_EQ(got.mu, c.mu);
    EXPECT_EQ(scene.bodies.view().p.x[2 * k + 1], b.p[0]);
  }
  // Scene size does not change a pair.
  const auto small = collide::generate_pairs<double>(10, {9, true});
  EXPECT_EQ(small.contacts.record(7).c[1], scene.contacts.record(7).c[1]);
}

TEST(SceneGenerator, SeedsDiffer) {
  const auto a = collide::generate_pairs<double>(10, {1, false});
  const auto b = collide::generate_pairs<double>(10, {2, false});
  EXPECT_NE(a.contacts.record(0).c[0], b.contacts.record(0).c[0]);
}

TEST(SceneGenerator, FrictionOnlyChangesMu) {
  const auto a = collide::generate_pairs<double>(100, {3, false});
  const auto b = collide::generate_pairs<double>(100, {3, true});
  for (std::size_t k = 0; k < 100; ++k) {
    EXPECT_EQ(a.contacts.record(k).mu, 0.0);
    EXPECT_GT(b.contacts.record(k).mu, 0.0);
    EXPECT_EQ(a.contacts.record(k).e, b.contacts.record(k).e);
  }
}

TEST(SceneGenerator, DebrisShape) {
  const std::size_t n = 1000;
  const auto scene = collide::generate_debris<double>(n);
  ASSERT_EQ(scene.bodies.size(), n / 2 + 1);
  ASSERT_EQ(collide::debris_body_count(n), n / 2 + 1);
  const auto ground = scene.bodies.size() - 1;
  EXPECT_EQ(scene.bodies.view().inv_mass[ground], 0.0);
  std::size_t on_ground = 0;
  std::vector<int> uses(scene.bodies.size(), 0);
  for (std::size_t k = 0; k < n; ++k) {
    const auto c = scene.contacts.record(k);
    on_ground += c.b == ground ? 1 : 0;
    EXPECT_NE(c.a, ground);
    ++uses[c.a];
    ++uses[c.b];
  }
  EXPECT_EQ(on_ground, n / 4);
  // Bodies are shared: some movable body is in more than one contact.
  EXPECT_GT(*std::max_element(uses.begin(), uses.end() - 1), 1);
}

TEST(SceneGenerator, TinyScenes) {
  EXPECT_EQ(collide::generate_pairs<float>(0).contacts.size(), 0u);
  const auto d0 = collide::generate_debris<double>(0);
  EXPECT_EQ(d0.contacts.size(), 0u);
  EXPECT_EQ(d0.bodies.size(), 1u);
  expect_valid_and_approaching(collide::generate_debris<double>(1));
  expect_valid_and_approaching(collide::generate_debris<double>(3));
}

}  // namespace
