// test_conservation.cpp - the conservation laws of the collision law, on
// 100k random collisions, for the double kernel (SIMD path) and the long
// double reference.
//
// What this proves
// ----------------
// For 100k independent approaching pairs (random masses, anisotropic
// inertia, orientations, velocities, spins and contact geometry), each
// contact between two movable bodies:
// * conserves linear momentum  P = ma va + mb vb;
// * conserves angular momentum about the origin, orbital part included:
//       L = sum over the two bodies of (m p x v + R diag(I) R^T w);
// * conserves kinetic energy   E = 1/2 sum (m v.v + w . R diag(I) R^T w)
//   when e = 1 and mu = 0;
// * never increases E when e < 1 and/or mu > 0.
// with and without friction, e = 1 and e uniform in [0, 1]. All quantities
// are evaluated in long double from the kernel's results (m = 1/inv_mass and
// I = 1/inv_inertia of the stored inverses, R from q / |q|), so the check
// itself adds no error beyond 2^-64 relative.
//
// Tolerances. The kernel's outputs are rounded: each stored velocity is the
// result of a short sequence of IEEE operations (the impulse times an inverse
// mass or an angular response, added to the old value), each exact to eps/2
// relative to its operands. A conserved quantity Q computed from them is
// therefore off by at most a small multiple of eps times the sum of the
// magnitudes of the terms that went into it (its "scale" S, below), not
// times |Q| itself, which may be small by cancellation. The world-frame
// inverse inertia is formed from a q that is unit only to eps, and the
// kernel applies diag(1/I) between R^T and R, so an angular update can be off
// by eps times the anisotropy Imax/Imin of the body; that factor is in the
// angular scales. We allow |dQ| <= 16 eps S: a few roundings per term with
// margin; the observed worst cases are printed (they are below 2 eps S).
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <ostream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

