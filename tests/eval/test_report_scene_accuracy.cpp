// test_report_scene_accuracy.cpp - the fast mode's error on the scenes of
// `collide report` (generate.hpp): pairs and debris (shared bodies, chains of
// contacts), every model, float and double, with and without friction, and
// of reference_solve<double> on the debris scenes: no contact above
// kImpulseErrorTargetEps (2 units).
//
// Why these scenes: the particle model without friction is where a single
// contact's own rounding, not a chain, decides. Taking the stored normal as
// unit and rounding vn = (va - vb) . n and (1 + e) vn / K cost up to 1.4 to
// 1.8 units each (hard_attribution); so the fast mode folds |n|^2 into K and
// forms the particle's vn and jn in double lanes (float) or compensated
// (double), rounding jn once (contact_kernel.hpp, fast_normal_impulse; the
// figures: docs/decisions/0010-the-fast-modes-normal-impulse.md).
//
// With friction, the debris scene's worst contact is the first on both of
// its bodies, so not a chain: its friction step reads the velocities left by
// its own normal impulse, whose rounding (relative to max(1/I) |r| jn, large
// for a long lever on a body with unequal moments) the impulse scale counts
// (reference.cpp, `after_normal`; docs/collision-law.md, "The friction step
// after the normal impulse"; the figures:
// docs/decisions/0008-the-impulse-scale.md). reference_solve<double>, the
// plainest evaluation of the law, is held to the same unit, so a unit that
// is short shows there and not only in the kernels.
//
// Mutations checked: without `after_normal`, ReferenceDoubleOnDebris and
// KernelsOnDebrisDouble fail with friction; with fast_normal_impulse's
// particle path replaced by the plain -(1 + e) ((va - vb) . n) / K in T,
// the particle rows of every kernel test here fail.
#include <algorithm>
#include <cstddef>
#include <iostream>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/check.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"
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

TEST(ReportSceneAccuracy, ReferenceDoubleOnDebris) {
  for (const bool friction : {false, true}) {
    GenerateOptions o;
    o.friction = friction;
    const Scene<double> scene = generate_debris<double>(kContacts, o);
    const LongDoubleReference ref = long_double_reference(scene);
    BodyBuffer<double> bodies = scene.bodies;
    const double err = max_error(reference(bodies, scene.contacts.view()), ref);
    std::cout << "[scene] reference<double> debris" << (friction ? " friction" : "") << ": max " << err
              << " eps * impulse_scale" << std::endl;
    EXPECT_LE(err, kErrorTargetEps) << (friction ? "with" : "without") << " friction";
  }
}

enum class Kind { pairs, debris };

template <class T>
void kernels_on(Kind kind) {
  const char* name = kind == Kind::pairs ? "pairs" : "debris";
  for (const bool friction : {false, true}) {
    for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
      GenerateOptions o;
      o.friction = friction;
      o.model = model;
      const Scene<T> scene = kind == Kind::pairs ? generate_pairs<T>(kContacts, o) : generate_debris<T>(kContacts, o);
      const LongDoubleReference ref = long_double_reference(scene);
      BodyBuffer<T> bodies = scene.bodies;
      ImpulseBuffer<T> j(scene.contacts.size());
      Schedule schedule;
      schedule.build(scene.contacts.view(), bodies.view());
      Solver(options_for(Path::simd)).solve(model, bodies.view(), scene.contacts.view(), j.view(), schedule);
      const double err = max_error(j, ref);
      std::cout << "[scene] kernel " << type_name<T>() << " " << to_string(model) << " " << name
                << (friction ? " friction" : "") << ": max " << err << " eps * impulse_scale" << std::endl;
      EXPECT_LE(err, kErrorTargetEps) << name << " " << to_string(model) << (friction ? " with" : " without")
                                      << " friction";
    }
  }
}

TEST(ReportSceneAccuracy, KernelsOnPairsFloat) { kernels_on<float>(Kind::pairs); }
TEST(ReportSceneAccuracy, KernelsOnPairsDouble) { kernels_on<double>(Kind::pairs); }
TEST(ReportSceneAccuracy, KernelsOnDebrisFloat) { kernels_on<float>(Kind::debris); }
TEST(ReportSceneAccuracy, KernelsOnDebrisDouble) { kernels_on<double>(Kind::debris); }

}  // namespace
}  // namespace collide::test
