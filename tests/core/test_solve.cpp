// test_solve.cpp - the collision law on hand-checkable cases, for every
// implementation: the reference (double, long double) and the kernel (float,
// double; scalar and SIMD paths).
//
// What this proves
// ----------------
// * Equal spheres meeting head-on with e = 1 swap their normal velocities and
//   keep their tangential ones, exactly; with friction on nothing changes
//   because nothing slides.
// * e = 0 leaves the two contact points with equal normal velocities (the
//   common velocity of the centre of mass), exactly.
// * A free thin rod (mass m, length L, I = m L^2 / 12) struck perpendicular at
//   its tip, against an immovable wall and by a particle, matches the closed
//   form jn = (1 + e) s / K with K = 1/m + (L/2)^2 / I = 4/m (+ 1/mp), exactly
//   for representable data and to a few eps when the whole configuration is
//   rotated (so the body-frame lever arm and the rotation are exercised).
// * Coulomb friction on a ball sliding on a wall: the sliding branch
//   (jt = mu jn) and the sticking branch (jt = |ut| / K(t), contact point at
//   rest afterwards), exactly.
// * An immovable body (m = inf) is never written, even when it moves
//   (kinematic) and even when its stored inverse moments are stale non-zeros;
//   two immovable bodies give J = 0.
// * Exactly separating (vn > 0) and exactly resting (vn == 0) contacts leave
//   every body bit for bit unchanged, -0.0 included, and give J = 0, with and
//   without friction.
// Each case is replicated into 11 independent copies so that the SIMD path
// runs it in full lanes and in the scalar tail (11 = 8 + 3 floats,
// 2 * 4 + 3 doubles with AVX2).
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "lanes.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

enum class Backend { reference, scalar, simd };

template <class T, Backend B>
struct Impl {
  using Type = T;
  static constexpr Backend backend = B;
};

using Impls = ::testing::Types<Impl<double, Backend::reference>, Impl<long double, Backend::reference>,
                               Impl<float, Backend::scalar>, Impl<float, Backend::simd>, Impl<double, Backend::scalar>,
                               Impl<double, Backend::simd>>;

struct ImplNames {
  template <class P>
  static std::string GetName(int) {
    const char* b = P::backend == Backend::reference ? "reference" : P::backend == Backend::scalar ? "scalar" : "simd";
    std::string t = type_name<typename P::Type>();
    for (char& ch : t) ch = ch == ' ' ? '_' : ch;
    return t + "_" + b;
  }
};

template <class P, class T = typename P::Type>
ImpulseBuffer<T> run(BodyBuffer<T>& bodies, const ContactView<T>& contacts) {
  if constexpr (P::backend == Backend::reference) {
    return reference<T>(bodies, contacts);
  } else {
    // Two threads and a tiny block: the solver's parallel branch is allowed.
    return kernel_solve<T>(bodies, contacts,
                           options_for(P::backend == Backend::simd ? Path::simd : Path::scalar, 2, 8));
  }
}

/// Same value and same sign (bit for bit for float and double; long double
/// has padding bytes, so value + sign + NaN-ness there).
template <class T>
bool identical(T x, T y) {
  if constexpr (std::is_same_v<T, long double>) {
    return (x == y && std::signbit(x) == std::signbit(y)) || (std::isnan(x) && std::isnan(y));
  } else {
    return same_bits(x, y);
  }
}

template <class T>
using V3 = std::array<long double, 3>;

/// A hand-checkable case: bodies, contacts, optional overrides of stored
/// inverse moments (applied after push_back), and the expected results.
template <class T>
struct Case {
  std::vector<BodyRecord<T>> bodies;
  std::vector<ContactRecord<T>> contacts;
  std::vector<std::pair<std::size_t, std::array<T, 3>>> inv_inertia;
  std::vector<V3<T>> v, w;  // expected, per body (ignored for immovable bodies)
  std::vector<V3<T>> j;     // expected, per contact
};

