// test_generate.cpp - the random scenes of generate.hpp.
//
// What `collide gen`, the tests and the benchmarks rely on: item k is a pure
// function of (seed, k); every contact approaches in the initial state, also
// after rounding to float; the debris scene has its ground last and on side
// b of every fourth contact; the pile is its lattice (every contact between
// lattice neighbours or a bottom box and the ground, each touching pair
// once, in broadphase cell order or a permutation of it, points off the
// line of centres); the chain is its staircase (box k + 1 the +x or +y
// neighbour of box k by parity, contact k between boxes k and k + 1, no
// ground, one schedule batch per contact, speeds bounded whatever its
// length); the inputs are valid scene values.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include "collide/io/generate.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"

namespace {

/// u . n of contact k, from the views of a scene's bodies and contacts (taken
/// once: a contact view scans mu).
template <class BodyView, class ContactView>
auto approach_speed(const BodyView& b, const ContactView& c, std::size_t k) {
  using T = std::remove_cvref_t<decltype(b.p.x[0])>;
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
  return T((ua[0] - ub[0]) * c.n.x[k] + (ua[1] - ub[1]) * c.n.y[k] + (ua[2] - ub[2]) * c.n.z[k]);
}

/// u . n of one contact between two body records, in T.
template <class T>
T record_approach_speed(const collide::BodyRecord<T>& a, const collide::BodyRecord<T>& b,
                        const collide::ContactRecord<T>& c) {
  const T ra[3] = {c.c[0] - a.p[0], c.c[1] - a.p[1], c.c[2] - a.p[2]};
  const T rb[3] = {c.c[0] - b.p[0], c.c[1] - b.p[1], c.c[2] - b.p[2]};
  T u[3];
  for (int j = 0; j < 3; ++j) {
    const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    u[j] = (a.v[j] + (a.w[j1] * ra[j2] - a.w[j2] * ra[j1])) - (b.v[j] + (b.w[j1] * rb[j2] - b.w[j2] * rb[j1]));
  }
  return u[0] * c.n[0] + u[1] * c.n[1] + u[2] * c.n[2];
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
    ASSERT_LT(approach_speed(b, c, k), T(0)) << "contact " << k;
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

// ---------------------------------------------------------------------------
// The pile.
// ---------------------------------------------------------------------------

/// Every column of two scenes holds the same bits.
template <class T>
bool same_bits(const collide::Scene<T>& x, const collide::Scene<T>& y) {
  const auto bx = x.bodies.view(), by = y.bodies.view();
  const auto cx = x.contacts.view(), cy = y.contacts.view();
  if (bx.count != by.count || cx.count != cy.count) return false;
  const auto same = [](const auto* p, const auto* q, std::size_t n) {
    return n == 0 || std::memcmp(p, q, n * sizeof(*p)) == 0;
  };
  const std::size_t nb = bx.count, nc = cx.count;
  return same(bx.inv_mass, by.inv_mass, nb) && same(bx.inv_inertia.x, by.inv_inertia.x, nb) &&
         same(bx.inv_inertia.y, by.inv_inertia.y, nb) && same(bx.inv_inertia.z, by.inv_inertia.z, nb) &&
         same(bx.q.w, by.q.w, nb) && same(bx.q.x, by.q.x, nb) && same(bx.q.y, by.q.y, nb) && same(bx.q.z, by.q.z, nb) &&
         same(bx.p.x, by.p.x, nb) && same(bx.p.y, by.p.y, nb) && same(bx.p.z, by.p.z, nb) && same(bx.v.x, by.v.x, nb) &&
         same(bx.v.y, by.v.y, nb) && same(bx.v.z, by.v.z, nb) && same(bx.w.x, by.w.x, nb) && same(bx.w.y, by.w.y, nb) &&
         same(bx.w.z, by.w.z, nb) && same(cx.a, cy.a, nc) && same(cx.b, cy.b, nc) && same(cx.c.x, cy.c.x, nc) &&
         same(cx.c.y, cy.c.y, nc) && same(cx.c.z, cy.c.z, nc) && same(cx.n.x, cy.n.x, nc) && same(cx.n.y, cy.n.y, nc) &&
         same(cx.n.z, cy.n.z, nc) && same(cx.e, cy.e, nc) && same(cx.mu, cy.mu, nc);
}

/// The contacts of a pile as a uniform grid broadphase emits them: cell by
/// cell, x fastest, each cell's +x, +y, +z neighbour and then the ground.
std::vector<std::pair<std::size_t, std::size_t>> broadphase_pairs(std::size_t side) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  const std::size_t ground = side * side * side;
  for (std::size_t z = 0; z < side; ++z) {
    for (std::size_t y = 0; y < side; ++y) {
      for (std::size_t x = 0; x < side; ++x) {
        const std::size_t id = x + side * (y + side * z);
        if (x + 1 < side) pairs.emplace_back(id, id + 1);
        if (y + 1 < side) pairs.emplace_back(id, id + side);
        if (z + 1 < side) pairs.emplace_back(id, id + side * side);
        if (z == 0) pairs.emplace_back(id, ground);
      }
    }
  }
  return pairs;
}

TEST(PileScene, CountsAndBroadphaseCellOrder) {
  for (std::size_t side = 0; side <= 7; ++side) {
    SCOPED_TRACE(side);
    const auto scene = collide::generate_pile<double>(side);
    const auto expected = broadphase_pairs(side);
    ASSERT_EQ(scene.bodies.size(), side * side * side + 1);
    ASSERT_EQ(collide::pile_body_count(side), scene.bodies.size());
    ASSERT_EQ(scene.contacts.size(), expected.size());
    ASSERT_EQ(collide::pile_contact_count(side), 3 * side * side * (side - (side > 0 ? 1 : 0)) + side * side);
    const auto c = scene.contacts.view();
    for (std::size_t k = 0; k < expected.size(); ++k) {
      ASSERT_EQ(c.a[k], expected[k].first) << "contact " << k;
      ASSERT_EQ(c.b[k], expected[k].second) << "contact " << k;
    }
  }
  // 100 per side: the scene of the level-schedule measurements.
  EXPECT_EQ(collide::pile_contact_count(100), 2980000U);
  EXPECT_EQ(collide::pile_body_count(100), 1000001U);
}

TEST(PileScene, EveryContactJoinsLatticeNeighboursOrTheGround) {
  const std::size_t side = 9;
  const auto scene = collide::generate_pile<double>(side, {3, true});
  const auto b = scene.bodies.view();
  const auto c = scene.contacts.view();
  const std::size_t ground = side * side * side;
  // The ground: the last body, immovable, at rest.
  ASSERT_EQ(b.count, ground + 1);
  EXPECT_EQ(b.inv_mass[ground], 0.0);
  EXPECT_EQ(b.v.x[ground], 0.0);
  EXPECT_EQ(b.v.z[ground], 0.0);
  EXPECT_EQ(b.w.y[ground], 0.0);
  for (std::size_t i = 0; i < ground; ++i) EXPECT_GT(b.inv_mass[i], 0.0) << i;
  std::set<std::pair<std::size_t, std::size_t>> touching;
  for (std::size_t k = 0; k < c.count; ++k) {
    SCOPED_TRACE(k);
    const std::size_t a = c.a[k], o = c.b[k];
    ASSERT_LT(a, ground);
    EXPECT_TRUE(touching.emplace(a, o).second) << "a second contact between " << a << " and " << o;
    const double n[3] = {c.n.x[k], c.n.y[k], c.n.z[k]};
    const double ra[3] = {c.c.x[k] - b.p.x[a], c.c.y[k] - b.p.y[a], c.c.z[k] - b.p.z[a]};
    int axis = 0;  // the lattice axis of the normal
    if (o == ground) {
      EXPECT_EQ(a / (side * side), 0U) << "only the bottom layer touches the ground";
      EXPECT_EQ(n[2], 1.0);  // from the ground (b) up to the box (a)
      axis = 2;
    } else {
      ASSERT_LT(o, ground);
      const double d[3] = {b.p.x[o] - b.p.x[a], b.p.y[o] - b.p.y[a], b.p.z[o] - b.p.z[a]};
      // A +x, +y or +z neighbour: one pitch along one axis.
      axis = d[0] == 1.0 ? 0 : d[1] == 1.0 ? 1 : 2;
      for (int j = 0; j < 3; ++j) EXPECT_EQ(d[j], j == axis ? 1.0 : 0.0);
      EXPECT_EQ(n[axis], -1.0);  // from the neighbour (b) towards the box (a)
      EXPECT_EQ(o - a, axis == 0 ? 1 : axis == 1 ? side : side * side);
    }
    for (int j = 0; j < 3; ++j) {
      if (j != axis) {
        EXPECT_EQ(n[j], 0.0);
        // Within the touching face, off the line of centres.
        EXPECT_LE(std::fabs(ra[j]), 0.4 + 1e-12);
      }
    }
    EXPECT_EQ(std::fabs(ra[axis]), 0.5) << "on the plane half way between the centres";
    const double off = std::hypot(ra[(axis + 1) % 3], ra[(axis + 2) % 3]);
    EXPECT_GT(off, 0.0) << "a contact point on the line of centres";
    EXPECT_TRUE(c.e[k] >= 0 && c.e[k] < 1);
    EXPECT_TRUE(c.mu[k] >= 0 && c.mu[k] < 1);
  }
  // Every lattice neighbour pair and every bottom box touches once.
  EXPECT_EQ(touching.size(), 3 * side * side * (side - 1) + side * side);
}

TEST(PileScene, BoxesAreTiltedBoxes) {
  const std::size_t side = 6;
  const auto scene = collide::generate_pile<double>(side, {8, false});
  for (std::size_t i = 0; i < side * side * side; ++i) {
    const auto r = scene.bodies.record(i);
    SCOPED_TRACE(i);
    EXPECT_TRUE(r.m >= 0.1 && r.m < 20.0001);
    // A box of edges in [0.9, 1): moments m (b^2 + c^2) / 12, each below
    // the sum of the other two, all different.
    for (int j = 0; j < 3; ++j) {
      EXPECT_GT(r.I[j] / r.m, 2 * 0.81 / 12 * 0.9999);
      EXPECT_LT(r.I[j] / r.m, 2.0 / 12 * 1.0001);
      EXPECT_LT(r.I[j], r.I[(j + 1) % 3] + r.I[(j + 2) % 3]);
    }
    EXPECT_NE(r.I[0], r.I[1]);
    // A small tilt: the rotation angle 2 acos(qw) is below |(0.05, 0.05, 0.05)|.
    const double norm = std::sqrt(r.q[0] * r.q[0] + r.q[1] * r.q[1] + r.q[2] * r.q[2] + r.q[3] * r.q[3]);
    EXPECT_NEAR(norm, 1.0, 1e-12);
    EXPECT_LT(2 * std::acos(std::min(1.0, r.q[0] / norm)), 0.0867);
    EXPECT_GT(std::fabs(r.q[1]) + std::fabs(r.q[2]) + std::fabs(r.q[3]), 0.0);
  }
}

TEST(PileScene, ApproachesInBothPrecisionsWithAMargin) {
  for (const collide::Model model : {collide::Model::rigid, collide::Model::sphere, collide::Model::particle}) {
    collide::GenerateOptions o{11, true, model};
    expect_valid_and_approaching(collide::generate_pile<double>(13, o));
    expect_valid_and_approaching(collide::generate_pile<float>(13, o));
  }
  // The largest pile, drawn item by item (its scene would not fit in
  // memory): coordinates to 1625 m, the top layer falling at 1625 m/s. The
  // documented 0.4 m/s margin holds in double and after rounding to float,
  // on the bottom layers, the top layers and a stride through the middle.
  const std::size_t side = collide::kMaxPileSide;
  const std::uint64_t n = collide::pile_contact_count(side);
  const collide::GenerateOptions o{2, false};
  std::size_t checked = 0;
  for (std::uint64_t k = 0; k < n; k += (k < 50000 || k + 50000 > n) ? 1 : 29989) {
    collide::ContactRecord<double> c;
    collide::BodyRecord<double> a, b;
    collide::draw_pile_contact(o, side, k, c);
    collide::draw_pile_body(o, side, c.a, a);
    collide::draw_pile_body(o, side, c.b, b);
    ASSERT_LT(record_approach_speed(a, b, c), -0.4) << k;
    ASSERT_LT(record_approach_speed(collide::detail::narrow<float>(a), collide::detail::narrow<float>(b),
                                    collide::detail::narrow<float>(c)),
              -0.399f)
        << k;
    ++checked;
  }
  EXPECT_GT(checked, 500000U);
  // Shuffled, its contacts come from anywhere in the pile, and approach.
  collide::GenerateOptions shuffled = o;
  shuffled.shuffle = true;
  std::uint64_t top_layer = 0;
  for (std::uint64_t k = 0; k < 20000; ++k) {
    collide::ContactRecord<double> c;
    collide::BodyRecord<double> a, b;
    collide::draw_pile_contact(shuffled, side, k, c);
    collide::draw_pile_body(shuffled, side, c.a, a);
    collide::draw_pile_body(shuffled, side, c.b, b);
    ASSERT_LT(record_approach_speed(a, b, c), -0.4) << k;
    top_layer += c.a >= (side - 2) * side * side ? 1 : 0;
  }
  EXPECT_GT(top_layer, 0U);
}

TEST(PileScene, NeedsTheRigidModel) {
  auto rigid = collide::generate_pile<double>(5, {4, false});
  const auto b = rigid.bodies.view();
  const auto c = rigid.contacts.view();
  EXPECT_EQ(collide::choose_model(b, c), collide::Model::rigid);
  EXPECT_FALSE(collide::model_misfit(collide::Model::sphere, b, c).empty());
  // The pile shaped for a smaller model fits it.
  for (const collide::Model model : {collide::Model::sphere, collide::Model::particle}) {
    auto s = collide::generate_pile<float>(5, {4, true, model});
    EXPECT_EQ(collide::model_misfit(model, s.bodies.view(), s.contacts.view()), "") << collide::to_string(model);
  }
}

/// `first`, drawn with seed 21 and friction: seed 22 draws another scene, and
/// without friction the first 100 contacts keep their e and bodies their
/// velocities, with mu = 0. `draw(options)` draws the same kind and size.
template <class Draw>
void expect_seed_and_friction_effects(const collide::Scene<double>& first, const Draw& draw) {
  const auto other = draw({22, true});
  EXPECT_NE(other.contacts.record(0).c[1], first.contacts.record(0).c[1]);
  EXPECT_NE(other.bodies.record(0).m, first.bodies.record(0).m);
  const auto frictionless = draw({21, false});
  for (std::size_t k = 0; k < 100; ++k) {
    EXPECT_EQ(frictionless.contacts.record(k).mu, 0.0);
    EXPECT_GT(first.contacts.record(k).mu, 0.0);
    EXPECT_EQ(frictionless.contacts.record(k).e, first.contacts.record(k).e);
    EXPECT_EQ(frictionless.bodies.record(k).v[0], first.bodies.record(k).v[0]);
  }
}

TEST(PileScene, PureFunctionOfSideOptionsAndSeed) {
  const collide::GenerateOptions o{21, true};
  const std::size_t side = 24;  // 13825 bodies, 40320 contacts: several blocks of work
  const auto first = collide::generate_pile<double>(side, o);
  EXPECT_TRUE(same_bits(first, collide::generate_pile<double>(side, o)));
  {
    oneapi::tbb::global_control one(oneapi::tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(same_bits(first, collide::generate_pile<double>(side, o))) << "one thread";
  }
  {
    oneapi::tbb::global_control four(oneapi::tbb::global_control::max_allowed_parallelism, 4);
    EXPECT_TRUE(same_bits(first, collide::generate_pile<double>(side, o))) << "four threads";
  }
  // The pieces `collide gen` streams are the scene's items.
  for (const std::uint64_t i : {0u, 1u, 600u, 13823u, 13824u}) {
    collide::BodyRecord<double> body;
    collide::draw_pile_body(o, side, i, body);
    EXPECT_EQ(first.bodies.view().v.x[i], body.v[0]) << i;
    EXPECT_EQ(first.bodies.view().q.z[i], body.q[3]) << i;
  }
  for (const std::uint64_t k : {0u, 5u, 20000u, 40319u}) {
    collide::ContactRecord<double> contact;
    collide::draw_pile_contact(o, side, k, contact);
    const auto got = first.contacts.record(k);
    EXPECT_EQ(got.a, contact.a);
    EXPECT_EQ(got.b, contact.b);
    EXPECT_EQ(got.c[1], contact.c[1]);
    EXPECT_EQ(got.e, contact.e);
    EXPECT_EQ(got.mu, contact.mu);
  }
  expect_seed_and_friction_effects(
      first, [&](const collide::GenerateOptions& g) { return collide::generate_pile<double>(side, g); });
}

TEST(PileScene, FloatIsTheDoubleDrawRoundedOnce) {
  const collide::GenerateOptions o{6, true};
  const std::size_t side = 11;
  const auto f = collide::generate_pile<float>(side, o);
  const auto d = collide::generate_pile<double>(side, o);
  // The float scene is the double draws narrowed (scene.hpp), value by value.
  collide::Scene<float> narrowed;
  narrowed.bodies.resize(collide::pile_body_count(side));
  narrowed.contacts.resize(collide::pile_contact_count(side));
  for (std::size_t i = 0; i < narrowed.bodies.size(); ++i) {
    collide::BodyRecord<double> body;
    collide::draw_pile_body(o, side, i, body);
    narrowed.bodies.set(i, collide::detail::narrow<float>(body));
  }
  for (std::size_t k = 0; k < narrowed.contacts.size(); ++k) {
    collide::ContactRecord<double> contact;
    collide::draw_pile_contact(o, side, k, contact);
    narrowed.contacts.set(k, collide::detail::narrow<float>(contact));
  }
  EXPECT_TRUE(same_bits(f, narrowed));
  // The stored columns are the double scene's, each rounded once.
  const auto fb = f.bodies.view();
  const auto db = d.bodies.view();
  for (std::size_t i = 0; i < fb.count; ++i) {
    ASSERT_EQ(fb.p.x[i], static_cast<float>(db.p.x[i]));
    ASSERT_EQ(fb.v.z[i], static_cast<float>(db.v.z[i]));
    ASSERT_EQ(fb.w.y[i], static_cast<float>(db.w.y[i]));
    ASSERT_EQ(fb.q.w[i], static_cast<float>(db.q.w[i]));
  }
  const auto fc = f.contacts.view();
  const auto dc = d.contacts.view();
  for (std::size_t k = 0; k < fc.count; ++k) {
    ASSERT_EQ(fc.a[k], dc.a[k]);
    ASSERT_EQ(fc.b[k], dc.b[k]);
    ASSERT_EQ(fc.c.y[k], static_cast<float>(dc.c.y[k]));
    ASSERT_EQ(fc.n.z[k], static_cast<float>(dc.n.z[k]));
    ASSERT_EQ(fc.e[k], static_cast<float>(dc.e[k]));
    ASSERT_EQ(fc.mu[k], static_cast<float>(dc.mu[k]));
  }
}

TEST(PileScene, ShuffleIsADeterministicPermutation) {
  for (const std::size_t side : {1U, 2U, 3U, 10U, 17U}) {
    SCOPED_TRACE(side);
    collide::GenerateOptions o{5, true};
    const auto ordered = collide::generate_pile<double>(side, o);
    o.shuffle = true;
    const auto shuffled = collide::generate_pile<double>(side, o);
    EXPECT_TRUE(same_bits(shuffled, collide::generate_pile<double>(side, o)));
    {
      oneapi::tbb::global_control one(oneapi::tbb::global_control::max_allowed_parallelism, 1);
      EXPECT_TRUE(same_bits(shuffled, collide::generate_pile<double>(side, o))) << "one thread";
    }
    // The same bodies; the same contacts, each once, with the same values.
    collide::Scene<double> bodies_only = ordered;
    bodies_only.contacts = shuffled.contacts;
    EXPECT_TRUE(same_bits(bodies_only, shuffled));
    const std::size_t n = ordered.contacts.size();
    ASSERT_EQ(shuffled.contacts.size(), n);
    std::vector<std::size_t> ordered_index(ordered.bodies.size() * 4, n);
    const auto slot = [&](const collide::ContactRecord<double>& r) {
      // The neighbour's direction identifies the contact of a box.
      const std::size_t d = r.b == ordered.bodies.size() - 1 ? 3 : r.b - r.a == 1 ? 0 : r.b - r.a == side ? 1 : 2;
      return 4 * std::size_t{r.a} + d;
    };
    for (std::size_t k = 0; k < n; ++k) ordered_index[slot(ordered.contacts.record(k))] = k;
    std::vector<int> seen(n, 0);
    std::size_t moved = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const auto r = shuffled.contacts.record(k);
      const std::size_t from = ordered_index[slot(r)];
      ASSERT_LT(from, n);
      ++seen[from];
      const auto o_r = ordered.contacts.record(from);
      ASSERT_EQ(
          std::make_tuple(r.a, r.b, r.c[0], r.c[1], r.c[2], r.n[0], r.n[1], r.n[2], r.e, r.mu),
          std::make_tuple(o_r.a, o_r.b, o_r.c[0], o_r.c[1], o_r.c[2], o_r.n[0], o_r.n[1], o_r.n[2], o_r.e, o_r.mu));
      moved += from != k ? 1 : 0;
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int s) { return s == 1; }));
    if (n >= 100) {
      EXPECT_GT(moved, n * 9 / 10) << "hardly shuffled";
    }
    expect_valid_and_approaching(shuffled);
  }
  // Another seed, another order.
  collide::GenerateOptions a{5, false}, b{6, false};
  a.shuffle = b.shuffle = true;
  const auto sa = collide::generate_pile<float>(10, a);
  const auto sb = collide::generate_pile<float>(10, b);
  std::size_t same_place = 0;
  for (std::size_t k = 0; k < sa.contacts.size(); ++k) {
    same_place +=
        sa.contacts.record(k).a == sb.contacts.record(k).a && sa.contacts.record(k).b == sb.contacts.record(k).b;
  }
  EXPECT_LT(same_place, sa.contacts.size() / 10);
}

