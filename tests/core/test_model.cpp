// test_model.cpp - the body models (model.cpp, collide/model.hpp) and the
// kernels that run them (particle, sphere, rigid in contact_kernel.hpp).
//
// What this proves
// ----------------
// * choose_model() picks the cheapest model whose omitted terms are within
//   the bound (here they are exactly zero; near-zero cases are in
//   test_model_bound.cpp): particle for bodies that cannot rotate and do not spin, particle
//   for frictionless contacts whose normals pass through both centres (even
//   with spinning bodies), sphere for equal principal moments (whatever the
//   orientation, immovable bodies' moments ignored), rigid otherwise; and
//   model_misfit() names the first body or contact that does not fit.
// * When a model fits, its kernel computes the law: within the error bound
//   of the long double reference for every contact, on pairs and shared-body
//   scenes, with friction where the model allows it; the particle model
//   never touches w; the SIMD and scalar paths agree bit for bit, and so do
//   1 and 3 threads with small blocks.
// * collide::solve (the one-shot call) runs the chosen model and says so in
//   its stats.
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

enum class Shape { points, central, spheres, rigid };

/// A scene that fits the model of `shape`:
///   points  - bodies with infinite moments and no spin (particle rule 1);
///   central - spinning rigid bodies, frictionless, every normal along a
///             coordinate axis through both centres (particle rule 2);
///   spheres - equal principal moments, random orientations (sphere);
///   rigid   - the general random scene.
template <class T>
SceneRecords<T> shaped(Shape shape, bool shared, bool friction, std::uint64_t seed) {
  SceneOptions o;
  o.seed = seed;
  o.friction = friction && shape != Shape::central;
  SceneRecords<T> r = shared ? shared_records<T>(3000, 1000, o) : pairs_records<T>(2003, o);
  Rng rng(seed + 1000);
  const T inf = std::numeric_limits<T>::infinity();
  for (auto& b : r.bodies) {
    if (std::isinf(b.m)) {
      // The ground: its moments never matter; its spin does for particles.
      if (shape == Shape::points) b.w[0] = b.w[1] = b.w[2] = 0;
      continue;
    }
    switch (shape) {
      case Shape::points:
        b.I[0] = b.I[1] = b.I[2] = inf;
        b.w[0] = b.w[1] = b.w[2] = 0;
        break;
      case Shape::spheres:
        b.I[1] = b.I[2] = b.I[0];
        break;
      case Shape::central:
      case Shape::rigid:
        break;
    }
  }
  if (shape == Shape::central) {
    // Move each body so that every contact's normal runs along an axis
    // through both centres: only pairs (each body in one contact) can do so.
    for (auto& c : r.contacts) {
      const int axis = static_cast<int>(rng.index(3));
      const T sign = rng.chance(0.5) ? T(1) : T(-1);
      for (int i = 0; i < 3; ++i) c.n[i] = i == axis ? sign : T(0);
      BodyRecord<T>& a = r.bodies[c.a];
      BodyRecord<T>& b = r.bodies[c.b];
      for (int i = 0; i < 3; ++i) {
        if (i != axis) a.p[i] = b.p[i] = c.c[i];
      }
      a.p[axis] = c.c[axis] + sign * T(rng.uniform(0.1, 1.5));  // a on the +n side
      b.p[axis] = c.c[axis] - sign * T(rng.uniform(0.1, 1.5));
      make_approach(a, b, c);
    }
  }
  return r;
}

Model expected_model(Shape s) {
  switch (s) {
    case Shape::points:
    case Shape::central:
      return Model::particle;
    case Shape::spheres:
      return Model::sphere;
    case Shape::rigid:
      break;
  }
  return Model::rigid;
}

const char* name(Shape s) {
  switch (s) {
    case Shape::points:
      return "points";
    case Shape::central:
      return "central";
    case Shape::spheres:
      return "spheres";
    case Shape::rigid:
      break;
  }
  return "rigid";
}

