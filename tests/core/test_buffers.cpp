// test_buffers.cpp - the owning buffers of the core (core/src/buffers.cpp,
// collide/bodies.hpp, collide/contacts.hpp).
//
// What this proves
// ----------------
// * BodyBuffer stores what the kernels consume: 1/m and 1/I, 0 for an
//   infinite mass or moment; an immovable body (m = inf) gets zero inverse
//   moments whatever its I; q is stored as given (the kernels normalise it);
//   p, v, w are copied bit for bit (-0.0 included). record() gives the
//   physical values back (1/0 = inf), set() overwrites one body, resize()
//   makes identity-oriented bodies.
// * ContactBuffer stores n as given and copies everything else bit for bit;
//   its view drops mu (frictionless) exactly when every mu is 0; record() and
//   set() round-trip. A normal off unit by more than the files' tolerance is
//   refused (every rule is test_rules.cpp's).
// The precision conversion of scenes is io's (tests/io/test_scene_convert.cpp).
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide::test {
namespace {

template <class T>
class Buffers : public ::testing::Test {};
using Precisions = ::testing::Types<float, double, long double>;
TYPED_TEST_SUITE(Buffers, Precisions);

TYPED_TEST(Buffers, BodyPushBackStoresInverses) {
  using T = TypeParam;
  const T inf = std::numeric_limits<T>::infinity();
  BodyBuffer<T> b;
  BodyRecord<T> r;
  r.m = 4;
  r.I[0] = 2, r.I[1] = inf, r.I[2] = T(0.5);
  r.q[0] = 1, r.q[1] = 1, r.q[2] = 1, r.q[3] = 1;  // |q| = 2
  r.p[0] = T(-0.0), r.p[1] = T(1.25), r.p[2] = T(3);
  r.v[0] = T(-0.0), r.v[1] = T(2), r.v[2] = T(-7.5);
  r.w[0] = T(0.1), r.w[1] = T(-0.0), r.w[2] = T(9);
  b.push_back(r);
  BodyRecord<T> g = r;  // immovable, finite moments
  g.m = inf;
  g.I[1] = 3;
  b.push_back(g);
  ASSERT_EQ(b.size(), 2u);
  const BodyView<const T> v = std::as_const(b).view();
  EXPECT_EQ(v.count, 2u);
  EXPECT_EQ(v.inv_mass[0], T(0.25));
  EXPECT_EQ(v.inv_inertia.x[0], T(0.5));
  EXPECT_EQ(v.inv_inertia.y[0], T(0));  // inf moment: no rotation about y
  EXPECT_EQ(v.inv_inertia.z[0], T(2));
  // q as given (|q| = 2): the kernels normalise it, as the law says.
  for (const T* q : {v.q.w, v.q.x, v.q.y, v.q.z}) EXPECT_EQ(q[0], T(1));
  EXPECT_TRUE(std::signbit(v.p.x[0]));
  EXPECT_TRUE(std::signbit(v.v.x[0]));
  EXPECT_TRUE(std::signbit(v.w.y[0]));
  EXPECT_EQ(v.w.x[0], T(0.1));
  EXPECT_EQ(v.v.z[0], T(-7.5));
  // Immovable whatever its I.
  EXPECT_EQ(v.inv_mass[1], T(0));
  EXPECT_EQ(v.inv_inertia.x[1], T(0));
  EXPECT_EQ(v.inv_inertia.y[1], T(0));
  EXPECT_EQ(v.inv_inertia.z[1], T(0));
  EXPECT_TRUE(is_immovable(v, 1));
  EXPECT_FALSE(is_immovable(v, 0));

  // record() inverts: 1/0 = inf.
  const BodyRecord<T> back = b.record(0);
  EXPECT_EQ(back.m, T(4));
  EXPECT_EQ(back.I[0], T(2));
  EXPECT_EQ(back.I[1], inf);
  EXPECT_EQ(back.I[2], T(0.5));
  EXPECT_EQ(back.q[0], T(1));  // q as given
  EXPECT_EQ(b.record(1).m, inf);
  EXPECT_EQ(b.record(1).I[1], inf);

  // set() overwrites one body; resize() appends identity-oriented bodies.
  BodyRecord<T> s;
  s.m = 8;
  b.set(1, s);
  EXPECT_EQ(std::as_const(b).view().inv_mass[1], T(0.125));
  b.resize(3);
  EXPECT_EQ(std::as_const(b).view().q.w[2], T(1));
  EXPECT_EQ(std::as_const(b).view().q.x[2], T(0));
  // The mutable and the const view share the arrays.
  EXPECT_EQ(b.view().v.x, std::as_const(b).view().v.x);
}

TYPED_TEST(Buffers, ContactPushBackStoresTheNormalAsGiven) {
  using T = TypeParam;
  ContactBuffer<T> c;
  ContactRecord<T> r;
  r.a = 3;
  r.b = 7;
  r.c[0] = T(-0.0), r.c[1] = T(1.5), r.c[2] = T(2);
  // A normal must be unit within kNormalTolerance (collide/rules.hpp).
  r.n[0] = 0, r.n[1] = 0, r.n[2] = 2;
  r.e = T(0.25);
  r.mu = 0;
  EXPECT_THROW(c.push_back(r), std::invalid_argument);
  EXPECT_EQ(c.size(), 0u);
  r.n[2] = T(1.0005);
  c.push_back(r);
  r.n[0] = 0, r.n[1] = T(0.6), r.n[2] = T(0.8);
  c.push_back(r);
  const ContactView<T> v = c.view();
  ASSERT_EQ(v.count, 2u);
  EXPECT_EQ(v.a[0], 3u);
  EXPECT_EQ(v.b[0], 7u);
  EXPECT_TRUE(std::signbit(v.c.x[0]));
  // Not renormalised: the kernels normalise n, so the accurate mode sees the
  // caller's value.
  EXPECT_EQ(v.n.z[0], T(1.0005));
  EXPECT_EQ(v.n.y[1], T(0.6));
  EXPECT_EQ(v.n.z[1], T(0.8));
  EXPECT_EQ(v.e[1], T(0.25));
  // Every mu is 0: the view is frictionless.
  EXPECT_FALSE(c.has_friction());
  EXPECT_EQ(v.mu, nullptr);
  // One mu > 0: the view carries mu.
  ContactRecord<T> f = c.record(1);
  f.mu = T(0.5);
  c.set(1, f);
  EXPECT_TRUE(c.has_friction());
  ASSERT_NE(c.view().mu, nullptr);
  EXPECT_EQ(c.view().mu[1], T(0.5));
  EXPECT_EQ(c.view().mu[0], T(0));
  // record() round-trips (n as stored).
  const ContactRecord<T> back = c.record(1);
  EXPECT_EQ(back.a, 3u);
  EXPECT_EQ(back.n[1], v.n.y[1]);
  EXPECT_EQ(back.e, T(0.25));
  c.resize(3);
  EXPECT_EQ(c.view().n.z[2], T(1));
}

}  // namespace
}  // namespace collide::test
