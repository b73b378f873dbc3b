// test_validate.cpp - the boundary checks of collide::validate
// (validate.cpp, collide/validate.hpp).
//
// What this proves
// ----------------
// * Valid random scenes (pairs and shared with an immovable ground, float and
//   double, with and without friction, per-contact and uniform e) pass.
// * Every rule of validate.hpp rejects what it should, and the message names
//   the view, the field and the element: impulses.count != contacts.count,
//   null arrays, negative / NaN / inf inverse mass and moments, non-finite
//   q, p, v, w, c, n, |q| or |n| off 1 by more than 1e-4 (within 1e-4 is
//   accepted), indices out of range, a contact of a body with itself, e
//   outside [0, 1] (per contact and uniform), mu negative or not finite.
// * The first problem in array order is the one reported.
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/validate.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

template <class T>
T* mut(const T* p) {
  return const_cast<T*>(p);
}

template <class T>
struct Fixture {
  Scene<T> scene;
  BodyView<T> bodies;
  ContactView<T> contacts;
  ImpulseBuffer<T> j;
  ImpulseView<T> impulses;

  explicit Fixture(bool friction = true) {
    SceneOptions o;
    o.seed = 21;
    o.friction = friction;
    scene = shared_scene<T>(40, 12, o);
    bodies = scene.bodies.view();
    contacts = scene.contacts.view();
    j.resize(contacts.count);
    impulses = j.view();
  }
  Validation run() const { return validate(bodies, contacts, impulses); }
};

template <class T>
class Validate : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Validate, Precisions);

TYPED_TEST(Validate, ValidScenesPass) {
  using T = TypeParam;
  for (const bool friction : {false, true}) {
    Fixture<T> f(friction);
    EXPECT_TRUE(f.run()) << f.run().message;
    f.contacts.e = nullptr;
    f.contacts.uniform_e = T(0.5);
    EXPECT_TRUE(f.run()) << f.run().message;
    SceneOptions o;
    o.friction = friction;
    Scene<T> p = pairs_scene<T>(100, o);
    ImpulseBuffer<T> j(100);
    const Validation v = validate(p.bodies.view(), p.contacts.view(), j.view());
    EXPECT_TRUE(v) << v.message;
  }
}

TYPED_TEST(Validate, EachRuleRejectsAndNamesTheElement) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T inf = std::numeric_limits<T>::infinity();
  struct Rule {
    const char* expect;  // substring of the message
    std::function<void(Fixture<T>&)> spoil;
  };
  const std::vector<Rule> rules = {
      {"impulses.count", [](Fixture<T>& f) { f.impulses.count -= 1; }},
      {"bodies.w.y is null", [](Fixture<T>& f) { f.bodies.w.y = nullptr; }},
      {"contacts: an array is null", [](Fixture<T>& f) { f.contacts.n.z = nullptr; }},
      {"impulses: an array is null", [](Fixture<T>& f) { f.impulses.j.x = nullptr; }},
      {"bodies.inv_mass[3]", [](Fixture<T>& f) { f.bodies.inv_mass[3] = -1; }},
      {"bodies.inv_mass[3]", [&](Fixture<T>& f) { f.bodies.inv_mass[3] = nan; }},
      {"bodies.inv_mass[3]", [&](Fixture<T>& f) { f.bodies.inv_mass[3] = inf; }},
      {"bodies.inv_inertia.y[4]", [&](Fixture<T>& f) { f.bodies.inv_inertia.y[4] = nan; }},
      {"bodies.inv_inertia.z[4]", [](Fixture<T>& f) { f.bodies.inv_inertia.z[4] = -T(0.5); }},
      {"bodies.q.x[5]", [&](Fixture<T>& f) { f.bodies.q.x[5] = inf; }},
      {"bodies.|q|[5]",
       [](Fixture<T>& f) {
         for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] *= T(1.01);
       }},
      {"bodies.p.z[6]", [&](Fixture<T>& f) { f.bodies.p.z[6] = nan; }},
      {"bodies.v.x[7]", [&](Fixture<T>& f) { f.bodies.v.x[7] = -inf; }},
      {"bodies.w.y[8]", [&](Fixture<T>& f) { f.bodies.w.y[8] = nan; }},
      {"contacts.a[2]", [](Fixture<T>& f) { mut(f.contacts.a)[2] = static_cast<BodyIndex>(f.bodies.count); }},
      {"contacts.b[2]", [](Fixture<T>& f) { mut(f.contacts.b)[2] = static_cast<BodyIndex>(f.bodies.count + 5); }},
      {"itself", [](Fixture<T>& f) { mut(f.contacts.b)[2] = f.contacts.a[2]; }},
      {"contacts.c.y[2]", [&](Fixture<T>& f) { mut(f.contacts.c.y)[2] = nan; }},
      {"contacts.n.x[2]", [&](Fixture<T>& f) { mut(f.contacts.n.x)[2] = inf; }},
      {"contacts.|n|[2]",
       [](Fixture<T>& f) {
         for (const T* n : {f.contacts.n.x, f.contacts.n.y, f.contacts.n.z}) mut(n)[2] *= T(0.99);
       }},
      {"contacts.e[2]", [](Fixture<T>& f) { mut(f.contacts.e)[2] = T(1.5); }},
      {"contacts.e[2]", [](Fixture<T>& f) { mut(f.contacts.e)[2] = -T(0.125); }},
      {"contacts.e[2]", [&](Fixture<T>& f) { mut(f.contacts.e)[2] = nan; }},
      {"uniform_e",
       [](Fixture<T>& f) {
         f.contacts.e = nullptr;
         f.contacts.uniform_e = 2;
       }},
      {"contacts.mu[2]", [](Fixture<T>& f) { mut(f.contacts.mu)[2] = -1; }},
      {"contacts.mu[2]", [&](Fixture<T>& f) { mut(f.contacts.mu)[2] = inf; }},
      {"contacts.mu[2]", [&](Fixture<T>& f) { mut(f.contacts.mu)[2] = nan; }},
  };
  for (const Rule& rule : rules) {
    Fixture<T> f;
    ASSERT_TRUE(f.run());
    rule.spoil(f);
    const Validation v = f.run();
    EXPECT_FALSE(v) << "expected a rejection mentioning " << rule.expect;
    EXPECT_NE(v.message.find(rule.expect), std::string::npos)
        << "message \"" << v.message << "\" does not name " << rule.expect;
  }
}