TEST(PileScene, SizesAndLimits) {
  EXPECT_EQ(collide::pile_side_for_contacts(0), 0U);
  EXPECT_EQ(collide::pile_side_for_contacts(1), 1U);
  EXPECT_EQ(collide::pile_side_for_contacts(15), 1U);
  EXPECT_EQ(collide::pile_side_for_contacts(16), 2U);  // 2^3 boxes: 12 + 4 contacts
  EXPECT_EQ(collide::pile_side_for_contacts(20000), 19U);
  EXPECT_EQ(collide::pile_side_for_contacts(1000000), 69U);
  EXPECT_EQ(collide::pile_contact_count(69), 976005U);
  EXPECT_EQ(collide::pile_side_for_contacts(std::size_t{1} << 62), collide::kMaxPileSide);
  // The largest pile's ids fit 32 bits, one more box per side does not.
  EXPECT_LE(collide::pile_body_count(collide::kMaxPileSide) - 1, std::size_t{0xFFFFFFFF});
  EXPECT_GT(collide::pile_body_count(collide::kMaxPileSide + 1) - 1, std::size_t{0xFFFFFFFF});
  EXPECT_THROW(collide::generate_pile<float>(collide::kMaxPileSide + 1), std::invalid_argument);
  const auto empty = collide::generate_pile<double>(0);
  EXPECT_EQ(empty.bodies.size(), 1U);
  EXPECT_EQ(empty.contacts.size(), 0U);
  EXPECT_EQ(empty.bodies.view().inv_mass[0], 0.0);
  expect_valid_and_approaching(collide::generate_pile<double>(1));
  expect_valid_and_approaching(collide::generate_pile<float>(2));
}

