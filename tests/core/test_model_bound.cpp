// test_model_bound.cpp - the automatic model choice on scenes a broadphase
// writes (model.cpp; the test is derived in docs/collision-law.md, "Which
// body model computes the law").
//
// What this proves
// ----------------
// * Near-collinear scenes - a lattice of touching spheres with anisotropic
//   moments and spin, every normal the centre difference normalised in the
//   scene's precision, every contact point pb + R n rounded in that
//   precision, bodies shared by up to six contacts - pick the particle model
//   in float and in double (also without spin, where the w bound is
//   tightest); near-isotropic moments (a few ulps apart) pick
//   the sphere model, with friction and off-centre contacts.
// * The chosen model's result is within the error bound against the long
//   double reference: every impulse within kImpulseErrorBoundEps units, and
//   every output v and w within the velocity bound of the law doc
//   (C eps (|v0| + sum s / m) and C eps (|w0| + sum s max(invI) |r|)).
// * Where a neglected term matters the choice is rigid, a forced smaller
//   model is refused naming the contact or body, and running that model
//   anyway is outside the bound: the same lattice 2000 radii from the
//   origin (the rounded contact points miss the centres by hundreds of eps),
//   a double scene whose normals were computed in float, and moments 1e-3
//   apart.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

using L = long double;

constexpr double kRadius = 0.5;