TYPED_TEST(Validate, UnitToleranceIsOneInTenThousand) {
  using T = TypeParam;
  Fixture<T> f;
  for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] *= T(1 + 5e-5);
  for (const T* n : {f.contacts.n.x, f.contacts.n.y, f.contacts.n.z}) mut(n)[2] *= T(1 - 5e-5);
  EXPECT_TRUE(f.run()) << f.run().message;
}

TYPED_TEST(Validate, FirstProblemIsReported) {
  using T = TypeParam;
  Fixture<T> f;
  f.bodies.v.x[9] = std::numeric_limits<T>::quiet_NaN();
  f.bodies.v.x[2] = std::numeric_limits<T>::infinity();
  mut(f.contacts.e)[1] = 3;
  const Validation v = f.run();
  EXPECT_NE(v.message.find("bodies.v.x[2]"), std::string::npos) << v.message;
}

// The smaller models' views are checked on their own fields: a sphere has no
// orientation to be unit, a particle no contact point to be present, and a
// bad value in a field the model reads is still named.
TYPED_TEST(Validate, SphereAndParticleViews) {
  using T = TypeParam;
  Fixture<T> f;
  EXPECT_TRUE(validate(sphere_view(f.bodies), f.contacts, f.impulses));
  EXPECT_TRUE(validate(particle_view(f.bodies), f.contacts, f.impulses));

  f.bodies.q.w[3] = T(7);  // not unit, but neither model reads q
  EXPECT_FALSE(f.run());
  EXPECT_TRUE(validate(sphere_view(f.bodies), f.contacts, f.impulses));
  EXPECT_TRUE(validate(particle_view(f.bodies), f.contacts, f.impulses));

  ContactView<T> no_point = f.contacts;
  no_point.c = {};
  EXPECT_TRUE(validate(particle_view(f.bodies), no_point, f.impulses));
  EXPECT_FALSE(validate(sphere_view(f.bodies), no_point, f.impulses));

  f.bodies.inv_inertia.x[4] = T(-1);
  const Validation sphere = validate(sphere_view(f.bodies), f.contacts, f.impulses);
  EXPECT_NE(sphere.message.find("bodies.inv_inertia[4]"), std::string::npos) << sphere.message;
  EXPECT_TRUE(validate(particle_view(f.bodies), f.contacts, f.impulses));

  f.bodies.v.z[6] = std::numeric_limits<T>::infinity();
  const Validation particle = validate(particle_view(f.bodies), f.contacts, f.impulses);
  EXPECT_NE(particle.message.find("bodies.v.z[6]"), std::string::npos) << particle.message;
}

}  // namespace
}  // namespace collide::test