// ---------------------------------------------------------------------------
// The chain.
// ---------------------------------------------------------------------------

/// Every contact of a scene approaches by more than `margin`, u . n computed
/// in double from the stored bodies and contacts (a float scene widened
/// exactly), with the pile's helper.
template <class T>
void expect_approaching_in_double(const collide::Scene<T>& scene, double margin) {
  const collide::Scene<double> wide = collide::convert_scene<double>(scene);
  const auto b = wide.bodies.view();
  const auto c = wide.contacts.view();
  for (std::size_t k = 0; k < c.count; ++k) {
    ASSERT_LT(approach_speed(b, c, k), -margin) << "contact " << k;
  }
}

/// The centre of box i of the chain before its draws: cell ((i + 1) / 2,
/// i / 2, 0) + 0.5, written out here so the test does not share the code.
std::array<double, 3> staircase_centre(std::uint64_t i) {
  const std::uint64_t x = (i + 1) / 2;
  const std::uint64_t y = i / 2;
  return {static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5, 0.5};
}

/// The velocity of box i before its jitter: (0.5, -0.5, 0) for even i, its
/// opposite for odd i.
std::array<double, 3> staircase_velocity(std::uint64_t i) {
  const double s = i % 2 == 0 ? 0.5 : -0.5;
  return {s, -s, 0.0};
}