/// A side^3 lattice of touching spheres of radius 0.5 around `centre`, each
/// with random anisotropic moments, orientation and spin (|w_i| <= 5), moving
/// towards the centre; a contact joins each pair of lattice neighbours with
/// the normal computed as a broadphase does: n = (pa - pb) / |pa - pb| in
/// precision N, c = pb + R n in T. Frictionless.
template <class T, class N>
SceneRecords<T> lattice(int side, double centre, std::uint64_t seed) {
  Rng rng(seed);
  SceneRecords<T> s;
  const double spacing = 2 * kRadius * 0.999;
  auto id = [side](int x, int y, int z) { return static_cast<BodyIndex>((x * side + y) * side + z); };
  for (int x = 0; x < side; ++x) {
    for (int y = 0; y < side; ++y) {
      for (int z = 0; z < side; ++z) {
        const double half = (side - 1) / 2.0;
        std::array<double, 3> p{(x - half) * spacing, (y - half) * spacing, (z - half) * spacing};
        for (double& c : p) c += rng.uniform(-0.002, 0.002);
        BodyRecord<T> b = random_body<T>(rng, {p[0] + centre, p[1] + centre, p[2] + centre});
        for (int i = 0; i < 3; ++i) b.v[i] = static_cast<T>(-2 * p[i] + rng.uniform(-0.5, 0.5));
        s.bodies.push_back(b);
      }
    }
  }
  for (int x = 0; x < side; ++x) {
    for (int y = 0; y < side; ++y) {
      for (int z = 0; z < side; ++z) {
        const int step[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        for (const auto& d : step) {
          if (x + d[0] >= side || y + d[1] >= side || z + d[2] >= side) continue;
          ContactRecord<T> k;
          k.b = id(x, y, z);
          k.a = id(x + d[0], y + d[1], z + d[2]);
          const BodyRecord<T>& a = s.bodies[k.a];
          const BodyRecord<T>& b = s.bodies[k.b];
          N diff[3];
          for (int i = 0; i < 3; ++i) diff[i] = static_cast<N>(a.p[i]) - static_cast<N>(b.p[i]);
          const N len = std::sqrt(diff[0] * diff[0] + diff[1] * diff[1] + diff[2] * diff[2]);
          for (int i = 0; i < 3; ++i) k.n[i] = static_cast<T>(diff[i] / len);
          for (int i = 0; i < 3; ++i) k.c[i] = b.p[i] + static_cast<T>(kRadius) * k.n[i];
          k.e = static_cast<T>(rng.uniform(0, 1));
          k.mu = 0;
          s.contacts.push_back(k);
        }
      }
    }
  }
  return s;
}

/// Moments that differ by a relative `spread` (x, x (1 + spread), x (1 - spread)).
template <class T>
void spread_moments(SceneRecords<T>& s, double spread) {
  for (auto& b : s.bodies) {
    if (std::isinf(b.m)) continue;
    const double i0 = b.I[0];
    b.I[1] = static_cast<T>(i0 * (1 + spread));
    b.I[2] = static_cast<T>(i0 * (1 - spread));
  }
}

/// The largest errors of a model's run against the long double reference,
/// in units of eps(T) of the impulse bound and of the velocity bound.
struct Errors {
  L impulse = 0, v = 0, w = 0;
  std::size_t acting = 0;
  [[nodiscard]] L worst() const { return std::max({impulse, v, w}); }
};

template <class T>
Errors errors_of(const Scene<T>& scene, Model model) {
  BodyBuffer<T> bodies = scene.bodies;
  ImpulseBuffer<T> j(scene.contacts.size());
  Schedule schedule;
  schedule.build(scene.contacts.view(), bodies.view());
  // Through the model's own view, not solve(Model, ...): the tests force
  // models that do not fit, which that overload asserts against in debug.
  const Solver solver(options_for(Path::simd, 1));
  switch (model) {
    case Model::particle:
      solver.solve(particle_view(bodies.view()), scene.contacts.view(), j.view(), schedule);
      break;
    case Model::sphere:
      solver.solve(sphere_view(bodies.view()), scene.contacts.view(), j.view(), schedule);
      break;
    case Model::rigid:
      solver.solve(bodies.view(), scene.contacts.view(), j.view(), schedule);
      break;
  }

  Scene<L> ref = convert_scene<L>(scene);
  std::vector<ReferenceContact<L>> diag;
  const ImpulseBuffer<L> jr = reference(ref.bodies, ref.contacts.view(), &diag);

  const L eps = std::numeric_limits<T>::epsilon();
  const BodyView<const T> b0 = scene.bodies.view();
  const ContactView<T> c = scene.contacts.view();
  // The velocity bound's scales (docs/collision-law.md): |v0| + sum s / m and
  // |w0| + sum s max(invI) |r| over the body's contacts.
  std::vector<L> v_scale(b0.count), w_scale(b0.count);
  for (std::size_t i = 0; i < b0.count; ++i) {
    v_scale[i] = std::hypot(L(b0.v.x[i]), L(b0.v.y[i]), L(b0.v.z[i]));
    w_scale[i] = std::hypot(L(b0.w.x[i]), L(b0.w.y[i]), L(b0.w.z[i]));
  }
  Errors e;
  for (std::size_t k = 0; k < c.count; ++k) {
    const L dj = std::hypot(L(j.view().j.x[k]) - jr.view().j.x[k], L(j.view().j.y[k]) - jr.view().j.y[k],
                            L(j.view().j.z[k]) - jr.view().j.z[k]);
    e.impulse = std::max(e.impulse, normalised_impulse_error<T>(dj, diag[k]));
    e.acting += diag[k].jn > 0;
    for (const BodyIndex i : {c.a[k], c.b[k]}) {
      const L r = std::hypot(L(c.c.x[k]) - L(b0.p.x[i]), L(c.c.y[k]) - L(b0.p.y[i]), L(c.c.z[k]) - L(b0.p.z[i]));
      const L inv_i = std::max({L(b0.inv_inertia.x[i]), L(b0.inv_inertia.y[i]), L(b0.inv_inertia.z[i])});
      v_scale[i] += diag[k].impulse_scale * L(b0.inv_mass[i]);
      w_scale[i] += diag[k].impulse_scale * inv_i * r;
    }
  }
  const BodyView<const T> b1 = std::as_const(bodies).view();
  const BodyView<const L> br = std::as_const(ref.bodies).view();
  for (std::size_t i = 0; i < b0.count; ++i) {
    if (b0.inv_mass[i] == T(0)) continue;  // never written
    const L dv = std::hypot(L(b1.v.x[i]) - br.v.x[i], L(b1.v.y[i]) - br.v.y[i], L(b1.v.z[i]) - br.v.z[i]);
    const L dw = std::hypot(L(b1.w.x[i]) - br.w.x[i], L(b1.w.y[i]) - br.w.y[i], L(b1.w.z[i]) - br.w.z[i]);
    if (dv > 0) e.v = std::max(e.v, dv / (eps * v_scale[i]));
    if (dw > 0) e.w = std::max(e.w, dw / (eps * w_scale[i]));
  }
  return e;
}

template <class T>
void expect_within_bound(const Scene<T>& scene, Model model) {
  const Errors e = errors_of(scene, model);
  EXPECT_LE(e.impulse, kImpulseErrorBoundEps) << to_string(model);
  EXPECT_LE(e.v, kImpulseErrorBoundEps) << to_string(model);
  EXPECT_LE(e.w, kImpulseErrorBoundEps) << to_string(model);
  EXPECT_GT(e.acting, scene.contacts.size() / 2);
  std::printf("  %s %s: impulse %.3Lg, v %.3Lg, w %.3Lg units (bound %g), %zu of %zu contacts act\n", type_name<T>(),
              to_string(model), e.impulse, e.v, e.w, kImpulseErrorBoundEps, e.acting, scene.contacts.size());
}

template <class T>
Model chosen(Scene<T>& s) {
  return choose_model(s.bodies.view(), s.contacts.view());
}

template <class T>
std::string misfit(Model m, Scene<T>& s) {
  return model_misfit(m, s.bodies.view(), s.contacts.view());
}

template <class T>
void near_collinear_picks_particle() {
  SCOPED_TRACE(type_name<T>());
  for (const std::uint64_t seed : {1, 2, 3}) {
    SceneRecords<T> r = lattice<T, T>(6, 0.0, seed);
    if (seed == 3) {
      // No spin: the velocity bound of w is then the angular response alone,
      // the tightest case of the w test.
      for (auto& b : r.bodies) b.w[0] = b.w[1] = b.w[2] = 0;
    }
    Scene<T> s = r.scene();
    ASSERT_EQ(chosen(s), Model::particle) << misfit(Model::particle, s);
    // Not exactly central: a rule that asked for r x n = 0 exactly would not
    // pick the particle model here.
    bool off_centre = false;
    const auto c = s.contacts.view();
    const auto b = s.bodies.view();
    for (std::size_t k = 0; k < c.count && !off_centre; ++k) {
      const L rx = L(c.c.x[k]) - L(b.p.x[c.a[k]]), ry = L(c.c.y[k]) - L(b.p.y[c.a[k]]);
      const L rz = L(c.c.z[k]) - L(b.p.z[c.a[k]]);
      off_centre = ry * c.n.z[k] - rz * c.n.y[k] != 0 || rz * c.n.x[k] - rx * c.n.z[k] != 0 ||
                   rx * c.n.y[k] - ry * c.n.x[k] != 0;
    }
    EXPECT_TRUE(off_centre);
    expect_within_bound(s, Model::particle);
  }
}

TEST(ModelBound, NearCollinearFloatScenePicksParticle) { near_collinear_picks_particle<float>(); }
TEST(ModelBound, NearCollinearDoubleScenePicksParticle) { near_collinear_picks_particle<double>(); }

template <class T>
void near_isotropic_picks_sphere() {
  SCOPED_TRACE(type_name<T>());
  for (const bool friction : {false, true}) {
    SceneOptions o;
    o.seed = 11;
    o.friction = friction;
    SceneRecords<T> r = shared_records<T>(3000, 1000, o);
    spread_moments(r, 3 * std::numeric_limits<T>::epsilon());
    Scene<T> s = r.scene();
    // The moments really differ (a few ulps), so the exact rule would fail.
    const auto b = s.bodies.view();
    EXPECT_NE(b.inv_inertia.x[0], b.inv_inertia.y[0]);
    ASSERT_EQ(chosen(s), Model::sphere) << misfit(Model::sphere, s);
    expect_within_bound(s, Model::sphere);
  }
}

TEST(ModelBound, NearIsotropicFloatScenePicksSphere) { near_isotropic_picks_sphere<float>(); }
TEST(ModelBound, NearIsotropicDoubleScenePicksSphere) { near_isotropic_picks_sphere<double>(); }

/// `s` picks rigid, a forced `smaller` model is refused naming `offender`,
/// and running it anyway leaves the bound.
template <class T>
void expect_rigid_and_smaller_outside(Scene<T>& s, Model smaller, const std::string& offender) {
  EXPECT_EQ(chosen(s), Model::rigid);
  const std::string why = misfit(smaller, s);
  EXPECT_NE(why.find(offender), std::string::npos) << why;
  expect_within_bound(s, Model::rigid);
  const Errors forced = errors_of(s, smaller);
  std::printf("  forced %s: impulse %.3Lg, v %.3Lg, w %.3Lg units (bound %g)\n", to_string(smaller), forced.impulse,
              forced.v, forced.w, kImpulseErrorBoundEps);
  EXPECT_GT(forced.worst(), kImpulseErrorBoundEps) << "the neglected term did not matter: the test is too strict";
}

TEST(ModelBound, FarFromTheOriginPicksRigid) {
  // 2000 radii out, the contact points rounded in float miss the centres by
  // ~eps |c| / R, hundreds of eps: the angular response the particle model
  // drops is outside the velocity bound.
  Scene<float> s = lattice<float, float>(4, 1000.0, 5).scene();
  expect_rigid_and_smaller_outside(s, Model::particle, "contact ");
}

TEST(ModelBound, DoubleSceneWithFloatNormalsPicksRigid) {
  Scene<double> s = lattice<double, float>(4, 0.0, 6).scene();
  expect_rigid_and_smaller_outside(s, Model::particle, "contact 0: the normal does not pass through the centre");
}

TEST(ModelBound, SlightlyAnisotropicPicksRigid) {
  for (const bool friction : {false, true}) {
    SceneOptions o;
    o.seed = 12;
    o.friction = friction;
    SceneRecords<double> r = shared_records<double>(3000, 1000, o);
    spread_moments(r, 1e-3);
    Scene<double> s = r.scene();
    expect_rigid_and_smaller_outside(s, Model::sphere, "body 0 has unequal principal moments");
  }
}

TEST(ModelBound, TheThresholdIsAQuarterOfTheBound) {
  EXPECT_EQ(kModelOmissionEps * 4, kImpulseErrorBoundEps);
  // Just inside and just outside the sphere threshold, in float.
  SceneRecords<float> r = pairs_records<float>(4, SceneOptions{});
  for (auto& b : r.bodies) b.I[1] = b.I[2] = b.I[0];
  Scene<float> equal = r.scene();
  EXPECT_EQ(chosen(equal), Model::sphere);
  const float eps = std::numeric_limits<float>::epsilon();
  Scene<float> inside = r.scene();
  inside.bodies.view().inv_inertia.y[2] = inside.bodies.view().inv_inertia.x[2] * (1 + 8 * eps);
  EXPECT_EQ(misfit(Model::sphere, inside), "");
  Scene<float> outside = r.scene();
  outside.bodies.view().inv_inertia.y[2] = outside.bodies.view().inv_inertia.x[2] * (1 + 32 * eps);
  EXPECT_NE(misfit(Model::sphere, outside).find("body 2"), std::string::npos) << misfit(Model::sphere, outside);
}

}  // namespace
}  // namespace collide::test
