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
//   q, p, v, w, c, n, |n| off 1 by more than 1e-3 (kNormalTolerance of
//   rules.hpp, the scene files' rule; within it is accepted, on both sides of
//   the boundary), a quaternion whose |q|^2 is not a normal, finite number
//   (the files' rule; any other length is accepted), indices out of range, a contact of a body with itself, e
//   outside [0, 1] (per contact and uniform), mu negative or not finite.
// * No array the solve writes shares memory with another array it writes
//   or reads (v and w, the impulses, packed records): each pair is named,
//   and views of one allocation whose arrays touch different bytes (the
//   rows of a 2-D array, interleaved rows) pass, as do read arrays that
//   share memory.
// * The first problem in array order is the one reported.
// * The vectorised screen that runs first (validate.cpp) changes no verdict:
//   -0.0 inverse masses and |n| just inside the tolerance (which fail the
//   screen) pass through the scan; a bad value in the last element of a scene
//   large enough to be screened in parallel chunks is still found and named.
// * Packed records (collide/packed.hpp) get the verdict and the message of the
//   SoA view they were packed from, for every rule, and their padding is
//   not read.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/packed.hpp"
#include "collide/rules.hpp"
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

template <class T>
struct Rule {
  const char* expect;  // substring of the message
  std::function<void(Fixture<T>&)> spoil;
};

/// Every rule of validate.hpp, each as a change that breaks it.
template <class T>
std::vector<Rule<T>> rules() {
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T inf = std::numeric_limits<T>::infinity();
  return {
      {"impulses.count", [](Fixture<T>& f) { f.impulses.count -= 1; }},
      {"bodies.w.y is null", [](Fixture<T>& f) { f.bodies.w.y = nullptr; }},
      {"contacts: an array is null", [](Fixture<T>& f) { f.contacts.n.z = nullptr; }},
      {"impulses: an array is null", [](Fixture<T>& f) { f.impulses.j.x = nullptr; }},
      {"bodies.inv_mass[3]", [](Fixture<T>& f) { f.bodies.inv_mass[3] = -1; }},
      {"bodies.inv_mass[3]", [=](Fixture<T>& f) { f.bodies.inv_mass[3] = nan; }},
      {"bodies.inv_mass[3]", [=](Fixture<T>& f) { f.bodies.inv_mass[3] = inf; }},
      {"bodies.inv_inertia.y[4]", [=](Fixture<T>& f) { f.bodies.inv_inertia.y[4] = nan; }},
      {"bodies.inv_inertia.z[4]", [](Fixture<T>& f) { f.bodies.inv_inertia.z[4] = -T(0.5); }},
      {"bodies.q.x[5]", [=](Fixture<T>& f) { f.bodies.q.x[5] = inf; }},
      {"bodies.|q|^2[5]",  // too small to normalise in T: |q|^2 below the smallest normal
       [](Fixture<T>& f) {
         for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] = 0;
         f.bodies.q.w[5] = std::sqrt(std::numeric_limits<T>::min()) / 2;
       }},
      {"bodies.|q|^2[5]",  // zero
       [](Fixture<T>& f) {
         for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] = 0;
       }},
      {"bodies.|q|^2[5]",  // |q|^2 overflows
       [](Fixture<T>& f) { f.bodies.q.w[5] = std::sqrt(std::numeric_limits<T>::max()) * 2; }},
      {"bodies.p.z[6]", [=](Fixture<T>& f) { f.bodies.p.z[6] = nan; }},
      {"bodies.v.x[7]", [=](Fixture<T>& f) { f.bodies.v.x[7] = -inf; }},
      {"bodies.w.y[8]", [=](Fixture<T>& f) { f.bodies.w.y[8] = nan; }},
      {"contacts.a[2]", [](Fixture<T>& f) { mut(f.contacts.a)[2] = static_cast<BodyIndex>(f.bodies.count); }},
      {"contacts.b[2]", [](Fixture<T>& f) { mut(f.contacts.b)[2] = static_cast<BodyIndex>(f.bodies.count + 5); }},
      {"itself", [](Fixture<T>& f) { mut(f.contacts.b)[2] = f.contacts.a[2]; }},
      {"contacts.c.y[2]", [=](Fixture<T>& f) { mut(f.contacts.c.y)[2] = nan; }},
      {"contacts.n.x[2]", [=](Fixture<T>& f) { mut(f.contacts.n.x)[2] = inf; }},
      {"contact 2: normal length",
       [](Fixture<T>& f) {
         for (const T* n : {f.contacts.n.x, f.contacts.n.y, f.contacts.n.z}) mut(n)[2] *= T(0.99);
       }},
      {"contacts.e[2]", [](Fixture<T>& f) { mut(f.contacts.e)[2] = T(1.5); }},
      {"contacts.e[2]", [](Fixture<T>& f) { mut(f.contacts.e)[2] = -T(0.125); }},
      {"contacts.e[2]", [=](Fixture<T>& f) { mut(f.contacts.e)[2] = nan; }},
      {"uniform_e",
       [](Fixture<T>& f) {
         f.contacts.e = nullptr;
         f.contacts.uniform_e = 2;
       }},
      {"contacts.mu[2]", [](Fixture<T>& f) { mut(f.contacts.mu)[2] = -1; }},
      {"contacts.mu[2]", [=](Fixture<T>& f) { mut(f.contacts.mu)[2] = inf; }},
      {"contacts.mu[2]", [=](Fixture<T>& f) { mut(f.contacts.mu)[2] = nan; }},
  };
}