TEST(ChainScene, CountsOrderAndStaircase) {
  for (const std::size_t n : {0U, 1U, 2U, 3U, 7U, 1000U}) {
    SCOPED_TRACE(n);
    const auto scene = collide::generate_chain<double>(n, {3, true});
    ASSERT_EQ(scene.bodies.size(), n + 1);
    ASSERT_EQ(collide::chain_body_count(n), n + 1);
    ASSERT_EQ(scene.contacts.size(), n);
    const auto b = scene.bodies.view();
    const auto c = scene.contacts.view();
    // No ground: every box is movable, on its cell of the staircase.
    std::map<std::pair<std::int64_t, std::int64_t>, std::size_t> cell_of_box;
    for (std::size_t i = 0; i < b.count; ++i) {
      SCOPED_TRACE(i);
      ASSERT_GT(b.inv_mass[i], 0.0);
      const auto p = staircase_centre(i);
      ASSERT_EQ(b.p.x[i], p[0]);
      ASSERT_EQ(b.p.y[i], p[1]);
      ASSERT_EQ(b.p.z[i], p[2]);
      // Box i + 1 is box i's +x neighbour for even i, its +y one for odd i.
      if (i + 1 < b.count) {
        ASSERT_EQ(b.p.x[i + 1] - b.p.x[i], i % 2 == 0 ? 1.0 : 0.0);
        ASSERT_EQ(b.p.y[i + 1] - b.p.y[i], i % 2 == 0 ? 0.0 : 1.0);
        ASSERT_EQ(b.p.z[i + 1], b.p.z[i]);
      }
      const auto cell = std::make_pair(static_cast<std::int64_t>(std::floor(b.p.x[i])),
                                       static_cast<std::int64_t>(std::floor(b.p.y[i])));
      ASSERT_TRUE(cell_of_box.emplace(cell, i).second) << "two boxes in one cell";
    }
    // Only consecutive boxes share a face (the staircase lies in one layer, so
    // the faces that can touch are along x and y).
    for (const auto& [cell, i] : cell_of_box) {
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const auto it = cell_of_box.find({cell.first + dx, cell.second + dy});
        if (it != cell_of_box.end()) {
          ASSERT_EQ(std::max(i, it->second) - std::min(i, it->second), 1U) << "boxes " << i << ", " << it->second;
        }
      }
    }
    for (std::size_t k = 0; k < c.count; ++k) {
      SCOPED_TRACE(k);
      ASSERT_EQ(c.a[k], k);
      ASSERT_EQ(c.b[k], k + 1);
      // The pile's +x (even k) or +y (odd k) contact of box k: the normal from
      // b towards a, the point on the plane between the centres, off the line
      // of centres within the face.
      const bool along_x = k % 2 == 0;
      EXPECT_EQ(c.n.x[k], along_x ? -1.0 : 0.0);
      EXPECT_EQ(c.n.y[k], along_x ? 0.0 : -1.0);
      EXPECT_EQ(c.n.z[k], 0.0);
      const double r[3] = {c.c.x[k] - b.p.x[k], c.c.y[k] - b.p.y[k], c.c.z[k] - b.p.z[k]};
      const int normal_axis = along_x ? 0 : 1;
      const int face_axis = along_x ? 1 : 0;
      EXPECT_EQ(r[normal_axis], 0.5);
      EXPECT_LE(std::fabs(r[face_axis]), 0.4 + 1e-12);
      EXPECT_LE(std::fabs(r[2]), 0.4 + 1e-12);
      EXPECT_GT(std::hypot(r[face_axis], r[2]), 0.0) << "a contact point on the line of centres";
      EXPECT_TRUE(c.e[k] >= 0 && c.e[k] < 1);
      EXPECT_TRUE(c.mu[k] >= 0 && c.mu[k] < 1);
    }
  }
}