/// The case replicated `copies` times; immovable bodies are shared by all
/// copies (many lanes read one ground body). map[copy][i] = index of body i.
template <class T>
Scene<T> replicate(const Case<T>& c, std::size_t copies, std::vector<std::vector<BodyIndex>>& map) {
  Scene<T> s;
  map.assign(copies, std::vector<BodyIndex>(c.bodies.size()));
  std::vector<BodyIndex> shared(c.bodies.size(), ~BodyIndex(0));
  for (std::size_t k = 0; k < copies; ++k) {
    for (std::size_t i = 0; i < c.bodies.size(); ++i) {
      const bool immovable = std::isinf(c.bodies[i].m);
      if (immovable && shared[i] != ~BodyIndex(0)) {
        map[k][i] = shared[i];
        continue;
      }
      map[k][i] = static_cast<BodyIndex>(s.bodies.size());
      if (immovable) shared[i] = map[k][i];
      s.bodies.push_back(c.bodies[i]);
    }
    for (const auto& [i, inv] : c.inv_inertia) {
      const BodyView<T> v = s.bodies.view();
      v.inv_inertia.x[map[k][i]] = inv[0];
      v.inv_inertia.y[map[k][i]] = inv[1];
      v.inv_inertia.z[map[k][i]] = inv[2];
    }
    for (ContactRecord<T> contact : c.contacts) {
      contact.a = map[k][contact.a];
      contact.b = map[k][contact.b];
      s.contacts.push_back(contact);
    }
  }
  return s;
}

/// Runs the case on implementation P and checks every copy: movable bodies
/// against the expected v, w; immovable ones bit for bit untouched; J. `tol`
/// is an absolute tolerance, 0 for exact equality.
template <class P, class T = typename P::Type>
void check_case(const Case<T>& c, long double tol = 0, std::size_t copies = 11) {
  std::vector<std::vector<BodyIndex>> map;
  const Scene<T> before = replicate(c, copies, map);
  Scene<T> after = before;
  const ImpulseBuffer<T> j = run<P>(after.bodies, after.contacts.view());
  const BodyView<const T> b0 = before.bodies.view();
  const BodyView<const T> b1 = std::as_const(after.bodies).view();
  auto near = [&](long double expected, T got) {
    return tol == 0 ? static_cast<T>(expected) == got : std::fabs(expected - static_cast<long double>(got)) <= tol;
  };
  for (std::size_t k = 0; k < copies; ++k) {
    SCOPED_TRACE("copy " + std::to_string(k));
    for (std::size_t i = 0; i < c.bodies.size(); ++i) {
      const std::size_t id = map[k][i];
      if (std::isinf(c.bodies[i].m)) {
        const auto x = body_arrays<T>(b0);
        const auto y = body_arrays<T>(b1);
        for (std::size_t f = 0; f < 17; ++f) {
          EXPECT_TRUE(identical(x[f][id], y[f][id])) << "immovable body " << i << " field " << kBodyFieldNames[f];
        }
        continue;
      }
      const T v[3] = {b1.v.x[id], b1.v.y[id], b1.v.z[id]};
      const T w[3] = {b1.w.x[id], b1.w.y[id], b1.w.z[id]};
      for (int d = 0; d < 3; ++d) {
        EXPECT_PRED2(near, c.v[i][d], v[d]) << "body " << i << " v[" << d << "]";
        EXPECT_PRED2(near, c.w[i][d], w[d]) << "body " << i << " w[" << d << "]";
      }
    }
    const auto jv = j.view();
    for (std::size_t n = 0; n < c.contacts.size(); ++n) {
      const std::size_t id = k * c.contacts.size() + n;
      const T got[3] = {jv.j.x[id], jv.j.y[id], jv.j.z[id]};
      for (int d = 0; d < 3; ++d) EXPECT_PRED2(near, c.j[n][d], got[d]) << "contact " << n << " J[" << d << "]";
    }
  }
}

template <class T>
BodyRecord<T> body(T m, std::array<T, 3> I, std::array<T, 3> p, std::array<T, 3> v, std::array<T, 3> w,
                   std::array<T, 4> q = {1, 0, 0, 0}) {
  BodyRecord<T> b;
  b.m = m;
  for (int i = 0; i < 3; ++i) {
    b.I[i] = I[i];
    b.p[i] = p[i];
    b.v[i] = v[i];
    b.w[i] = w[i];
  }
  for (int i = 0; i < 4; ++i) b.q[i] = q[i];
  return b;
}