TEST(Model, ChooseModelPicksTheCheapestThatFits) {
  for (const Shape shape : {Shape::points, Shape::central, Shape::spheres, Shape::rigid}) {
    for (const bool friction : {false, true}) {
      SCOPED_TRACE(std::string(name(shape)) + (friction ? " friction" : ""));
      // Central contacts need distinct bodies per contact: pairs only.
      const Scene<double> s = shaped<double>(shape, shape != Shape::central, friction, 3).scene();
      Scene<double> copy = s;
      const ContactView<double> c = copy.contacts.view();
      EXPECT_EQ(choose_model(copy.bodies.view(), c), expected_model(shape));
      EXPECT_EQ(model_misfit(expected_model(shape), copy.bodies.view(), c), "");
      EXPECT_EQ(model_misfit(Model::rigid, copy.bodies.view(), c), "");
    }
  }
  EXPECT_STREQ(to_string(Model::particle), "particle");
  EXPECT_STREQ(to_string(Model::sphere), "sphere");
  EXPECT_STREQ(to_string(Model::rigid), "rigid");
}

TEST(Model, MisfitNamesTheFirstOffender) {
  Scene<double> s = shaped<double>(Shape::spheres, false, false, 4).scene();
  // Body 5 gets unequal moments.
  s.bodies.view().inv_inertia.y[5] *= 2;
  EXPECT_EQ(choose_model(s.bodies.view(), s.contacts.view()), Model::rigid);
  const std::string sphere = model_misfit(Model::sphere, s.bodies.view(), s.contacts.view());
  EXPECT_NE(sphere.find("body 5"), std::string::npos) << sphere;
  // Particle: bodies rotate and normals are off-centre.
  const std::string particle = model_misfit(Model::particle, s.bodies.view(), s.contacts.view());
  EXPECT_NE(particle.find("body 0"), std::string::npos) << particle;
  EXPECT_NE(particle.find("contact 0"), std::string::npos) << particle;
  // With friction the second particle rule cannot apply.
  Scene<double> f = shaped<double>(Shape::rigid, false, true, 4).scene();
  const std::string pf = model_misfit(Model::particle, f.bodies.view(), f.contacts.view());
  EXPECT_NE(pf.find("friction"), std::string::npos) << pf;
  // An immovable body's unequal moments do not matter for spheres; its spin
  // does for particles.
  Scene<double> g = shaped<double>(Shape::points, true, false, 5).scene();
  EXPECT_EQ(choose_model(g.bodies.view(), g.contacts.view()), Model::particle);
  const std::size_t ground = g.bodies.size() - 1;
  g.bodies.view().inv_inertia.x[ground] = 3;  // stale, ignored
  EXPECT_EQ(choose_model(g.bodies.view(), g.contacts.view()), Model::particle);
  g.bodies.view().w.z[ground] = 0.5;  // a spinning ground moves its contact points
  EXPECT_NE(choose_model(g.bodies.view(), g.contacts.view()), Model::particle);
}

