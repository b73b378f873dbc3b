// test_bounds.cpp - what keeps a solve inside the caller's arrays, checked in
// every build type (these tests run in Release, where no assert is on).
//
// What this proves
// ----------------
// * Schedule::build refuses a contact with a out of range, b out of range or
//   a == b, at the first, a middle and the last contact, on a scene of more
//   contacts than the level pass prefetches ahead (so the bad index is
//   prefetched before it is checked) and on one of three contacts; also in
//   the wide pass of a chain of more than 254 levels. The message names the
//   contact, the index and the body count exactly as validate() does, and the
//   schedule is empty afterwards (no counts, no batches), even when it held a
//   good schedule before, so a later solve refuses it.
// * Every Solver::solve overload (SoA rigid, sphere and particle, packed
//   rigid, sphere and particle, and the model overload) refuses a schedule
//   built for other contact or body counts, and impulses of another count,
//   with a message naming the counts; and a null array the model reads.
// * The one-shot collide::solve() refuses the same bad indices, and a NaN
//   velocity, with validate()'s message.
// * None of these calls writes anything: every body array and the impulses
//   are compared byte for byte before and after.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "support/scenes.hpp"

namespace collide::test {
namespace {

/// The bytes of every body array and of the impulses, to compare before and
/// after a call that must write nothing.
template <class T>
std::vector<unsigned char> snapshot(const BodyView<T>& b, const ImpulseView<T>& j) {
  std::vector<unsigned char> bytes;
  const auto add = [&](const T* p, std::size_t n) {
    if (p == nullptr) return;  // a null array the call must refuse
    const auto* c = reinterpret_cast<const unsigned char*>(p);
    bytes.insert(bytes.end(), c, c + n * sizeof(T));
  };
  for (const T* p : {b.inv_mass, b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z, b.q.w, b.q.x, b.q.y, b.q.z, b.p.x,
                     b.p.y, b.p.z, b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z}) {
    add(p, b.count);
  }
  for (const T* p : {j.j.x, j.j.y, j.j.z}) add(p, j.count);
  return bytes;
}

template <class Record>
std::vector<unsigned char> record_bytes(const PackedBuffer<Record>& records) {
  const auto* c = reinterpret_cast<const unsigned char*>(records.bodies.data());
  return {c, c + records.bodies.size() * sizeof(Record)};
}

/// The message of an exception `f` throws, or "" (and a test failure) when
/// it throws none or another type.
template <class Exception = std::invalid_argument, class F>
std::string thrown(F&& f) {
  try {
    f();
  } catch (const Exception& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw another exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << "threw nothing";
  return "";
}

enum class Bad { a_out_of_range, b_out_of_range, self };

const char* name(Bad bad) {
  switch (bad) {
    case Bad::a_out_of_range:
      return "a out of range";
    case Bad::b_out_of_range:
      return "b out of range";
    case Bad::self:
      return "a == b";
  }
  return "";
}

/// A scene whose contact `k` is made bad, and the validate()-style message
/// that names it ("contacts.a[17] = 40: out of range (40 bodies)").
template <class T>
struct BadScene {
  Scene<T> scene;
  std::vector<BodyIndex> a, b;  // the indices, one of them bad
  ImpulseBuffer<T> impulses;
  std::string message;

  BadScene(Scene<T> s, Bad bad, std::size_t k) : scene(std::move(s)), impulses(scene.contacts.size()) {
    const ContactView<T> c = scene.contacts.view();
    a.assign(c.a, c.a + c.count);
    b.assign(c.b, c.b + c.count);
    const std::size_t bodies = scene.bodies.size();
    const std::string range = ": out of range (" + std::to_string(bodies) + " bodies)";
    const std::string at = "[" + std::to_string(k) + "] = ";
    switch (bad) {
      case Bad::a_out_of_range:  // one past the last body
        a[k] = static_cast<BodyIndex>(bodies);
        message = "contacts.a" + at + std::to_string(a[k]) + range;
        break;
      case Bad::b_out_of_range:  // as far out as an index goes
        b[k] = std::numeric_limits<BodyIndex>::max();
        message = "contacts.b" + at + std::to_string(b[k]) + range;
        break;
      case Bad::self:
        b[k] = a[k];
        message = "contacts.b" + at + std::to_string(b[k]) + ": a contact of a body with itself";
        break;
    }
    const ImpulseView<T> j = impulses.view();
    for (T* p : {j.j.x, j.j.y, j.j.z}) std::fill(p, p + j.count, T(7));  // a solve would overwrite them
  }
  ContactView<T> contacts() const {
    ContactView<T> c = scene.contacts.view();
    c.a = a.data();
    c.b = b.data();
    return c;
  }
  BodyView<T> bodies() { return scene.bodies.view(); }
};

template <class T>
class Bounds : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Bounds, Precisions);

/// The scenes: 40 contacts over 12 movable bodies and a ground (more than
/// the 16 contacts the level pass prefetches ahead), and 3 pairs.
template <class T>
std::vector<Scene<T>> scenes() {
  std::vector<Scene<T>> s;
  SceneOptions o;
  o.friction = true;
  s.push_back(shared_scene<T>(40, 12, o));
  s.push_back(pairs_scene<T>(3, o));
  return s;
}

TYPED_TEST(Bounds, ScheduleBuildNamesTheBadContactAndIsLeftEmpty) {
  using T = TypeParam;
  for (Scene<T>& good : scenes<T>()) {
    const std::size_t n = good.contacts.size();
    for (const Bad bad : {Bad::a_out_of_range, Bad::b_out_of_range, Bad::self}) {
      for (const std::size_t k : {std::size_t{0}, n / 2, n - 1}) {
        SCOPED_TRACE(std::string(name(bad)) + " at contact " + std::to_string(k) + " of " + std::to_string(n));
        BadScene<T> s(good, bad, k);
        const std::vector<unsigned char> before = snapshot(s.bodies(), s.impulses.view());

        // A schedule that held a good build of the scene before.
        Schedule schedule;
        schedule.build(good.contacts.view(), good.bodies.view());
        ASSERT_EQ(schedule.contact_count(), n);
        ASSERT_GT(schedule.batch_count(), 0u);
        EXPECT_EQ(thrown([&] { schedule.build(s.contacts(), s.bodies()); }), "collide::Schedule::build: " + s.message);
        EXPECT_EQ(schedule.contact_count(), 0u);
        EXPECT_EQ(schedule.body_count(), 0u);
        EXPECT_EQ(schedule.batch_count(), 0u);
        EXPECT_EQ(schedule.largest_batch(), 0u);
        EXPECT_EQ(schedule.conflicts(), 0u);

        // The same from packed records, and on several threads.
        PackedBuffer<PackedSphere<T>> spheres(s.bodies().count);
        pack(sphere_view(s.bodies()), packed_view(spheres));
        EXPECT_EQ(thrown([&] { schedule.build(s.contacts(), packed_view(spheres), 2); }),
                  "collide::Schedule::build: " + s.message);

        // The emptied schedule cannot serve a solve of the scene, bad or good.
        const Solver solver;
        EXPECT_NE(thrown([&] { solver.solve(s.bodies(), s.contacts(), s.impulses.view(), schedule); })
                      .find("the schedule was built for 0 contacts and 0 bodies, not " + std::to_string(n) +
                            " contacts and " + std::to_string(good.bodies.size()) + " bodies"),
                  std::string::npos);

        // One-shot: validate()'s message.
        SolverOptions options;
        options.path = Path::scalar;
        EXPECT_EQ(thrown([&] { solve(s.bodies(), s.contacts(), s.impulses.view(), options); }),
                  "collide::solve: " + s.message);
        EXPECT_EQ(thrown([&] { solve(s.bodies(), s.contacts(), s.impulses.view()); }), "collide::solve: " + s.message);

        EXPECT_EQ(snapshot(s.bodies(), s.impulses.view()), before) << "a refused call wrote into the arrays";
      }
    }
  }
}

TYPED_TEST(Bounds, ScheduleBuildChecksTheWidePassToo) {
  using T = TypeParam;
  // A chain of 300 contacts is 300 levels: the byte-wide level pass stops at
  // contact 254 and the rest is assigned on words.
  Scene<T> chain;
  for (int i = 0; i < 301; ++i) chain.bodies.push_back(BodyRecord<T>{});
  for (BodyIndex k = 0; k < 300; ++k) {
    ContactRecord<T> c;
    c.a = k;
    c.b = k + 1;
    chain.contacts.push_back(c);
  }
  Schedule schedule;
  schedule.build(chain.contacts.view(), chain.bodies.view());
  ASSERT_EQ(schedule.batch_count(), 300u);
  for (const Bad bad : {Bad::a_out_of_range, Bad::b_out_of_range, Bad::self}) {
    for (const std::size_t k : {std::size_t{253}, std::size_t{254}, std::size_t{290}, std::size_t{299}}) {
      SCOPED_TRACE(std::string(name(bad)) + " at contact " + std::to_string(k));
      BadScene<T> s(chain, bad, k);
      EXPECT_EQ(thrown([&] { schedule.build(s.contacts(), s.bodies()); }), "collide::Schedule::build: " + s.message);
      EXPECT_EQ(schedule.contact_count(), 0u);
      EXPECT_EQ(schedule.batch_count(), 0u);
      schedule.build(chain.contacts.view(), chain.bodies.view());  // and a good build after it works as before
      EXPECT_EQ(schedule.batch_count(), 300u);
    }
  }
}

TYPED_TEST(Bounds, ScheduleBuildRefusesNullArrays) {
  using T = TypeParam;
  Scene<T> s = pairs_scene<T>(3);
  Schedule schedule;
  ContactView<T> c = s.contacts.view();
  c.b = nullptr;
  EXPECT_EQ(thrown([&] { schedule.build(c, s.bodies.view()); }),
            "collide::Schedule::build: contacts.a or contacts.b is null but contacts.count = 3");
  BodyView<T> b = s.bodies.view();
  b.inv_mass = nullptr;
  EXPECT_EQ(thrown([&] { schedule.build(s.contacts.view(), b); }),
            "collide::Schedule::build: bodies.inv_mass is null but bodies.count = 6");
  PackedView<PackedSphere<T>> records{6, nullptr};
  EXPECT_EQ(thrown([&] { schedule.build(s.contacts.view(), records); }),
            "collide::Schedule::build: bodies.inv_mass is null but bodies.count = 6");
  EXPECT_EQ(schedule.contact_count(), 0u);
}

/// Calls every Solver::solve overload on the scene's bodies (packed copies
/// for the packed ones) and checks that each throws a message containing
/// `expected` and writes nothing.
template <class T>
void expect_every_solve_refuses(Scene<T>& scene, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                                const Schedule& schedule, const std::string& expected) {
  const BodyView<T> bodies = scene.bodies.view();
  PackedBuffer<PackedRigid<T>> rigid(bodies.count);
  PackedBuffer<PackedSphere<T>> sphere(bodies.count);
  PackedBuffer<PackedParticle<T>> particle(bodies.count);
  pack(bodies, packed_view(rigid));
  pack(sphere_view(bodies), packed_view(sphere));
  pack(particle_view(bodies), packed_view(particle));
  const auto before = snapshot(bodies, impulses);
  const auto rigid_before = record_bytes(rigid), sphere_before = record_bytes(sphere);
  const auto particle_before = record_bytes(particle);
  for (const Path path : {Path::scalar, Path::simd}) {
    for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
      SolverOptions o;
      o.path = path;
      o.layout = layout;
      o.threads = 1;
      const Solver solver(o);
      const auto expect = [&](const char* overload, auto&& call) {
        const std::string what = thrown(call);
        EXPECT_NE(what.find(expected), std::string::npos) << overload << ": " << what;
        EXPECT_EQ(what.rfind("collide::Solver::solve: ", 0), 0u) << overload << ": " << what;
      };
      expect("rigid", [&] { solver.solve(bodies, contacts, impulses, schedule); });
      expect("sphere", [&] { solver.solve(sphere_view(bodies), contacts, impulses, schedule); });
      expect("particle", [&] { solver.solve(particle_view(bodies), contacts, impulses, schedule); });
      expect("packed rigid", [&] { solver.solve(packed_view(rigid), contacts, impulses, schedule); });
      expect("packed sphere", [&] { solver.solve(packed_view(sphere), contacts, impulses, schedule); });
      expect("packed particle", [&] { solver.solve(packed_view(particle), contacts, impulses, schedule); });
      for (const Model m : {Model::particle, Model::sphere, Model::rigid}) {
        expect(to_string(m), [&] { solver.solve(m, bodies, contacts, impulses, schedule); });
      }
    }
  }
  EXPECT_EQ(snapshot(bodies, impulses), before) << "a refused solve wrote into the arrays";
  EXPECT_EQ(record_bytes(rigid), rigid_before);
  EXPECT_EQ(record_bytes(sphere), sphere_before);
  EXPECT_EQ(record_bytes(particle), particle_before);
}

TYPED_TEST(Bounds, EverySolveRefusesAScheduleOfOtherCounts) {
  using T = TypeParam;
  for (Scene<T>& scene : scenes<T>()) {
    const ContactView<T> contacts = scene.contacts.view();
    const std::size_t n = contacts.count, bodies = scene.bodies.size();
    SCOPED_TRACE(std::to_string(n) + " contacts");
    ImpulseBuffer<T> j(n);
    const ImpulseView<T> jv = j.view();
    for (T* p : {jv.j.x, jv.j.y, jv.j.z}) std::fill(p, p + n, T(7));

    // Built for one contact fewer (the prefix of the scene).
    Schedule fewer;
    fewer.build(contact_slice(contacts, 0, n - 1), scene.bodies.view());
    expect_every_solve_refuses(scene, contacts, jv, fewer,
                               "the schedule was built for " + std::to_string(n - 1) + " contacts and " +
                                   std::to_string(bodies) + " bodies, not " + std::to_string(n) + " contacts and " +
                                   std::to_string(bodies) + " bodies");

    // Built for one body more (the same contacts over a longer body array).
    Scene<T> more = scene;
    more.bodies.push_back(BodyRecord<T>{});
    Schedule wider;
    wider.build(contacts, more.bodies.view());
    expect_every_solve_refuses(scene, contacts, jv, wider,
                               "built for " + std::to_string(n) + " contacts and " + std::to_string(bodies + 1) +
                                   " bodies, not " + std::to_string(n) + " contacts and " + std::to_string(bodies));

    // The right schedule, impulses of another count.
    Schedule right;
    right.build(contacts, scene.bodies.view());
    ImpulseView<T> short_j = jv;
    short_j.count = n - 1;
    expect_every_solve_refuses(
        scene, contacts, short_j, right,
        "impulses.count = " + std::to_string(n - 1) + " but contacts.count = " + std::to_string(n));

    // A null array the kernels read.
    ImpulseView<T> no_j = jv;
    no_j.j.y = nullptr;
    expect_every_solve_refuses(scene, contacts, no_j, right, "impulses.j.y is null but impulses.count = ");
    ContactView<T> no_n = contacts;
    no_n.n.z = nullptr;
    expect_every_solve_refuses(scene, no_n, jv, right, "contacts.n.z is null but contacts.count = ");
  }
}

TYPED_TEST(Bounds, NullBodyArraysAreRefusedPerModel) {
  using T = TypeParam;
  Scene<T> scene = pairs_scene<T>(5);
  const ContactView<T> contacts = scene.contacts.view();
  ImpulseBuffer<T> j(contacts.count);
  Schedule schedule;
  schedule.build(contacts, scene.bodies.view());
  const Solver solver;
  BodyView<T> no_w = scene.bodies.view();
  no_w.w.z = nullptr;
  EXPECT_EQ(thrown([&] { solver.solve(no_w, contacts, j.view(), schedule); }),
            "collide::Solver::solve: bodies.w.z is null but bodies.count = 10");
  EXPECT_EQ(thrown([&] { solver.solve(sphere_view(no_w), contacts, j.view(), schedule); }),
            "collide::Solver::solve: bodies.w.z is null but bodies.count = 10");
  // The particle model reads neither w nor the contact point.
  ContactView<T> no_c = contacts;
  no_c.c = {};
  solver.solve(particle_view(no_w), no_c, j.view(), schedule);
  EXPECT_EQ(thrown([&] { solver.solve(sphere_view(scene.bodies.view()), no_c, j.view(), schedule); }),
            "collide::Solver::solve: contacts.c.x is null but contacts.count = 5");
  PackedView<PackedRigid<T>> rigid{10, nullptr, scene.bodies.view().inv_mass};
  EXPECT_EQ(thrown([&] { solver.solve(rigid, contacts, j.view(), schedule); }),
            "collide::Solver::solve: bodies.records is null but bodies.count = 10");
}

TYPED_TEST(Bounds, OneShotSolveValidatesFirst) {
  using T = TypeParam;
  for (Scene<T>& scene : scenes<T>()) {
    const std::size_t n = scene.contacts.size();
    for (const std::size_t i : {std::size_t{0}, scene.bodies.size() - 1}) {
      Scene<T> s = scene;
      const BodyView<T> b = s.bodies.view();
      b.v.x[i] = std::numeric_limits<T>::quiet_NaN();
      ImpulseBuffer<T> j(n);
      const ImpulseView<T> jv = j.view();
      for (T* p : {jv.j.x, jv.j.y, jv.j.z}) std::fill(p, p + n, T(7));
      const auto before = snapshot(b, jv);
      const Validation v = validate(b, s.contacts.view(), jv);
      ASSERT_FALSE(v);
      EXPECT_EQ(v.message, "bodies.v.x[" + std::to_string(i) + "] = nan: must be finite");
      EXPECT_EQ(thrown([&] { solve(b, s.contacts.view(), jv); }), "collide::solve: " + v.message);
      EXPECT_EQ(snapshot(b, jv), before);
    }
    // Impulses of another count: validate()'s message too.
    ImpulseBuffer<T> j(n + 1);
    EXPECT_EQ(
        thrown([&] { solve(scene.bodies.view(), scene.contacts.view(), j.view()); }),
        "collide::solve: impulses.count = " + std::to_string(n + 1) + " but contacts.count = " + std::to_string(n));
  }
}

}  // namespace
}  // namespace collide::test