template <class T>
ContactRecord<T> contact(BodyIndex a, BodyIndex b, std::array<T, 3> c, std::array<T, 3> n, T e, T mu = 0) {
  ContactRecord<T> k;
  k.a = a;
  k.b = b;
  for (int i = 0; i < 3; ++i) {
    k.c[i] = c[i];
    k.n[i] = n[i];
  }
  k.e = e;
  k.mu = mu;
  return k;
}

template <class T>
constexpr T kInf = std::numeric_limits<T>::infinity();

template <class P>
class LawCases : public ::testing::Test {};
TYPED_TEST_SUITE(LawCases, Impls, ImplNames);

// Equal spheres (m = 2), head-on along x, e = 1: K = 1/2 + 1/2 = 1 (r x n = 0
// whatever the orientation), vn = -4, jn = 8, the normal velocities -3 and 1
// swap. Tangential velocities are equal, so friction (mu = 0.7) finds ut = 0
// exactly and does nothing. Spins about the normal do not enter.
TYPED_TEST(LawCases, EqualSpheresHeadOnSwapVelocities) {
  using T = typename TypeParam::Type;
  for (const T mu : {T(0), T(0.75)}) {
    SCOPED_TRACE("mu = " + std::to_string(static_cast<double>(mu)));
    Case<T> c;
    c.bodies = {body<T>(2, {0.75, 1.25, 0.5}, {1, 0, 0}, {-3, 0.5, -0.25}, {1.5, 0, 0}, {0.5, 0.5, -0.5, 0.5}),
                body<T>(2, {1, 2, 3}, {-1, 0, 0}, {1, 0.5, -0.25}, {-2, 0, 0}, {0, 0.6, 0, 0.8})};
    c.contacts = {contact<T>(0, 1, {0, 0, 0}, {1, 0, 0}, 1, mu)};
    c.v = {{1, 0.5, -0.25}, {-3, 0.5, -0.25}};
    c.w = {{1.5, 0, 0}, {-2, 0, 0}};
    c.j = {{8, 0, 0}};
    check_case<TypeParam>(c);
  }
}

// e = 0, masses 1 and 4 along z: vn = -3 - 2 = -5, K = 1 + 1/4, jn = 4; both
// normal velocities become 1, the centre-of-mass velocity (-3 + 4 * 2) / 5.
// Tangential components are kept (frictionless).
TYPED_TEST(LawCases, PerfectlyInelasticLeavesEqualNormalVelocities) {
  using T = typename TypeParam::Type;
  Case<T> c;
  c.bodies = {body<T>(1, {0.5, 0.25, 2}, {0, 0, 1}, {2, 0, -3}, {0, 0, 0.75}, {0.5, -0.5, 0.5, 0.5}),
              body<T>(4, {1, 1, 1}, {0, 0, -2}, {0, 1, 2}, {0, 0, -1.5})};
  c.contacts = {contact<T>(0, 1, {0, 0, 0}, {0, 0, 1}, 0)};
  c.v = {{2, 0, 1}, {0, 1, 1}};
  c.w = {{0, 0, 0.75}, {0, 0, -1.5}};
  c.j = {{0, 0, 4}};
  check_case<TypeParam>(c);
  // The normal velocities of the contact points are equal afterwards.
  EXPECT_EQ(c.v[0][2], c.v[1][2]);
}

/// Closed form for a thin rod (mass m, length L, I = m L^2 / 12 about its
/// transverse axes) at rest... moving with its centre at speed s towards a
/// wall, struck perpendicular at its tip; the other side has inverse mass
/// inv_mp (0 for an immovable wall) and moves at sp along the normal towards
/// the rod (its lever arm is parallel to n). Returns jn, the rod's velocity
/// change along n and its spin about the axis n x rod.
struct RodResult {
  long double jn, rod_v, rod_w, other_v;
};
RodResult rod_closed_form(long double m, long double L, long double rod_vn, long double inv_mp, long double other_vn,
                          long double e) {
  const long double I = m * L * L / 12;
  const long double K = 1 / m + (L / 2) * (L / 2) / I + inv_mp;  // = 4/m + inv_mp
  const long double vn = rod_vn - other_vn;                      // tip has no spin before
  const long double jn = -(1 + e) * vn / K;
  return {jn, rod_vn + jn / m, jn * (L / 2) / I, other_vn - jn * inv_mp};
}