using L = long double;
using V3 = std::array<L, 3>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 scale(const V3& a, L s) { return {a[0] * s, a[1] * s, a[2] * s}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
L dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
L norm(const V3& a) { return std::sqrt(dot(a, a)); }

/// One body in long double, from the stored (inverse) values.
struct Body {
  L m;
  V3 I;  // principal moments
  L R[3][3];
  V3 p, v, w;

  /// R diag(I) R^T x.
  [[nodiscard]] V3 inertia_times(const V3& x) const {
    V3 body{};
    for (int i = 0; i < 3; ++i) body[i] = (R[0][i] * x[0] + R[1][i] * x[1] + R[2][i] * x[2]) * I[i];
    V3 out{};
    for (int i = 0; i < 3; ++i) out[i] = R[i][0] * body[0] + R[i][1] * body[1] + R[i][2] * body[2];
    return out;
  }
  [[nodiscard]] L i_max() const { return std::max({I[0], I[1], I[2]}); }
  [[nodiscard]] L anisotropy() const { return i_max() / std::min({I[0], I[1], I[2]}); }
};

template <class T>
Body load(const BodyView<const T>& b, std::size_t i) {
  Body out;
  out.m = 1 / L(b.inv_mass[i]);
  out.I = {1 / L(b.inv_inertia.x[i]), 1 / L(b.inv_inertia.y[i]), 1 / L(b.inv_inertia.z[i])};
  const L qw = b.q.w[i], qx = b.q.x[i], qy = b.q.y[i], qz = b.q.z[i];
  const L s = 2 / (qw * qw + qx * qx + qy * qy + qz * qz);
  const L r[3][3] = {{1 - s * (qy * qy + qz * qz), s * (qx * qy - qw * qz), s * (qx * qz + qw * qy)},
                     {s * (qx * qy + qw * qz), 1 - s * (qx * qx + qz * qz), s * (qy * qz - qw * qx)},
                     {s * (qx * qz - qw * qy), s * (qy * qz + qw * qx), 1 - s * (qx * qx + qy * qy)}};
  for (int x = 0; x < 3; ++x) {
    for (int y = 0; y < 3; ++y) out.R[x][y] = r[x][y];
  }
  out.p = {L(b.p.x[i]), L(b.p.y[i]), L(b.p.z[i])};
  out.v = {L(b.v.x[i]), L(b.v.y[i]), L(b.v.z[i])};
  out.w = {L(b.w.x[i]), L(b.w.y[i]), L(b.w.z[i])};
  return out;
}

V3 momentum(const Body& b) { return scale(b.v, b.m); }
V3 angular_momentum(const Body& b) { return add(cross(b.p, scale(b.v, b.m)), b.inertia_times(b.w)); }
L energy(const Body& b) { return (b.m * dot(b.v, b.v) + dot(b.w, b.inertia_times(b.w))) / 2; }

/// Worst observed |dQ| / (eps S) for each law, and whether anything happened.
struct Worst {
  L momentum = 0, angular = 0, energy = 0, energy_gain = 0;
  L energy_lost = 0, energy_moved = 0;  // sums, for the sanity checks
};

/// Checks every pair k (bodies 2k, 2k+1, contact k) of a solved pairs scene.
template <class T>
Worst check_pairs(const BodyView<const T>& before, const BodyView<const T>& after, const ImpulseView<const T>& j, L eps,
                  bool elastic_frictionless, const std::string& label) {
  constexpr L kC = 16;
  Worst worst;
  std::size_t failures = 0;
  for (std::size_t k = 0; k < j.count; ++k) {
    const Body a0 = load(before, 2 * k), b0 = load(before, 2 * k + 1);
    const Body a1 = load(after, 2 * k), b1 = load(after, 2 * k + 1);
    const L jmag = norm({L(j.j.x[k]), L(j.j.y[k]), L(j.j.z[k])});

    // Linear momentum: each body's m v rounds to eps m |v'|, and m (P / m)
    // to eps |J|.
    const V3 dp = sub(add(momentum(a1), momentum(b1)), add(momentum(a0), momentum(b0)));
    const L sp = a0.m * (norm(a0.v) + norm(a1.v)) + b0.m * (norm(b0.v) + norm(b1.v)) + 2 * jmag;

    // Angular momentum: the orbital terms as above times |p|; the spin terms
    // round to eps Imax |w'|, and the angular response to eps * anisotropy *
    // |r x J| (|r| <= |c| + |p|, c from the contact).
    const V3 dl = sub(add(angular_momentum(a1), angular_momentum(b1)), add(angular_momentum(a0), angular_momentum(b0)));
    auto spin_scale = [&](const Body& x0, const Body& x1) {
      return x0.m * norm(x0.p) * (norm(x0.v) + norm(x1.v)) + x0.i_max() * (norm(x0.w) + norm(x1.w)) +
             (x0.anisotropy() + 1) * 2 * (norm(x0.p) + 10) * jmag;
    };
    const L sl = spin_scale(a0, a1) + spin_scale(b0, b1);

    // Energy: m v.v and w.Iw w round to eps times themselves; a velocity
    // update off by eps |dv| (eps * anisotropy * |dw|) moves E by that times
    // m |v| (Imax |w|).
    const L e0 = energy(a0) + energy(b0), e1 = energy(a1) + energy(b1);
    auto energy_scale = [&](const Body& x0, const Body& x1) {
      return x0.m * (dot(x0.v, x0.v) + dot(x1.v, x1.v)) + x0.i_max() * (dot(x0.w, x0.w) + dot(x1.w, x1.w)) +
             x0.m * (norm(x0.v) + norm(x1.v)) * norm(sub(x1.v, x0.v)) +
             x0.anisotropy() * x0.i_max() * (norm(x0.w) + norm(x1.w)) * norm(sub(x1.w, x0.w));
    };
    const L se = energy_scale(a0, a1) + energy_scale(b0, b1);

    const L rp = norm(dp) / (eps * sp), rl = norm(dl) / (eps * sl), re = std::fabs(e1 - e0) / (eps * se);
    worst.momentum = std::max(worst.momentum, rp);
    worst.angular = std::max(worst.angular, rl);
    worst.energy = std::max(worst.energy, re);
    worst.energy_gain = std::max(worst.energy_gain, (e1 - e0) / (eps * se));
    worst.energy_lost += e0 - e1;
    worst.energy_moved += std::fabs(energy(a1) - energy(a0));

    bool ok = rp <= kC && rl <= kC;
    ok = ok && (elastic_frictionless ? re <= kC : (e1 - e0) <= kC * eps * se);
    if (!ok && failures++ < 5) {
      ADD_FAILURE() << label << ": pair " << k << " dP/(eps S) = " << static_cast<double>(rp)
                    << ", dL/(eps S) = " << static_cast<double>(rl) << ", dE = " << static_cast<double>(e1 - e0) << " ("
                    << static_cast<double>(re) << " eps S), E0 = " << static_cast<double>(e0);
    }
  }
  EXPECT_EQ(failures, 0u) << label;
  std::cout << "[conservation] " << label << ": worst |dP| " << static_cast<double>(worst.momentum) << ", |dL| "
            << static_cast<double>(worst.angular);
  if (elastic_frictionless) {
    std::cout << ", |dE| " << static_cast<double>(worst.energy);
  } else {
    std::cout << ", largest gain dE " << static_cast<double>(worst.energy_gain);
  }
  std::cout << " (units of eps*scale; tolerance 16)" << std::endl;
  return worst;
}

struct Case {
  const char* name;
  double e;  // < 0: uniform in [0, 1]
  bool friction;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class Conservation : public ::testing::TestWithParam<Case> {};

TEST_P(Conservation, KernelDoubleSimd) {
  const Case c = GetParam();
  SceneOptions o;
  o.seed = 555;
  o.e = c.e;
  o.friction = c.friction;
  const Scene<double> scene = pairs_scene<double>(100000, o);
  BodyBuffer<double> after = scene.bodies;
  const ImpulseBuffer<double> j = kernel_solve(after, scene.contacts.view(), options_for(Path::simd, 2));
  const bool elastic = c.e == 1 && !c.friction;
  const Worst w =
      check_pairs<double>(scene.bodies.view(), std::as_const(after).view(), j.view(),
                          std::numeric_limits<double>::epsilon(), elastic, std::string("double simd ") + c.name);
  // Non-trivial: bodies exchange a lot of energy; with e < 1 or friction
  // energy is really lost (by far more than rounding).
  EXPECT_GT(w.energy_moved, 1e4L);
  if (!elastic) {
    EXPECT_GT(w.energy_lost, 1e3L);
  }
}

TEST_P(Conservation, ReferenceLongDouble) {
  const Case c = GetParam();
  SceneOptions o;
  o.seed = 556;
  o.e = c.e;
  o.friction = c.friction;
  // Built in long double, so that every normal is unit to long double
  // precision: the law's K(n) = 1/ma + 1/mb + ... takes |n| = 1, and a
  // double-normalised normal widened exactly (convert_scene) is unit only to
  // ~1e-16, which would cap the reference's energy conservation at double
  // accuracy (|dE|/E ~ 1e-16, hundreds of long double eps).
  const Scene<long double> scene = pairs_scene<long double>(100000, o);
  BodyBuffer<long double> after = scene.bodies;
  const ImpulseBuffer<long double> j = reference(after, scene.contacts.view());
  const bool elastic = c.e == 1 && !c.friction;
  const Worst w = check_pairs<long double>(scene.bodies.view(), std::as_const(after).view(), j.view(),
                                           std::numeric_limits<long double>::epsilon(), elastic,
                                           std::string("long double reference ") + c.name);
  EXPECT_GT(w.energy_moved, 1e4L);
  if (!elastic) {
    EXPECT_GT(w.energy_lost, 1e3L);
  }
}

INSTANTIATE_TEST_SUITE_P(Pairs, Conservation,
                         ::testing::Values(Case{"elastic_frictionless", 1, false},
                                           Case{"random_e_frictionless", -1, false}, Case{"elastic_friction", 1, true},
                                           Case{"random_e_friction", -1, true}),
                         [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace collide::test
