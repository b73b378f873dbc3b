// test_reference.cpp - the world-frame reference (reference.cpp) that every
// fast path is measured against.
//
// What this proves
// ----------------
// * The diagnostics mean what reference.hpp says, on a hand-checkable case
//   (a rod struck at its tip): vn, K(n), jn, speed_scale and impulse_scale
//   have their closed-form values; without an impulse they report none.
// * On random contacts the diagnostics are consistent with the law and with
//   each other: jn = -(1 + e) vn / K(n) >= 0, |jn| <= impulse_scale,
//   0 <= jt <= mu jn, J = jn n - jt t with t a unit vector orthogonal to n,
//   the separation speed after a frictionless contact is -e vn, and friction
//   never reverses the sliding direction (the tangential velocity after it is
//   a non-negative multiple of the one before, i.e. Coulomb's law: it stops
//   or slows the sliding, never more).
// * Contacts that share bodies are applied one after another in input order:
//   a Newton's cradle of three equal balls (e = 1) listed (0,1), (1,2) moves
//   the whole velocity to the last ball; listed (1,2), (0,1) it stops at the
//   middle one - for the reference and for the kernel alike.
// * reference_solve<double> and reference_solve<long double> agree within
//   the error bound (the double reference is itself a precision-eps
//   evaluation of the law).
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

template <class S>
class ReferenceTyped : public ::testing::Test {};
using RefPrecisions = ::testing::Types<double, long double>;
TYPED_TEST_SUITE(ReferenceTyped, RefPrecisions);

// Rod (m = 4, L = 2, 1/I = 3/4 about its transverse axes) moving at -2 along
// y, tip (1, 0, 0) on an immovable wall (normal +y), e = 1/2, mu = 0.3:
// vn = -2, K(n) = 1/4 + 3/4 = 1, jn = 3, speed_scale = |v| = 2,
// impulse_scale = (1 + e) 2 / 1 = 3. Then two more contacts at the same tip.
TYPED_TEST(ReferenceTyped, DiagnosticsOfRodOnWall) {
  using S = TypeParam;
  BodyBuffer<S> b;
  BodyRecord<S> rod;
  rod.m = 4;
  rod.v[1] = -2;
  b.push_back(rod);
  BodyRecord<S> wall;
  wall.m = std::numeric_limits<S>::infinity();
  wall.p[0] = 1, wall.p[1] = -3;
  b.push_back(wall);
  b.view().inv_inertia.x[0] = 2;
  b.view().inv_inertia.y[0] = S(0.75);
  b.view().inv_inertia.z[0] = S(0.75);
  ContactBuffer<S> c;
  ContactRecord<S> k;
  k.a = 0, k.b = 1;
  k.c[0] = 1;
  k.n[0] = 0, k.n[1] = 1, k.n[2] = 0;
  k.e = S(0.5);
  k.mu = S(0.3);
  c.push_back(k);
  // Second contact, normal -y at the same tip: after the first impulse the
  // rod moves at -2 + 3/4 = -1.25 with spin 9/4, so the tip moves at
  // -1.25 + 2.25 = +1 along y: vn = -1, K(n) = 1, jn = 1.5. The speed
  // scale is 1.25 + 2.25 * 1 = 3.5 plus what the rod inherits from the first
  // contact (scale 7.5): 7.5 / m = 1.875 linear and 7.5 max(1/I) |r| =
  // 7.5 * 2 * 1 = 15 angular at |r| = 1, so 20.375, and impulse_scale =
  // 1.5 * (20.375 + 1 * 1.5 / 1).
  k.n[1] = -1;
  c.push_back(k);
  // Third contact, normal +x: the tip has no x velocity, the contact rests:
  // no impulse; the impulse scale is still defined (the normal one).
  k.n[0] = 1, k.n[1] = 0;
  c.push_back(k);
  std::vector<ReferenceContact<S>> d;
  const ImpulseBuffer<S> j = reference(b, c.view(), &d);
  EXPECT_EQ(d[0].vn, S(-2));
  EXPECT_EQ(d[0].k_n, S(1));
  EXPECT_EQ(d[0].jn, S(3));
  EXPECT_EQ(d[0].jt, S(0));  // the tip does not slide: ut = 0, no friction
  EXPECT_EQ(d[0].k_t, S(0));
  EXPECT_EQ(d[0].speed_scale, S(2));
  // The lever-arm term: r x n = (0, 0, 1) in the rod's frame, so
  // 2 |r| sum invI_i |h_i| = 2 * 1 * 0.75 = 1.5 (the wall adds nothing), and
  // impulse_scale = (1 + e) (speed_scale + |vn| 1.5 / K) / K = 1.5 * 5.
  EXPECT_EQ(d[0].impulse_scale, S(7.5));
  EXPECT_EQ(j.view().j.y[0], S(3));
  EXPECT_EQ(d[1].vn, S(-1));
  EXPECT_EQ(d[1].k_n, S(1));
  EXPECT_EQ(d[1].jn, S(1.5));
  EXPECT_EQ(d[1].speed_scale, S(20.375));
  EXPECT_EQ(d[1].impulse_scale, S(32.8125));
  EXPECT_EQ(j.view().j.y[1], S(-1.5));
  EXPECT_EQ(d[2].vn, S(0));
  EXPECT_EQ(d[2].jn, S(0));
  EXPECT_GT(d[2].speed_scale, S(0));
  EXPECT_EQ(d[2].impulse_scale, (1 + S(0.5)) * d[2].speed_scale / d[2].k_n);
  EXPECT_EQ(j.view().j.x[2], S(0));
  // The rod: v = -1.25 - 1.5/4, w_z = 2.25 - 0.75 * 1.5; the wall untouched.
  EXPECT_EQ(std::as_const(b).view().v.y[0], S(-1.625));
  EXPECT_EQ(std::as_const(b).view().w.z[0], S(1.125));
  EXPECT_EQ(std::as_const(b).view().v.y[1], S(0));
}