// Rod along x (m = 4, L = 2, so I = 4/3 and 1/I = 3/4 stored exactly), centre
// at the origin moving at -2 along y, tip (1, 0, 0) hits an immovable wall
// (normal +y): K = 1/4 + 1 * 3/4 = 1 = 4/m. e = 1: jn = 4, v = -1, w_z = 3, so
// the tip leaves at +2. The wall carries finite moments (ignored) and is
// shared by all copies.
TYPED_TEST(LawCases, RodTipAgainstImmovableWallMatchesClosedForm) {
  using T = typename TypeParam::Type;
  for (const T e : {T(1), T(0.5), T(0)}) {
    SCOPED_TRACE("e = " + std::to_string(static_cast<double>(e)));
    const RodResult r = rod_closed_form(4, 2, -2, 0, 0, e);
    EXPECT_EQ(r.jn, 2 * (1 + static_cast<long double>(e)));  // K = 4/m = 1, vn = -2
    Case<T> c;
    c.bodies = {body<T>(4, {0.5, 4.0 / 3, 4.0 / 3}, {0, 0, 0}, {0, -2, 0}, {0, 0, 0}),
                body<T>(kInf<T>, {1, 2, 3}, {1, -3, 0}, {0, 0, 0}, {0, 0, 0})};
    c.inv_inertia = {{0, {2, 0.75, 0.75}}};
    c.contacts = {contact<T>(0, 1, {1, 0, 0}, {0, 1, 0}, e)};
    c.v = {{0, r.rod_v, 0}, {}};
    c.w = {{0, 0, r.rod_w}, {}};
    c.j = {{0, r.jn, 0}};
    check_case<TypeParam>(c);
  }
}

// The same rod at rest, struck at its tip by a particle (m = 4, lever arm
// parallel to n) moving at +5 along y: K = 1/4 + 4/4 = 5/4, e = 1: jn = 8,
// rod v = 2, w_z = 6, particle 5 -> 3. Energy 50 = 18 + 8 + 24.
TYPED_TEST(LawCases, RodTipStruckByParticleMatchesClosedForm) {
  using T = typename TypeParam::Type;
  const RodResult r = rod_closed_form(4, 2, 0, 0.25, 5, 1);
  EXPECT_EQ(r.jn, 8);
  Case<T> c;
  c.bodies = {body<T>(4, {0.5, 4.0 / 3, 4.0 / 3}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}),
              body<T>(4, {1, 1, 1}, {1, -1, 0}, {0, 5, 0}, {0, 0, 0})};
  c.inv_inertia = {{0, {2, 0.75, 0.75}}};
  c.contacts = {contact<T>(0, 1, {1, 0, 0}, {0, 1, 0}, 1)};
  c.v = {{0, r.rod_v, 0}, {0, r.other_v, 0}};
  c.w = {{0, 0, r.rod_w}, {0, 0, 0}};
  c.j = {{0, r.jn, 0}};
  check_case<TypeParam>(c);
}

/// Rotation matrix of q / |q|, in long double (q is only unit to double
/// precision; the law normalises it, so must the expected values).
std::array<std::array<long double, 3>, 3> rotation_matrix(const std::array<double, 4>& q) {
  const long double w = q[0], x = q[1], y = q[2], z = q[3];
  const long double s = 2 / (w * w + x * x + y * y + z * z);
  return {{{1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y)},
           {s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x)},
           {s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y)}}};
}