/// Runs `model` on the scene and checks it against the long double
/// reference (error bound), the SIMD path against the scalar path, 1 against
/// 3 threads (bitwise), and what the particle model must leave alone.
template <class T>
void expect_model_computes_the_law(Shape shape, bool shared, bool friction) {
  const Model model = expected_model(shape);
  SCOPED_TRACE(std::string(type_name<T>()) + " " + name(shape) + (shared ? " shared" : " pairs") +
               (friction ? " friction" : ""));
  const Scene<T> scene = shaped<T>(shape, shared, friction, 6).scene();
  Scene<T> probe = scene;
  ASSERT_EQ(choose_model(probe.bodies.view(), probe.contacts.view()), model);

  auto run = [&](Path path, int threads, BodyBuffer<T>& bodies) {
    bodies = scene.bodies;
    ImpulseBuffer<T> j(scene.contacts.size());
    Schedule schedule;
    schedule.build(scene.contacts.view(), bodies.view());
    const SolveStats st =
        Solver(options_for(path, threads, 8)).solve(model, bodies.view(), scene.contacts.view(), j.view(), schedule);
    EXPECT_EQ(st.model, model);
    EXPECT_EQ(st.friction, scene.contacts.view().mu != nullptr);
    return j;
  };
  BodyBuffer<T> simd_bodies, scalar_bodies, threaded_bodies;
  const ImpulseBuffer<T> j = run(Path::simd, 1, simd_bodies);
  EXPECT_TRUE(same_impulses(j, run(Path::scalar, 1, scalar_bodies)));
  EXPECT_TRUE(same_bodies(simd_bodies, scalar_bodies));
  EXPECT_TRUE(same_impulses(j, run(Path::simd, 3, threaded_bodies)));
  EXPECT_TRUE(same_bodies(simd_bodies, threaded_bodies));

  if (model == Model::particle) {
    // Neither w nor anything but v is written.
    const auto before = body_arrays<T>(scene.bodies.view());
    const auto after = body_arrays<T>(std::as_const(simd_bodies).view());
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      for (std::size_t f = 14; f < 17; ++f) ASSERT_TRUE(same_bits(before[f][i], after[f][i])) << "body " << i;
    }
  }

  Scene<long double> ref = convert_scene<long double>(scene);
  std::vector<ReferenceContact<long double>> diag;
  const ImpulseBuffer<long double> jr = reference(ref.bodies, ref.contacts.view(), &diag);
  const long double eps = std::numeric_limits<T>::epsilon();
  long double worst = 0;
  std::size_t acting = 0;
  for (std::size_t k = 0; k < j.size(); ++k) {
    const long double dx = j.view().j.x[k] - jr.view().j.x[k], dy = j.view().j.y[k] - jr.view().j.y[k],
                      dz = j.view().j.z[k] - jr.view().j.z[k];
    const long double scale = diag[k].impulse_scale;
    const long double err = std::sqrt(dx * dx + dy * dy + dz * dz);
    worst = std::max(worst, err / (eps * scale));
    acting += diag[k].jn > 0;
  }
  EXPECT_LE(worst, kErrorBoundEps);
  EXPECT_GT(acting, j.size() / 2);
}

TEST(Model, EachModelComputesTheLawWhereItFits) {
  for (const bool friction : {false, true}) {
    for (const bool shared : {false, true}) {
      expect_model_computes_the_law<float>(Shape::points, shared, friction);
      expect_model_computes_the_law<double>(Shape::points, shared, friction);
      expect_model_computes_the_law<float>(Shape::spheres, shared, friction);
      expect_model_computes_the_law<double>(Shape::spheres, shared, friction);
    }
  }
  expect_model_computes_the_law<float>(Shape::central, false, false);
  expect_model_computes_the_law<double>(Shape::central, false, false);
}

// The one-shot collide::solve chooses the model itself.
TEST(Model, OneShotSolveRunsTheChosenModel) {
  for (const Shape shape : {Shape::points, Shape::central, Shape::spheres, Shape::rigid}) {
    SCOPED_TRACE(name(shape));
    Scene<double> s = shaped<double>(shape, false, false, 7).scene();
    ImpulseBuffer<double> j(s.contacts.size());
    const SolveStats st = collide::solve(s.bodies.view(), s.contacts.view(), j.view(), options_for(Path::simd, 1));
    EXPECT_EQ(st.model, expected_model(shape));
    // Same answer as an explicit Solver run with that model.
    Scene<double> t = shaped<double>(shape, false, false, 7).scene();
    ImpulseBuffer<double> jt(t.contacts.size());
    Schedule schedule;
    schedule.build(t.contacts.view(), t.bodies.view());
    Solver(options_for(Path::simd, 1)).solve(st.model, t.bodies.view(), t.contacts.view(), jt.view(), schedule);
    EXPECT_TRUE(same_impulses(j, jt));
    EXPECT_TRUE(same_bodies(s.bodies, t.bodies));
  }
}

}  // namespace
}  // namespace collide::test