TYPED_TEST(Validate, EachRuleRejectsAndNamesTheElement) {
  using T = TypeParam;
  for (const Rule<T>& rule : rules<T>()) {
    Fixture<T> f;
    ASSERT_TRUE(f.run());
    rule.spoil(f);
    const Validation v = f.run();
    EXPECT_FALSE(v) << "expected a rejection mentioning " << rule.expect;
    EXPECT_NE(v.message.find(rule.expect), std::string::npos)
        << "message \"" << v.message << "\" does not name " << rule.expect;
  }
}

/// The fixture with |q| of body 5 scaled by `q_scale` and |n| of contact 2
/// by `n_scale`: its verdict.
template <class T>
Validation scaled_units(double q_scale, double n_scale) {
  Fixture<T> f;
  for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] *= T(q_scale);
  for (const T* n : {f.contacts.n.x, f.contacts.n.y, f.contacts.n.z}) mut(n)[2] *= T(n_scale);
  return f.run();
}

TYPED_TEST(Validate, NormalToleranceIsOneInAThousandAndQuaternionsAnyLength) {
  using T = TypeParam;
  static_assert(kNormalTolerance == 1e-3);
  // Inside: what the scene files accept (0.5e-3 off, and just inside the
  // boundary on both sides; the stored values are unit to a few ulps of T,
  // far below the 1e-6 left). The law normalises q, so its length is free.
  for (const double off : {5e-5, 5e-4, 0.999e-3}) {
    for (const double sign : {1.0, -1.0}) {
      const Validation v = scaled_units<T>(1 + sign * off, 1 - sign * off);
      EXPECT_TRUE(v) << "off by " << sign * off << ": " << v.message;
    }
  }
  for (const double q_scale : {0.5, 1.01, 2.0, 1e6}) {
    const Validation v = scaled_units<T>(q_scale, 1);
    EXPECT_TRUE(v) << "|q| scaled by " << q_scale << ": " << v.message;
  }
  // Outside: just past the boundary on both sides, and 2e-3.
  for (const double off : {1.001e-3, 2e-3}) {
    for (const double sign : {1.0, -1.0}) {
      const Validation v = scaled_units<T>(1, 1 + sign * off);
      EXPECT_NE(v.message.find("contact 2: normal length"), std::string::npos)
          << "off by " << sign * off << ": " << v.message;
      EXPECT_NE(v.message.find("is not 1 within 1e-3"), std::string::npos) << v.message;
    }
  }
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

  // A zero quaternion breaks the rigid model's rule, but neither smaller
  // model reads q.
  for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[3] = T(0);
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

// validate() screens every array with branch-free vector passes first and
// scans element by element only when a screen fails; the screen is stricter
// than the rules, never looser.
TYPED_TEST(Validate, ScreenChangesNoVerdict) {
  using T = TypeParam;
  Fixture<T> f;
  f.bodies.inv_mass[3] = -T(0);  // fails the screen's sign test; the rule (>= 0) accepts it
  f.bodies.inv_inertia.y[4] = -T(0);
  EXPECT_TRUE(f.run()) << f.run().message;
  // Off 1 by 0.995e-3: outside the screen's band (0.99e-3), inside the rule's 1e-3.
  for (T* q : {f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z}) q[5] *= T(1 + 0.995e-3);
  for (const T* n : {f.contacts.n.x, f.contacts.n.y, f.contacts.n.z}) mut(n)[2] *= T(1 - 0.995e-3);
  EXPECT_TRUE(f.run()) << f.run().message;
  // Just outside the rules, with every other value inside the screens (so
  // no other screen failure sends the scene to the scan): a normal off by
  // 1.005e-3, then a quaternion whose |q|^2 is just below the smallest
  // normal number while just above it passes.
  Fixture<T> g;
  for (const T* n : {g.contacts.n.x, g.contacts.n.y, g.contacts.n.z}) mut(n)[2] *= T(1 + 1.005e-3);
  EXPECT_NE(g.run().message.find("contact 2: normal length"), std::string::npos) << g.run().message;
  Fixture<T> h;
  for (T* q : {h.bodies.q.x, h.bodies.q.y, h.bodies.q.z}) q[5] = 0;
  h.bodies.q.w[5] = std::sqrt(std::numeric_limits<T>::min()) * T(1.5);
  EXPECT_TRUE(h.run()) << h.run().message;
  h.bodies.q.w[5] = std::sqrt(std::numeric_limits<T>::min()) * T(0.5);
  EXPECT_NE(h.run().message.find("bodies.|q|^2[5]"), std::string::npos) << h.run().message;
}

// Above 64k elements the screens run in parallel chunks: a problem in the last
// element of the last chunk is found, and the first in array order is named.
TYPED_TEST(Validate, LargeScenesAreScreenedWhole) {
  using T = TypeParam;
  Scene<T> s = pairs_scene<T>(70000, SceneOptions{});
  BodyView<T> b = s.bodies.view();
  ContactView<T> c = s.contacts.view();
  ImpulseBuffer<T> j(c.count);
  ASSERT_GT(b.count, std::size_t{1} << 16);
  ASSERT_GT(c.count, std::size_t{1} << 16);
  EXPECT_TRUE(validate(b, c, j.view()));
  EXPECT_TRUE(validate_indices(c.a, c.b, c.count, b.count));

  const std::size_t last_body = b.count - 1, last_contact = c.count - 1;
  b.v.z[last_body] = std::numeric_limits<T>::quiet_NaN();
  Validation v = validate(b, c, j.view());
  EXPECT_NE(v.message.find("bodies.v.z[" + std::to_string(last_body) + "]"), std::string::npos) << v.message;
  b.v.z[last_body] = 0;

  mut(c.b)[last_contact] = static_cast<BodyIndex>(b.count);
  v = validate(b, c, j.view());
  EXPECT_NE(v.message.find("contacts.b[" + std::to_string(last_contact) + "]"), std::string::npos) << v.message;
  v = validate_indices(c.a, c.b, c.count, b.count);
  EXPECT_NE(v.message.find("contacts.b[" + std::to_string(last_contact) + "]"), std::string::npos) << v.message;
  mut(c.a)[40000] = c.b[40000];
  v = validate_indices(c.a, c.b, c.count, b.count);
  EXPECT_NE(v.message.find("contacts.b[40000]"), std::string::npos) << v.message;
}

/// One record type's verdict against its SoA view's, for every rule.
template <class Record, class T, class ToView>
void expect_same_verdicts(ToView to_view) {
  for (const Rule<T>& rule : rules<T>()) {
    Fixture<T> f;
    rule.spoil(f);
    const auto soa = to_view(f.bodies);
    bool has_null = false;
    for (const T* x : {f.bodies.inv_mass, f.bodies.inv_inertia.x, f.bodies.inv_inertia.y, f.bodies.inv_inertia.z,
                       f.bodies.q.w, f.bodies.q.x, f.bodies.q.y, f.bodies.q.z, f.bodies.p.x, f.bodies.p.y, f.bodies.p.z,
                       f.bodies.v.x, f.bodies.v.y, f.bodies.v.z, f.bodies.w.x, f.bodies.w.y, f.bodies.w.z}) {
      has_null = has_null || x == nullptr;
    }
    if (has_null) continue;  // records have no per-field pointers (the null record test below)
    PackedBuffer<Record> records(soa.count);
    pack(soa, packed_view(records));
    const Validation expected = validate(soa, f.contacts, f.impulses);
    const Validation got = validate(packed_view(records), f.contacts, f.impulses);
    EXPECT_EQ(got.ok, expected.ok) << rule.expect;
    EXPECT_EQ(got.message, expected.message) << rule.expect;
  }
}

TYPED_TEST(Validate, PackedRecordsGetTheVerdictOfTheirSoAView) {
  using T = TypeParam;
  expect_same_verdicts<PackedRigid<T>, T>([](const BodyView<T>& b) { return b; });
  expect_same_verdicts<PackedSphere<T>, T>([](const BodyView<T>& b) { return sphere_view(b); });
  expect_same_verdicts<PackedParticle<T>, T>([](const BodyView<T>& b) { return particle_view(b); });

  Fixture<T> f;
  const PackedView<PackedRigid<T>> none{f.bodies.count, nullptr};
  EXPECT_NE(validate(none, f.contacts, f.impulses).message.find("bodies.records is null"), std::string::npos);
  PackedBuffer<PackedRigid<T>> rigid(f.bodies.count);
  pack(f.bodies, packed_view(rigid));
  const PackedView<PackedRigid<T>> no_masses{f.bodies.count, rigid.bodies.data(), nullptr};
  EXPECT_NE(validate(no_masses, f.contacts, f.impulses).message.find("bodies.inv_mass is null"), std::string::npos);
}

/// A copy of x[0, n) followed by `tail` zeros, so that a view starting
/// inside the copy ends inside the buffer as well.
template <class T>
std::vector<T> with_tail(const T* x, std::size_t n, std::size_t tail) {
  std::vector<T> out(n + tail, T(0));
  std::copy(x, x + n, out.begin());
  return out;
}

// Arrays the solve writes (v, w, the impulses, records) may share no byte
// with another array of the solve; the message names both, and says which
// one the solve writes.
TYPED_TEST(Validate, WrittenArraysShareNoMemory) {
  using T = TypeParam;
  const auto message = [](const auto& bodies, const Fixture<T>& f) {
    return validate(bodies, f.contacts, f.impulses).message;
  };
  {
    Fixture<T> f;
    f.bodies.w = f.bodies.v;  // the same array for v and w
    EXPECT_EQ(f.run().message, "bodies.v.x and bodies.w.x share memory: the solve writes both");
    EXPECT_EQ(message(sphere_view(f.bodies), f), "bodies.v.x and bodies.w.x share memory: the solve writes both");
  }
  {
    // Overlapping, not equal: p.x moved into a buffer with room for v.y,
    // three elements on, to end inside it.
    Fixture<T> f;
    std::vector<T> px = with_tail(f.bodies.p.x, f.bodies.count, 3);
    f.bodies.p.x = px.data();
    f.bodies.v.y = px.data() + 3;
    EXPECT_EQ(f.run().message,
              "bodies.p.x and bodies.v.y share memory: the solve writes bodies.v.y while it reads bodies.p.x");
    EXPECT_EQ(message(particle_view(f.bodies), f), "") << "a particle solve reads no p";
  }
  {
    Fixture<T> f;
    f.impulses.j.z = mut(f.contacts.n.x);
    EXPECT_EQ(f.run().message,
              "contacts.n.x and impulses.j.z share memory: the solve writes impulses.j.z while it reads contacts.n.x");
    Fixture<T> g;
    std::vector<T> wz = with_tail(g.bodies.w.z, g.bodies.count, g.impulses.count + 1);
    g.bodies.w.z = wz.data();
    g.impulses.j.y = wz.data() + 1;
    EXPECT_EQ(g.run().message, "bodies.w.z and impulses.j.y share memory: the solve writes both");
  }
  {
    // Arrays that are only read may share memory; an empty array shares nothing.
    Fixture<T> f;
    f.contacts.c = f.contacts.n;
    f.bodies.p.y = f.bodies.p.x;
    EXPECT_TRUE(f.run()) << f.run().message;
    f.contacts.count = 0;
    f.impulses.count = 0;
    f.impulses.j.x = mut(f.contacts.n.x);
    EXPECT_TRUE(f.run()) << f.run().message;
  }
  {
    // One allocation holding v and w: the rows of a (6, N) array, then
    // interleaved (v.x, w.x, v.y, w.y, ...), touch different bytes.
    Fixture<T> f;
    const std::size_t n = f.bodies.count;
    std::vector<T> rows(6 * n);
    const T* const from[6] = {f.bodies.v.x, f.bodies.v.y, f.bodies.v.z, f.bodies.w.x, f.bodies.w.y, f.bodies.w.z};
    for (std::size_t r = 0; r < 6; ++r) std::copy(from[r], from[r] + n, rows.data() + r * n);
    f.bodies.v = {rows.data(), rows.data() + n, rows.data() + 2 * n};
    f.bodies.w = {rows.data() + 3 * n, rows.data() + 4 * n, rows.data() + 5 * n};
    EXPECT_TRUE(f.run()) << f.run().message;
    f.bodies.v = {rows.data(), rows.data() + 2 * n, rows.data() + 4 * n};
    f.bodies.w = {rows.data() + n, rows.data() + 3 * n, rows.data() + 5 * n};
    EXPECT_TRUE(f.run()) << f.run().message;
    f.bodies.w.z = rows.data() + 4 * n + 1;  // one element into v.z
    EXPECT_EQ(f.run().message, "bodies.v.z and bodies.w.z share memory: the solve writes both");
  }
  {
    // Packed records are written whole.
    Fixture<T> f;
    PackedBuffer<PackedRigid<T>> rigid(f.bodies.count);
    pack(f.bodies, packed_view(rigid));
    PackedView<PackedRigid<T>> view = packed_view(rigid);
    EXPECT_TRUE(message(view, f).empty());
    view.inv_mass = &rigid[3].inv_inertia[0];
    EXPECT_EQ(message(view, f),
              "bodies.records and bodies.inv_mass share memory: the solve writes bodies.records while it reads "
              "bodies.inv_mass");
    PackedBuffer<PackedParticle<T>> particle(f.bodies.count);
    pack(particle_view(f.bodies), packed_view(particle));
    f.impulses.j.x = &particle[1].v[0];
    EXPECT_EQ(message(packed_view(particle), f), "bodies.records and impulses.j.x share memory: the solve writes both");
  }
}

TEST(ValidateDisjoint, NamesTheFirstPair) {
  const double x[8] = {};
  const double y[8] = {};
  const ArrayBytes arrays[] = {{"bodies", "p", x, sizeof x, false},
                               {"bodies", "q", x + 2, 2 * sizeof(double), false},
                               {"solve", "out", y, sizeof y, true},
                               {"bodies", "v", y + 7, sizeof(double), true},
                               {"bodies", "w", nullptr, 0, true}};
  EXPECT_TRUE(validate_disjoint(arrays, 3));
  EXPECT_EQ(validate_disjoint(arrays, 5).message, "solve.out and bodies.v share memory: the solve writes both");
  const ArrayBytes touching[] = {{"a", "x", x, 4 * sizeof(double), true}, {"a", "y", x + 4, 4 * sizeof(double), true}};
  EXPECT_TRUE(validate_disjoint(touching, 2));
}

// The kernels never read a record's padding: NaN there is not an error. (A
// rigid record has none: 16 values, its inverse mass beside it; its values
// and the inverse masses are each screened where they are.)
TYPED_TEST(Validate, PackedPaddingIsNotRead) {
  using T = TypeParam;
  Fixture<T> f;
  PackedBuffer<PackedRigid<T>> rigid(f.bodies.count);
  PackedBuffer<PackedSphere<T>> sphere(f.bodies.count);
  pack(f.bodies, packed_view(rigid));
  pack(sphere_view(f.bodies), packed_view(sphere));
  static_assert(sizeof(PackedRigid<T>) == 16 * sizeof(T));
  for (auto& r : sphere.bodies) {
    T* x = &r.v[0];
    for (std::size_t k = 11; k < sizeof(r) / sizeof(T); ++k) x[k] = std::numeric_limits<T>::quiet_NaN();
  }
  EXPECT_TRUE(validate(packed_view(sphere), f.contacts, f.impulses))
      << validate(packed_view(sphere), f.contacts, f.impulses).message;
  EXPECT_TRUE(validate(packed_view(rigid), f.contacts, f.impulses));
  rigid[7].inv_inertia[2] = -1;
  EXPECT_NE(validate(packed_view(rigid), f.contacts, f.impulses).message.find("bodies.inv_inertia.z[7]"),
            std::string::npos);
  rigid[7].inv_inertia[2] = 1;
  rigid.inv_mass[5] = std::numeric_limits<T>::quiet_NaN();
  EXPECT_NE(validate(packed_view(rigid), f.contacts, f.impulses).message.find("bodies.inv_mass[5]"), std::string::npos);
}

}  // namespace
}  // namespace collide::test