// The rod cases with the whole configuration turned by a random rotation Q:
// the rod's orientation is Q, every world vector is Q times the original. The
// results must be Q times the closed form, to a few eps of the velocity scale
// (the inputs are rounded to T after rotation, so exactness is lost).
TYPED_TEST(LawCases, RotatedRodMatchesRotatedClosedForm) {
  using T = typename TypeParam::Type;
  Rng rng(20240611);
  for (int trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const auto q = rng.quaternion();
    const auto R = rotation_matrix(q);
    auto rot = [&](std::array<long double, 3> v) {
      V3<T> out{};
      for (int i = 0; i < 3; ++i) out[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
      return out;
    };
    auto cast = [](const V3<T>& v) { return std::array<T, 3>{T(v[0]), T(v[1]), T(v[2])}; };
    const bool particle = trial % 2 == 1;
    const long double e = particle ? 1 : 0.5L;
    const RodResult r = particle ? rod_closed_form(4, 2, 0, 0.25, 5, e) : rod_closed_form(4, 2, -2, 0, 0, e);
    Case<T> c;
    const std::array<T, 4> qt{T(q[0]), T(q[1]), T(q[2]), T(q[3])};
    c.bodies = {
        body<T>(4, {0.5, 4.0 / 3, 4.0 / 3}, {0, 0, 0}, cast(rot({0, particle ? 0.0L : -2.0L, 0})), {0, 0, 0}, qt),
        particle ? body<T>(4, {1, 1, 1}, cast(rot({1, -1, 0})), cast(rot({0, 5, 0})), {0, 0, 0})
                 : body<T>(kInf<T>, {1, 2, 3}, cast(rot({1, -3, 0})), {0, 0, 0}, {0, 0, 0})};
    c.inv_inertia = {{0, {2, 0.75, 0.75}}};
    c.contacts = {contact<T>(0, 1, cast(rot({1, 0, 0})), cast(rot({0, 1, 0})), T(e))};
    c.v = {rot({0, r.rod_v, 0}), rot({0, r.other_v, 0})};
    c.w = {rot({0, 0, r.rod_w}), {0, 0, 0}};
    c.j = {rot({0, r.jn, 0})};
    // Values are <= 8 in magnitude; 64 eps of that covers input rounding and
    // the kernel's own rounding with a wide margin.
    check_case<TypeParam>(c, 64 * 8 * static_cast<long double>(std::numeric_limits<T>::epsilon()), 5);
  }
}

// Coulomb friction, ball (m = 1, I = 1, lever arm -n) on a static wall, e = 0:
// vn = -2, jn = 2, then ut = (4, 0, 0), t = x, K(t) = 1 + 1 = 2 so sticking
// needs jt = 2. mu = 0.5: slides, jt = mu jn = 1, v = (3, 0, 0), w_z = -1.
// mu = 1 and mu = 2: sticks, jt = 2, v = (2, 0, 0), w_z = -2 (rolling: the
// contact point is at rest afterwards).
TYPED_TEST(LawCases, FrictionSlidesOrSticksOnWall) {
  using T = typename TypeParam::Type;
  struct Row {
    T mu;
    long double jt;
  };
  for (const Row row : {Row{T(0.5), 1}, Row{T(1), 2}, Row{T(2), 2}}) {
    SCOPED_TRACE("mu = " + std::to_string(static_cast<double>(row.mu)));
    Case<T> c;
    c.bodies = {body<T>(1, {1, 1, 1}, {0, 1, 0}, {4, -2, 0}, {0, 0, 0}),
                body<T>(kInf<T>, {1, 1, 1}, {0, -1, 0}, {0, 0, 0}, {0, 0, 0})};
    c.contacts = {contact<T>(0, 1, {0, 0, 0}, {0, 1, 0}, 0, row.mu)};
    c.v = {{4 - row.jt, 0, 0}, {}};
    c.w = {{0, 0, -row.jt}, {}};
    c.j = {{-row.jt, 2, 0}};
    check_case<TypeParam>(c);
  }
}

// A ball (m = 2) hits a moving, spinning immovable wall (kinematic: v = y,
// w = z/2, contact point 2 m from its centre so its point velocity is 2 y),
// e = 1/2: vn = -3 - 2 = -5, K = 1/2 (the wall adds nothing), jn = 15, the
// ball leaves at 4.5 = 2 + e * 5. The wall stores stale non-zero inverse
// moments: with them K would be 1/2 + 4 and the test would fail, so this also
// proves "immovable whatever its I". Its velocity has -0.0 components, which
// an update by "v + P * 0" would turn into +0.0: the wall must not be written
// at all.
TYPED_TEST(LawCases, KinematicImmovableBodyIsUntouchedAndItsInertiaIgnored) {
  using T = typename TypeParam::Type;
  for (const bool wall_is_a : {false, true}) {
    SCOPED_TRACE(wall_is_a ? "wall on side a" : "wall on side b");
    const BodyRecord<T> ball = body<T>(2, {1, 1, 1}, {0, 1, 0}, {0.5, -3, 0}, {0, 0, 0});
    const BodyRecord<T> wall =
        body<T>(kInf<T>, {1, 1, 1}, {-2, 0, 0}, {T(-0.0), 1, T(-0.0)}, {0, 0, 0.5}, {0.5, 0.5, 0.5, 0.5});
    Case<T> c;
    if (wall_is_a) {
      // The same collision seen from the wall: normal from the ball to it.
      c.bodies = {wall, ball};
      c.inv_inertia = {{0, {1, 1, 1}}};
      c.contacts = {contact<T>(0, 1, {0, 0, 0}, {0, -1, 0}, 0.5)};
      c.v = {{}, {0.5, 4.5, 0}};
      c.w = {{}, {0, 0, 0}};
      c.j = {{0, -15, 0}};
    } else {
      c.bodies = {ball, wall};
      c.inv_inertia = {{1, {1, 1, 1}}};
      c.contacts = {contact<T>(0, 1, {0, 0, 0}, {0, 1, 0}, 0.5)};
      c.v = {{0.5, 4.5, 0}, {}};
      c.w = {{0, 0, 0}, {}};
      c.j = {{0, 15, 0}};
    }
    check_case<TypeParam>(c);
  }
}

// Two immovable bodies approaching: K(n) = 0, J = 0, nothing is written.
TYPED_TEST(LawCases, TwoImmovableBodiesGiveZeroImpulse) {
  using T = typename TypeParam::Type;
  Case<T> c;
  c.bodies = {body<T>(kInf<T>, {1, 1, 1}, {0, 1, 0}, {0, -3, 0}, {1, 0, 0}),
              body<T>(kInf<T>, {1, 1, 1}, {0, -1, 0}, {0, 3, 0}, {0, 1, 0})};
  c.contacts = {contact<T>(0, 1, {0, 0, 0}, {0, 1, 0}, 1, 0.5)};
  c.v = {{}, {}};
  c.w = {{}, {}};
  c.j = {{0, 0, 0}};
  check_case<TypeParam>(c);
}

/// Runs a scene and checks that no body changed (bit for bit, -0.0 and all)
/// and every J is zero.
template <class P, class T = typename P::Type>
void expect_nothing_changes(const Scene<T>& before) {
  Scene<T> after = before;
  const ImpulseBuffer<T> j = run<P>(after.bodies, after.contacts.view());
  const auto x = body_arrays<T>(before.bodies.view());
  const auto y = body_arrays<T>(std::as_const(after.bodies).view());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < before.bodies.size(); ++i) {
    for (std::size_t f = 0; f < 17; ++f) changed += !identical(x[f][i], y[f][i]);
  }
  EXPECT_EQ(changed, 0u);
  const auto jv = j.view();
  std::size_t nonzero = 0;
  for (std::size_t k = 0; k < j.size(); ++k) nonzero += (jv.j.x[k] != 0) + (jv.j.y[k] != 0) + (jv.j.z[k] != 0);
  EXPECT_EQ(nonzero, 0u);
}