TEST(ChainScene, BoxesAreThePilesBoxesAtBoundedSpeeds) {
  const auto scene = collide::generate_chain<double>(200, {8, false});
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const auto r = scene.bodies.record(i);
    SCOPED_TRACE(i);
    EXPECT_TRUE(r.m >= 0.1 && r.m < 20.0001);
    for (int j = 0; j < 3; ++j) {
      EXPECT_GT(r.I[j] / r.m, 2 * 0.81 / 12 * 0.9999);
      EXPECT_LT(r.I[j] / r.m, 2.0 / 12 * 1.0001);
      EXPECT_LT(r.I[j], r.I[(j + 1) % 3] + r.I[(j + 2) % 3]);
    }
    EXPECT_LT(2 * std::acos(std::min(1.0, r.q[0])), 0.0867);
    // (0.5, -0.5, 0) m/s for even boxes, the opposite for odd ones, plus up
    // to 0.1 m/s per axis; spinning at up to 0.25 rad/s per axis.
    const auto v = staircase_velocity(i);
    for (int j = 0; j < 3; ++j) {
      EXPECT_LE(std::fabs(r.v[j] - v[j]), 0.1) << j;
      EXPECT_LE(std::fabs(r.w[j]), 0.25) << j;
    }
  }
}

TEST(ChainScene, EveryContactApproachesAtBoundedSpeeds) {
  for (const collide::Model model : {collide::Model::rigid, collide::Model::sphere, collide::Model::particle}) {
    for (const bool friction : {false, true}) {
      SCOPED_TRACE(collide::to_string(model));
      for (const std::size_t n : {1U, 2U, 3U, 3000U}) {
        SCOPED_TRACE(n);
        const collide::GenerateOptions o{11, friction, model};
        expect_valid_and_approaching(collide::generate_chain<double>(n, o));
        expect_valid_and_approaching(collide::generate_chain<float>(n, o));
        // The documented 0.4 m/s margin, from the stored values in double.
        expect_approaching_in_double(collide::generate_chain<double>(n, o), 0.4);
        expect_approaching_in_double(collide::generate_chain<float>(n, o), 0.4);
      }
    }
  }
  // A long chain in float, 2^20 contacts: the speeds do not grow along it, so
  // every contact keeps the margin (float rounds the contact points of the
  // far boxes to a 16th of a metre, which could cost 0.016 m/s; they keep
  // more than 0.5 m/s), and every speed stays within 0.6 m/s per axis.
  {
    const auto f = collide::generate_chain<float>(std::size_t{1} << 20, {2, false});
    expect_valid_and_approaching(f);
    expect_approaching_in_double(f, 0.4);
    const auto b = f.bodies.view();
    float fastest = 0;
    for (std::size_t i = 0; i < b.count; ++i) {
      fastest = std::max({fastest, std::fabs(b.v.x[i]), std::fabs(b.v.y[i]), std::fabs(b.v.z[i])});
    }
    EXPECT_LE(fastest, 0.6F);
    EXPECT_GT(fastest, 0.59F);
    EXPECT_EQ(b.p.x[b.count - 1], 524288.5F);  // the last box, 2^20, in cell (2^19, 2^19)
    EXPECT_EQ(b.p.y[b.count - 1], 524288.5F);
  }
  // The benchmark's largest chain, 4Mi contacts, and the tail of the longest
  // chain there may be, drawn item by item: in double (and for the 4Mi, in
  // float too) every contact approaches by 0.4 m/s, at speeds within 0.6 m/s.
  const collide::GenerateOptions o{2, false};
  const auto check = [&](std::size_t n, std::uint64_t from, bool in_float) {
    SCOPED_TRACE(n);
    double fastest = 0;
    for (std::uint64_t k = from; k < n; ++k) {
      collide::ContactRecord<double> c;
      collide::BodyRecord<double> a, b;
      collide::draw_chain_contact(o, n, k, c);
      collide::draw_chain_body(o, n, c.a, a);
      collide::draw_chain_body(o, n, c.b, b);
      ASSERT_LT(record_approach_speed(a, b, c), -0.4) << k;
      if (in_float) {
        const auto af = collide::detail::narrow<double>(collide::detail::narrow<float>(a));
        const auto bf = collide::detail::narrow<double>(collide::detail::narrow<float>(b));
        const auto cf = collide::detail::narrow<double>(collide::detail::narrow<float>(c));
        ASSERT_LT(record_approach_speed(af, bf, cf), -0.4) << k;
      }
      for (int j = 0; j < 3; ++j) fastest = std::max({fastest, std::fabs(a.v[j]), std::fabs(b.v[j])});
      // The staircase holds at any length.
      const auto pa = staircase_centre(k);
      ASSERT_EQ(a.p[0], pa[0]) << k;
      ASSERT_EQ(a.p[1], pa[1]) << k;
      ASSERT_EQ(b.p[0] - a.p[0], k % 2 == 0 ? 1.0 : 0.0) << k;
      ASSERT_EQ(b.p[1] - a.p[1], k % 2 == 0 ? 0.0 : 1.0) << k;
    }
    EXPECT_LE(fastest, 0.6);
    EXPECT_LE(fastest, 1.0);
  };
  check(std::size_t{1} << 22, 0, true);
  check(collide::kMaxChainContacts, collide::kMaxChainContacts - 100000, false);
}

