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
// * Each model's field table (kRigidFields, kSphereFields, kParticleFields)
//   names every array of its view once, in member order, with its role:
//   for_each_array, which the checks walk, reaches exactly the member a
//   view sets by hand; the packed records' fields land on their values
//   (record_slot against offsetof, test_packed.cpp's layout).
// The precision conversion of scenes is io's (tests/io/test_scene_convert.cpp).
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/packed.hpp"

namespace collide::test {
namespace {

/// What for_each_array reported of one array.
struct Visited {
  std::string name;
  const float* array;
  ArrayRole role;
};

template <class View>
std::vector<Visited> visit(const View& view) {
  std::vector<Visited> out;
  for_each_array(view, [&](const char* name, const float* array, ArrayRole role) {
    out.push_back({name, array, role});
  });
  return out;
}

/// Expects the walk to give exactly these arrays, in this order.
void expect_walk(const std::vector<Visited>& walked, const std::vector<Visited>& expected) {
  ASSERT_EQ(walked.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    SCOPED_TRACE(expected[k].name);
    EXPECT_EQ(walked[k].name, expected[k].name);
    EXPECT_EQ(walked[k].array, expected[k].array);
    EXPECT_EQ(walked[k].role, expected[k].role);
  }
}

TEST(FieldTables, RigidTableNamesEveryMemberOfTheViewOnce) {
  float storage[17] = {};
  const float* s = storage;
  // Every member set by hand, to its own array, in declaration order.
  const BodyView<const float> b{1,
                                s + 0,
                                {s + 1, s + 2, s + 3},
                                {s + 4, s + 5, s + 6, s + 7},
                                {s + 8, s + 9, s + 10},
                                {s + 11, s + 12, s + 13},
                                {s + 14, s + 15, s + 16}};
  const ArrayRole inv = ArrayRole::inverse, state = ArrayRole::state, vel = ArrayRole::velocity;
  expect_walk(visit(b), {{"inv_mass", s + 0, inv},
                         {"inv_inertia.x", s + 1, inv},
                         {"inv_inertia.y", s + 2, inv},
                         {"inv_inertia.z", s + 3, inv},
                         {"q.w", s + 4, state},
                         {"q.x", s + 5, state},
                         {"q.y", s + 6, state},
                         {"q.z", s + 7, state},
                         {"p.x", s + 8, state},
                         {"p.y", s + 9, state},
                         {"p.z", s + 10, state},
                         {"v.x", s + 11, vel},
                         {"v.y", s + 12, vel},
                         {"v.z", s + 13, vel},
                         {"w.x", s + 14, vel},
                         {"w.y", s + 15, vel},
                         {"w.z", s + 16, vel}});
  EXPECT_EQ(kFieldCount<BodyView<float>>, 17u);
}

TEST(FieldTables, SphereAndParticleTablesNameEveryMemberOfTheirViewsOnce) {
  float storage[11] = {};
  const float* s = storage;
  const SphereView<const float> sphere{
      1, s + 0, s + 1, {s + 2, s + 3, s + 4}, {s + 5, s + 6, s + 7}, {s + 8, s + 9, s + 10}};
  const ArrayRole inv = ArrayRole::inverse, state = ArrayRole::state, vel = ArrayRole::velocity;
  expect_walk(visit(sphere), {{"inv_mass", s + 0, inv},
                              {"inv_inertia", s + 1, inv},
                              {"p.x", s + 2, state},
                              {"p.y", s + 3, state},
                              {"p.z", s + 4, state},
                              {"v.x", s + 5, vel},
                              {"v.y", s + 6, vel},
                              {"v.z", s + 7, vel},
                              {"w.x", s + 8, vel},
                              {"w.y", s + 9, vel},
                              {"w.z", s + 10, vel}});
  const ParticleView<const float> particle{1, s + 0, {s + 1, s + 2, s + 3}};
  expect_walk(visit(particle),
              {{"inv_mass", s + 0, inv}, {"v.x", s + 1, vel}, {"v.y", s + 2, vel}, {"v.z", s + 3, vel}});
}

/// Every field of Record's table but the one kept beside it sits at its
/// record_slot among the record's values; the slots are distinct and fill
/// the record's first kRecordValues values.
template <class Record>
void expect_record_slots() {
  using T = typename PackedValue<Record>::type;
  Record r{};
  const T* first = reinterpret_cast<const T*>(&r);
  std::vector<int> seen(kRecordValues<Record>, 0);
  std::size_t beside = 0;
  for_each_body_field<Record>([&](auto at) {
    using At = decltype(at);
    SCOPED_TRACE(At::field.name);
    if constexpr (kKeptBeside<Record, At::field.member>) {
      ++beside;
    } else {
      constexpr std::size_t slot = record_slot<Record, At>();
      ASSERT_LT(slot, seen.size());
      EXPECT_EQ(&At::of(r), first + slot);
      ++seen[slot];
    }
  });
  for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], 1) << "value " << k;
  EXPECT_EQ(beside + kRecordValues<Record>, kFieldCount<Record>);
}

TEST(FieldTables, PackedFieldsLandOnTheirRecordValues) {
  expect_record_slots<PackedRigid<float>>();
  expect_record_slots<PackedRigid<double>>();
  expect_record_slots<PackedSphere<float>>();
  expect_record_slots<PackedSphere<double>>();
  expect_record_slots<PackedParticle<float>>();
  expect_record_slots<PackedParticle<double>>();
}

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