// Random pairs with every normal turned to separate (vn > 0), with friction:
// nothing changes.
TYPED_TEST(LawCases, SeparatingContactsChangeNothing) {
  using T = typename TypeParam::Type;
  SceneOptions o;
  o.seed = 7;
  o.friction = true;
  auto records = pairs_records<T>(203, o);
  for (auto& k : records.contacts) {
    for (T& x : k.n) x = -x;
    ASSERT_GT(approach_speed(records.bodies[k.a], records.bodies[k.b], k), 0);
  }
  expect_nothing_changes<TypeParam>(records.scene());
}

// Exactly resting contacts (vn == 0, and -0.0 in many velocities): n = +-y,
// equal y velocities, spins about y only (so w x r has no y part), and
// tangential velocities that would make friction act. Nothing changes, -0.0
// stays -0.0 (an update by "x + 0" would turn it into +0.0).
TYPED_TEST(LawCases, RestingContactsChangeNothingBitwise) {
  using T = typename TypeParam::Type;
  Rng rng(99);
  SceneRecords<T> s;
  auto signed_zero = [&] { return rng.chance(0.5) ? T(-0.0) : T(0.0); };
  for (int k = 0; k < 203; ++k) {
    const T vy = k % 5 == 0 ? signed_zero() : T(rng.uniform(-5, 5));
    for (int side = 0; side < 2; ++side) {
      BodyRecord<T> b = random_body<T>(rng, rng.in_box(5));
      b.v[1] = vy;
      if (k % 3 == 0) b.v[0] = signed_zero();
      b.w[0] = signed_zero();
      b.w[2] = signed_zero();
      if (k % 4 == 0) b.w[1] = signed_zero();
      s.bodies.push_back(b);
    }
    ContactRecord<T> c =
        random_contact<T>(rng, SceneOptions{1, true, -1, 5}, BodyIndex(2 * k), BodyIndex(2 * k + 1), rng.in_box(5));
    c.n[0] = 0, c.n[1] = rng.chance(0.5) ? T(1) : T(-1), c.n[2] = 0;
    ASSERT_EQ(approach_speed(s.bodies[2 * k], s.bodies[2 * k + 1], c), 0);
    s.contacts.push_back(c);
  }
  // Also a pair at rest with every velocity -0.0.
  BodyRecord<T> z;
  for (int i = 0; i < 3; ++i) z.v[i] = z.w[i] = T(-0.0);
  z.p[1] = 1;
  s.bodies.push_back(z);
  z.p[1] = -1;
  s.bodies.push_back(z);
  s.contacts.push_back(
      contact<T>(BodyIndex(s.bodies.size() - 2), BodyIndex(s.bodies.size() - 1), {0, 0, 0}, {0, 1, 0}, 1, 1));
  expect_nothing_changes<TypeParam>(s.scene());
}