TEST(ChainScene, PureFunctionOfSeedAndK) {
  const collide::GenerateOptions o{21, true};
  const std::size_t n = 20000;  // several blocks of work
  const auto first = collide::generate_chain<double>(n, o);
  EXPECT_TRUE(same_bits(first, collide::generate_chain<double>(n, o)));
  {
    oneapi::tbb::global_control one(oneapi::tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(same_bits(first, collide::generate_chain<double>(n, o))) << "one thread";
  }
  // The streaming pieces are the scene's items.
  for (const std::uint64_t i : {0u, 1u, 9999u, 20000u}) {
    collide::BodyRecord<double> body;
    collide::draw_chain_body(o, n, i, body);
    EXPECT_EQ(first.bodies.view().v.x[i], body.v[0]) << i;
    EXPECT_EQ(first.bodies.view().q.z[i], body.q[3]) << i;
    EXPECT_EQ(first.bodies.view().inv_mass[i], 1.0 / body.m) << i;
  }
  for (const std::uint64_t k : {0u, 5u, 12345u, 19999u}) {
    collide::ContactRecord<double> contact;
    collide::draw_chain_contact(o, n, k, contact);
    const auto got = first.contacts.record(k);
    EXPECT_EQ(got.a, contact.a);
    EXPECT_EQ(got.b, contact.b);
    EXPECT_EQ(got.c[1], contact.c[1]);
    EXPECT_EQ(got.c[2], contact.c[2]);
    EXPECT_EQ(got.e, contact.e);
    EXPECT_EQ(got.mu, contact.mu);
  }
  // Neither a contact nor a box depends on the chain's length.
  const auto shorter = collide::generate_chain<double>(100, o);
  EXPECT_EQ(shorter.contacts.record(77).c[1], first.contacts.record(77).c[1]);
  EXPECT_EQ(shorter.contacts.record(77).e, first.contacts.record(77).e);
  EXPECT_EQ(shorter.bodies.record(77).v[0], first.bodies.record(77).v[0]);
  EXPECT_EQ(shorter.bodies.record(78).p[1], first.bodies.record(78).p[1]);
  expect_seed_and_friction_effects(
      first, [&](const collide::GenerateOptions& g) { return collide::generate_chain<double>(n, g); });
  // Not the pile's values: the chain draws from streams of its own.
  const auto pile = collide::generate_pile<double>(2, o);
  EXPECT_NE(pile.bodies.record(0).m, first.bodies.record(0).m);
  EXPECT_NE(pile.contacts.record(0).c[1], first.contacts.record(0).c[1]);
}

TEST(ChainScene, FloatAndDoubleAgreeWithinRounding) {
  const collide::GenerateOptions o{6, true};
  const std::size_t n = 5000;
  const auto f = collide::generate_chain<float>(n, o);
  const auto d = collide::generate_chain<double>(n, o);
  // The float scene is the double one, each value rounded once.
  const auto fb = f.bodies.view();
  const auto db = d.bodies.view();
  ASSERT_EQ(fb.count, db.count);
  const auto near = [](double x, double y) { return std::fabs(x - y) <= 0x1p-24 * std::fabs(y); };
  for (std::size_t i = 0; i < fb.count; ++i) {
    SCOPED_TRACE(i);
    ASSERT_EQ(fb.p.x[i], static_cast<float>(db.p.x[i]));
    ASSERT_EQ(fb.v.x[i], static_cast<float>(db.v.x[i]));
    ASSERT_EQ(fb.w.y[i], static_cast<float>(db.w.y[i]));
    ASSERT_EQ(fb.q.w[i], static_cast<float>(db.q.w[i]));
    ASSERT_TRUE(near(fb.v.z[i], db.v.z[i]));
    // Inverse mass and moments are the rounded draws' inverses, within a float rounding or two.
    ASSERT_NEAR(fb.inv_mass[i], db.inv_mass[i], 2 * 0x1p-24 * db.inv_mass[i]);
    ASSERT_NEAR(fb.inv_inertia.z[i], db.inv_inertia.z[i], 2 * 0x1p-24 * db.inv_inertia.z[i]);
  }
  const auto fc = f.contacts.view();
  const auto dc = d.contacts.view();
  ASSERT_EQ(fc.count, dc.count);
  for (std::size_t k = 0; k < fc.count; ++k) {
    SCOPED_TRACE(k);
    ASSERT_EQ(fc.a[k], dc.a[k]);
    ASSERT_EQ(fc.b[k], dc.b[k]);
    ASSERT_EQ(fc.c.y[k], static_cast<float>(dc.c.y[k]));
    ASSERT_EQ(fc.n.x[k], static_cast<float>(dc.n.x[k]));
    ASSERT_EQ(fc.e[k], static_cast<float>(dc.e[k]));
    ASSERT_EQ(fc.mu[k], static_cast<float>(dc.mu[k]));
    ASSERT_TRUE(near(fc.c.z[k], dc.c.z[k]));
  }
}

TEST(ChainScene, FitsEachModel) {
  auto rigid = collide::generate_chain<double>(500, {4, false});
  const auto b = rigid.bodies.view();
  const auto c = rigid.contacts.view();
  EXPECT_EQ(collide::choose_model(b, c), collide::Model::rigid);
  EXPECT_FALSE(collide::model_misfit(collide::Model::sphere, b, c).empty());
  EXPECT_FALSE(collide::model_misfit(collide::Model::particle, b, c).empty());
  for (const collide::Model model : {collide::Model::rigid, collide::Model::sphere, collide::Model::particle}) {
    for (const bool friction : {false, true}) {
      auto d = collide::generate_chain<double>(500, {4, friction, model});
      EXPECT_EQ(collide::model_misfit(model, d.bodies.view(), d.contacts.view()), "") << collide::to_string(model);
      auto f = collide::generate_chain<float>(500, {4, friction, model});
      EXPECT_EQ(collide::model_misfit(model, f.bodies.view(), f.contacts.view()), "") << collide::to_string(model);
      EXPECT_EQ(collide::choose_model(f.bodies.view(), f.contacts.view()), model) << collide::to_string(model);
    }
  }
}

TEST(ChainScene, ScheduleIsOneBatchPerContact) {
  auto d = collide::generate_chain<double>(1000, {7, true});
  collide::Schedule schedule;
  schedule.build(d.contacts.view(), d.bodies.view());
  EXPECT_EQ(schedule.contact_count(), 1000U);
  EXPECT_EQ(schedule.batch_count(), 1000U);
  EXPECT_EQ(schedule.largest_batch(), 1U);
  // Batch k is contact k: the law runs through the staircase in chain order.
  for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
    ASSERT_EQ(schedule.batch_begin(k), k);
    ASSERT_EQ(schedule.solve_order()[k], k);
  }
  auto f = collide::generate_chain<float>(1000, {7, false, collide::Model::particle});
  collide::Schedule float_schedule;
  float_schedule.build(f.contacts.view(), f.bodies.view(), 2);
  EXPECT_EQ(float_schedule.batch_count(), 1000U);
}