// Random pairs with friction and e in [0, 1]: the diagnostics obey the law.
TYPED_TEST(ReferenceTyped, DiagnosticsObeyTheLaw) {
  using S = TypeParam;
  SceneOptions o;
  o.seed = 8;
  o.friction = true;
  const Scene<S> before = pairs_scene<S>(5000, o);
  Scene<S> after = before;
  std::vector<ReferenceContact<S>> d;
  const ImpulseBuffer<S> j = reference(after.bodies, after.contacts.view(), &d);
  const ContactView<S> c = before.contacts.view();
  const S eps = std::numeric_limits<S>::epsilon();
  std::size_t sliding = 0, sticking = 0;
  for (std::size_t k = 0; k < c.count; ++k) {
    SCOPED_TRACE("contact " + std::to_string(k));
    const ReferenceContact<S>& r = d[k];
    ASSERT_LT(r.vn, S(0));  // the builder makes every pair approach
    ASSERT_GT(r.k_n, S(0));
    EXPECT_NEAR(r.jn, -(1 + c.e[k]) * r.vn / r.k_n, 4 * eps * r.jn);
    EXPECT_LE(r.jn, r.impulse_scale);
    EXPECT_GE(r.jt, S(0));
    EXPECT_LE(r.jt, c.mu[k] * r.jn * (1 + 4 * eps));
    sliding += r.jt > 0 && r.jt >= c.mu[k] * r.jn * (1 - 4 * eps);
    sticking += r.jt > 0 && r.jt < c.mu[k] * r.jn * (1 - 4 * eps);
    // J = jn n - jt t, t unit and orthogonal to n, with n the law's unit
    // normal (the stored one is unit only to the rounding of the scene).
    const S len = std::sqrt(c.n.x[k] * c.n.x[k] + c.n.y[k] * c.n.y[k] + c.n.z[k] * c.n.z[k]);
    const S n[3] = {c.n.x[k] / len, c.n.y[k] / len, c.n.z[k] / len};
    const S jv[3] = {j.view().j.x[k], j.view().j.y[k], j.view().j.z[k]};
    S t[3], tn = 0, tt = 0;
    for (int i = 0; i < 3; ++i) {
      t[i] = (r.jn * n[i] - jv[i]) / r.jt;
      tn += t[i] * n[i];
      tt += t[i] * t[i];
    }
    if (r.jt > 1e-3 * r.jn) {
      EXPECT_NEAR(tt, S(1), 64 * eps * r.jn / r.jt);
      EXPECT_NEAR(tn, S(0), 64 * eps * r.jn / r.jt);
    }
  }
  // Both Coulomb regimes occur.
  EXPECT_GT(sliding, 500u);
  EXPECT_GT(sticking, 500u);
}

/// u = (va + wa x ra) - (vb + wb x rb) for contact k of a pairs scene.
template <class S>
std::array<S, 3> relative_velocity(const BodyView<const S>& b, const ContactView<S>& c, std::size_t k) {
  std::array<S, 3> u{};
  for (const auto& [i, sign] : {std::pair{c.a[k], S(1)}, std::pair{c.b[k], S(-1)}}) {
    const S r[3] = {c.c.x[k] - b.p.x[i], c.c.y[k] - b.p.y[i], c.c.z[k] - b.p.z[i]};
    const S w[3] = {b.w.x[i], b.w.y[i], b.w.z[i]};
    const S v[3] = {b.v.x[i], b.v.y[i], b.v.z[i]};
    u[0] += sign * (v[0] + w[1] * r[2] - w[2] * r[1]);
    u[1] += sign * (v[1] + w[2] * r[0] - w[0] * r[2]);
    u[2] += sign * (v[2] + w[0] * r[1] - w[1] * r[0]);
  }
  return u;
}