TEST(Solver, RejectsNegativeThreadCount) {
  SolverOptions o;
  o.threads = -1;
  EXPECT_THROW(Solver{o}, std::invalid_argument);
}

// The stats describe what ran: the lane width of the path, the batch count of
// the schedule, the thread count asked for.
TEST(Solver, StatsDescribeTheRun) {
  Scene<float> s = shared_scene<float>(500, 200, SceneOptions{3});
  Schedule schedule;
  schedule.build(s.contacts.view(), s.bodies.view());
  ImpulseBuffer<float> j(s.contacts.size());
  for (const Path path : {Path::scalar, Path::simd}) {
    Scene<float> copy = s;
    const SolveStats st =
        Solver(options_for(path, 3)).solve(copy.bodies.view(), copy.contacts.view(), j.view(), schedule);
    EXPECT_EQ(st.contacts, 500u);
    EXPECT_EQ(st.batches, schedule.batch_count());
    // The ISA of a default solver's SIMD path is measured per kind of solve.
    EXPECT_EQ(st.lanes, path == Path::simd ? simd_width<float>(st.isa) : 1u);
    EXPECT_EQ(st.threads, 3);
    EXPECT_EQ(st.path, path);
    EXPECT_EQ(st.model, Model::rigid);
  }
  // The default SIMD width is that of default_isa().
  EXPECT_EQ(simd_width<float>(), simd_width<float>(default_isa()));
  EXPECT_EQ(simd_width<double>(), simd_width<double>(default_isa()));
  EXPECT_EQ(simd_width<float>(Isa::sse2), 4u);
  EXPECT_EQ(simd_width<double>(Isa::sse2), 2u);
  EXPECT_STREQ(to_string(Path::simd), "simd");
  EXPECT_STREQ(to_string(Path::scalar), "scalar");
  EXPECT_STREQ(to_string(Model::rigid), "rigid");
}

// The one-shot collide::solve equals a Solver run with the same options.
TEST(Solver, OneShotSolveEqualsSolver) {
  const Scene<double> s = shared_scene<double>(2000, 700, SceneOptions{5, true});
  Scene<double> x = s, y = s;
  ImpulseBuffer<double> jx(s.contacts.size());
  collide::solve(x.bodies.view(), x.contacts.view(), jx.view(), options_for(Path::simd, 2, 64));
  const ImpulseBuffer<double> jy = kernel_solve(y.bodies, y.contacts.view(), options_for(Path::simd, 2, 64));
  EXPECT_TRUE(same_bodies(x.bodies, y.bodies));
  EXPECT_TRUE(same_impulses(jx, jy));
}

}  // namespace
}  // namespace collide::test