TEST(ChainScene, SizesAndLimits) {
  EXPECT_EQ(collide::chain_body_count(0), 1U);
  EXPECT_EQ(collide::chain_body_count(4194304), 4194305U);
  // The longest chain's ids fit 32 bits, and so do its last contact's.
  EXPECT_EQ(collide::kMaxChainContacts, std::size_t{0xFFFFFFFE});
  EXPECT_LE(collide::chain_body_count(collide::kMaxChainContacts) - 1, std::size_t{0xFFFFFFFF});
  collide::ContactRecord<double> last;
  collide::draw_chain_contact({}, collide::kMaxChainContacts, collide::kMaxChainContacts - 1, last);
  EXPECT_EQ(last.a, 0xFFFFFFFDU);
  EXPECT_EQ(last.b, 0xFFFFFFFEU);
  EXPECT_THROW(collide::generate_chain<float>(collide::kMaxChainContacts + 1), std::invalid_argument);
  EXPECT_THROW(collide::generate_chain<double>(std::size_t{1} << 40), std::invalid_argument);
  const auto empty = collide::generate_chain<double>(0);
  EXPECT_EQ(empty.bodies.size(), 1U);
  EXPECT_EQ(empty.contacts.size(), 0U);
  EXPECT_GT(empty.bodies.view().inv_mass[0], 0.0);
  expect_valid_and_approaching(collide::generate_chain<double>(1));
  expect_valid_and_approaching(collide::generate_chain<float>(2));
}

}  // namespace
