// test_debris_accuracy.cpp - the fast mode's error on the debris scenes
// (shared bodies, chains of contacts), every model, float and double, with
// and without friction, and of reference_solve<double> on the same scenes:
// no contact above kImpulseErrorTargetEps (2 units; issue 13), except the
// particle model without friction, still above it (2.37 float, 2.77 double
// at 100k contacts: a single contact's own rounding of vn, not a chain),
// which is held to the bound (kImpulseErrorBoundEps) and stays open.
//
// With friction the debris scene measured 7.6 units in double and 6.0 in
// float, and reference_solve<double> (the plainest evaluation of the law)
// 7.2, so the unit, not the kernels' order of operations, was short. The
// worst contact was the first on both of its bodies, so not a chain: its
// friction step read the velocities left by its own normal impulse, whose
// rounding (relative to max(1/I) |r| jn, with |r| = 47 m on a body with
// moments 1:62) the scale did not count. The scale now does (reference.cpp,
// `after_normal`; docs/collision-law.md, "The friction step after the
// normal impulse"), and the friction cases are within the target. Counting
// the rounding of every velocity update along chains instead (|v'|/2 per
// update) was tried first and changed nothing (7.2).
//
// Mutation checked: without `after_normal`, ReferenceDoubleOnDebris and
// KernelsOnDebrisDouble fail with friction.
#include <algorithm>
#include <cstddef>
#include <iostream>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/check.hpp"
#include "collide/generate.hpp"
#include "collide/model.hpp"
#include "collide/reference.hpp"
#include "collide/scene.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

constexpr std::size_t kContacts = 100000;

struct LongDoubleReference {
  ImpulseBuffer<long double> j;
  std::vector<ReferenceContact<long double>> diag;
};

template <class T>
LongDoubleReference long_double_reference(const Scene<T>& scene) {
  Scene<long double> ref = convert_scene<long double>(scene);
  LongDoubleReference r;
  r.j = reference(ref.bodies, ref.contacts.view(), &r.diag);
  return r;
}

template <class T>
double max_error(const ImpulseBuffer<T>& j, const LongDoubleReference& ref) {
  const std::vector<double> e = impulse_errors_eps<T>(std::as_const(j).view(), std::as_const(ref.j).view(), ref.diag);
  return *std::max_element(e.begin(), e.end());
}

TEST(DebrisAccuracy, ReferenceDoubleOnDebris) {
  for (const bool friction : {false, true}) {
    GenerateOptions o;
    o.friction = friction;
    const Scene<double> scene = generate_debris<double>(kContacts, o);
    const LongDoubleReference ref = long_double_reference(scene);
    BodyBuffer<double> bodies = scene.bodies;
    const double err = max_error(reference(bodies, scene.contacts.view()), ref);
    std::cout << "[debris] reference<double> debris" << (friction ? " friction" : "") << ": max " << err
              << " eps * impulse_scale" << std::endl;
    EXPECT_LE(err, kErrorTargetEps) << (friction ? "with" : "without") << " friction";
  }
}

template <class T>
void kernels_on_debris() {
  for (const bool friction : {false, true}) {
    for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
      GenerateOptions o;
      o.friction = friction;
      o.model = model;
      const Scene<T> scene = generate_debris<T>(kContacts, o);
      const LongDoubleReference ref = long_double_reference(scene);
      BodyBuffer<T> bodies = scene.bodies;
      ImpulseBuffer<T> j(scene.contacts.size());
      Schedule schedule;
      schedule.build(scene.contacts.view(), bodies.view());
      Solver(options_for(Path::simd)).solve(model, bodies.view(), scene.contacts.view(), j.view(), schedule);
      const double err = max_error(j, ref);
      std::cout << "[debris] kernel " << type_name<T>() << " " << to_string(model) << " debris"
                << (friction ? " friction" : "") << ": max " << err << " eps * impulse_scale" << std::endl;
      // Open: the particle model without friction (2.4 float, 2.8 double),
      // held to the bound.
      const bool open = !friction && model == Model::particle;
      EXPECT_LE(err, open ? kErrorBoundEps : kErrorTargetEps)
          << to_string(model) << (friction ? " with" : " without") << " friction";
    }
  }
}

TEST(DebrisAccuracy, KernelsOnDebrisFloat) { kernels_on_debris<float>(); }
TEST(DebrisAccuracy, KernelsOnDebrisDouble) { kernels_on_debris<double>(); }

}  // namespace
}  // namespace collide::test