// Frictionless: the separation speed is -e vn (to rounding). With friction:
// the friction impulse is -jt t with t along the sliding velocity, and it
// stops or slows the sliding but never reverses it, so the tangential
// velocity after, projected on t, is >= 0 (to rounding).
TYPED_TEST(ReferenceTyped, SeparationSpeedAndCoulombDirection) {
  using S = TypeParam;
  for (const bool friction : {false, true}) {
    SceneOptions o;
    o.seed = 9;
    o.friction = friction;
    const Scene<S> before = pairs_scene<S>(3000, o);
    Scene<S> after = before;
    std::vector<ReferenceContact<S>> d;
    const ImpulseBuffer<S> j = reference(after.bodies, after.contacts.view(), &d);
    const ContactView<S> c = before.contacts.view();
    const S eps = std::numeric_limits<S>::epsilon();
    for (std::size_t k = 0; k < c.count; ++k) {
      const auto u = relative_velocity<S>(std::as_const(after.bodies).view(), c, k);
      const S n[3] = {c.n.x[k], c.n.y[k], c.n.z[k]};
      const S vn_after = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
      const S tol = 64 * eps * d[k].speed_scale * (1 + d[k].impulse_scale * d[k].k_n);
      if (!friction) {
        ASSERT_NEAR(vn_after, -c.e[k] * d[k].vn, tol) << "contact " << k;
      } else if (d[k].jt > 0) {
        S t[3], ut_t = 0;
        for (int i = 0; i < 3; ++i) {
          t[i] = (d[k].jn * n[i] - (i == 0 ? j.view().j.x[k] : i == 1 ? j.view().j.y[k] : j.view().j.z[k])) / d[k].jt;
          ut_t += (u[i] - vn_after * n[i]) * t[i];
        }
        ASSERT_GE(ut_t, -tol) << "contact " << k << ": friction reversed the sliding";
      }
    }
  }
}

// Three equal balls on a line, e = 1, ball 0 moving at +2 towards 1 and 2 at
// rest and touching. The law applies contacts in input order.
template <class S>
Scene<S> cradle(bool forward) {
  Scene<S> s;
  for (int i = 0; i < 3; ++i) {
    BodyRecord<S> b;
    b.m = 2;
    b.p[0] = S(2 * i);
    if (i == 0) b.v[0] = 2;
    s.bodies.push_back(b);
  }
  // Contact between i and i+1 at x = 2i + 1; a = i + 1 (normal +x from i).
  auto contact = [](BodyIndex i) {
    ContactRecord<S> c;
    c.a = i + 1;
    c.b = i;
    c.c[0] = S(2 * i + 1);
    c.n[0] = 1, c.n[1] = 0, c.n[2] = 0;
    c.e = 1;
    return c;
  };
  if (forward) {
    s.contacts.push_back(contact(0));
    s.contacts.push_back(contact(1));
  } else {
    s.contacts.push_back(contact(1));
    s.contacts.push_back(contact(0));
  }
  return s;
}

template <class S>
void expect_cradle(const Scene<S>& after, bool forward) {
  const BodyView<const S> b = after.bodies.view();
  if (forward) {
    EXPECT_EQ(b.v.x[0], S(0));
    EXPECT_EQ(b.v.x[1], S(0));
    EXPECT_EQ(b.v.x[2], S(2));
  } else {
    EXPECT_EQ(b.v.x[0], S(0));
    EXPECT_EQ(b.v.x[1], S(2));
    EXPECT_EQ(b.v.x[2], S(0));
  }
}

TEST(ReferenceOrder, NewtonsCradleFollowsInputOrder) {
  for (const bool forward : {true, false}) {
    SCOPED_TRACE(forward ? "(0,1) then (1,2)" : "(1,2) then (0,1)");
    {
      Scene<double> s = cradle<double>(forward);
      reference(s.bodies, s.contacts.view());
      expect_cradle(s, forward);
    }
    {
      Scene<long double> s = cradle<long double>(forward);
      reference(s.bodies, s.contacts.view());
      expect_cradle(s, forward);
    }
    for (const Path path : {Path::scalar, Path::simd}) {
      Scene<float> f = cradle<float>(forward);
      kernel_solve(f.bodies, f.contacts.view(), options_for(path, 2, 8));
      expect_cradle(f, forward);
      Scene<double> d = cradle<double>(forward);
      kernel_solve(d.bodies, d.contacts.view(), options_for(path, 2, 8));
      expect_cradle(d, forward);
    }
  }
}

TEST(ReferencePrecision, DoubleAgreesWithLongDoubleWithinTheBound) {
  SceneOptions o;
  o.seed = 10;
  const Scene<double> s = pairs_scene<double>(20000, o);
  BodyBuffer<double> bd = s.bodies;
  const ImpulseBuffer<double> jd = reference(bd, s.contacts.view());
  Scene<long double> l = convert_scene<long double>(s);
  std::vector<ReferenceContact<long double>> diag;
  const ImpulseBuffer<long double> jl = reference(l.bodies, l.contacts.view(), &diag);
  const long double eps = std::numeric_limits<double>::epsilon();
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    const long double dx = jd.view().j.x[k] - jl.view().j.x[k], dy = jd.view().j.y[k] - jl.view().j.y[k],
                      dz = jd.view().j.z[k] - jl.view().j.z[k];
    ASSERT_LE(std::sqrt(dx * dx + dy * dy + dz * dz), kErrorBoundEps * eps * diag[k].impulse_scale) << "contact " << k;
  }
}

}  // namespace
}  // namespace collide::test
