// test_hard_pairs.cpp - the single-contact hard-case families.
//
// What this proves
// ----------------
// For each family of collide/eval/hard_scenes.hpp - extreme mass ratios, immovable
// bodies, needle-thin inertia struck at the tip, long lever arms, grazing
// approach, extreme unit scales, subnormal speeds, exactly separating and
// exactly resting contacts, e = 0 and e = 1, friction at the stick/slip
// boundary, spin-dominated contacts - 1000 random collisions from a fixed
// seed, in float and double, for every body model the family applies to
// (Model::particle, Model::sphere, Model::rigid scenes, each run through every
// model that fits it):
// * the kernel's impulses satisfy the documented bound against the long
//   double reference with the reference's conditioning (impulse_scale), on
//   every contact (run_scene in hard_check.hpp), and no NaN or inf appears;
// * the scalar and SIMD paths agree bit for bit;
// * what the family is about actually happens: the promised extreme is in
//   the scene, most contacts act, and the family's own law holds (immovable
//   bodies and non-approaching contacts untouched bit for bit, J = 0 between
//   two immovable bodies, e = 0 stops the normal motion, e = 1 keeps the
//   energy, no contact creates momentum or energy).
// The "[hard]" lines printed are the figures of
// docs/decisions/0008-the-impulse-scale.md.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hard/hard_check.hpp"

namespace collide::hard {
namespace {

constexpr std::size_t kCount = 1000;

/// The fits a family applies to. Rotation-free families also run for
/// particles; needles are rigid by definition; spin and levers need rotation.
const std::vector<Model> kAllFits = {Model::particle, Model::sphere, Model::rigid};
const std::vector<Model> kRotatingFits = {Model::sphere, Model::rigid};

/// Runs `run(T{}, fit)` for T = float and double and every fit in `fits`.
template <class Run>
void each(const std::vector<Model>& fits, const Run& run) {
  for (const Model fit : fits) {
    run(float{}, fit);
    run(double{}, fit);
  }
}

/// Momentum and energy of every pair of movable bodies (pairs scenes).
template <class T>
void expect_pairs_conserved(const Scene<T>& in, const Outcome<T>& out, const Reference& ref, bool elastic = false) {
  const ContactView<T> c = in.contacts.view();
  const BodyView<const T> b = in.bodies.view();
  for (std::size_t k = 0; k < c.count; ++k) {
    if (b.inv_mass[c.a[k]] == T(0) || b.inv_mass[c.b[k]] == T(0)) continue;
    SCOPED_TRACE("pair " + std::to_string(k));
    expect_conserved(in, out, ref, {c.a[k], c.b[k]}, {k}, elastic);
  }
}

template <class T>
void conserved(const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
  expect_pairs_conserved(in, out, ref);
}

/// Max over pairs of the larger mass over the smaller.
template <class T>
double widest_mass_ratio(const Scene<T>& s) {
  const BodyView<const T> b = s.bodies.view();
  double widest = 1;
  for (std::size_t i = 0; i + 1 < b.count; i += 2) {
    const double r = double(b.inv_mass[i]) / double(b.inv_mass[i + 1]);
    widest = std::max({widest, r, 1 / r});
  }
  return widest;
}

TEST(HardPairs, MassRatiosUpTo1e8) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = mass_ratio_family<T>(kCount, fit, 11).scene();
    EXPECT_GE(widest_mass_ratio(s), 0.999e8);
    run_scene<T>("mass-ratio", s, fit, kCount * 9 / 10, conserved<T>);
  };
  each(kAllFits, run);
}

/// Immovable bodies: never written; J = 0 when both are immovable; an
/// impulse and no NaN when one is (no 0 * inf anywhere).
template <class T>
void expect_immovable_law(const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
  const ContactView<T> c = in.contacts.view();
  const BodyView<const T> b = in.bodies.view();
  const auto j = out.j.view();
  for (std::size_t k = 0; k < c.count; ++k) {
    const bool fixed_a = b.inv_mass[c.a[k]] == T(0), fixed_b = b.inv_mass[c.b[k]] == T(0);
    // The family's layout: kind k % 3 (a, b, both), sides swapped for odd k.
    const Immovable kind = immovable_kind(k);
    ASSERT_EQ(fixed_a || fixed_b, true);
    ASSERT_EQ(fixed_a && fixed_b, kind == Immovable::both);
    const bool zero = j.j.x[k] == T(0) && j.j.y[k] == T(0) && j.j.z[k] == T(0);
    if (fixed_a && fixed_b) {
      EXPECT_TRUE(zero) << "contact " << k << " between two immovable bodies has an impulse";
    } else {
      EXPECT_EQ(zero, !(ref.diag[k].jn > 0)) << "contact " << k;
    }
  }
  EXPECT_TRUE(test::same_bodies(in.bodies, out.bodies, [&](std::size_t i) { return b.inv_mass[i] != T(0); }))
      << "an immovable body was written";
}

TEST(HardPairs, ImmovableOnEitherSideAndBoth) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = immovable_family<T>(kCount, fit, 12).scene();
    run_scene<T>("immovable", s, fit, kCount / 2, expect_immovable_law<T>);
    // The same scene with stale, finite inverse moments left in the
    // immovable bodies' arrays (what a caller's own arrays may hold): the
    // law says m = inf is immovable whatever its I, so nothing changes.
    BodyBuffer<T> stale = s.bodies;
    const BodyView<T> v = stale.view();
    SceneRng rng(99);
    std::size_t poisoned = 0;
    for (std::size_t i = 0; i < v.count; ++i) {
      if (v.inv_mass[i] != T(0)) continue;
      const T inv = static_cast<T>(rng.log_uniform(1e-3, 1e3));
      v.inv_inertia.x[i] = inv;
      v.inv_inertia.y[i] = fit == Model::rigid ? static_cast<T>(rng.log_uniform(1e-3, 1e3)) : inv;
      v.inv_inertia.z[i] = inv;
      ++poisoned;
    }
    ASSERT_GT(poisoned, kCount / 2);
    const Scene<T> poisoned_scene{stale, s.contacts};
    run_scene<T>("immovable-stale-I", poisoned_scene, stale, fit, kCount / 2, expect_immovable_law<T>);
  };
  each(kAllFits, run);
}

TEST(HardPairs, NeedleThinInertiaStruckAtTheTip) {
  auto run = [](auto zero) {
    using T = decltype(zero);
    const Scene<T> s = needle_family<T>(kCount, 13).scene();
    // The thinnest needle reached: smallest inverse-moment ratio over movable bodies.
    const BodyView<const T> b = s.bodies.view();
    double thinnest = 1;
    for (std::size_t i = 0; i < b.count; ++i) {
      if (b.inv_mass[i] == T(0)) continue;
      const double lo = std::min({double(b.inv_inertia.x[i]), double(b.inv_inertia.y[i]), double(b.inv_inertia.z[i])});
      const double hi = std::max({double(b.inv_inertia.x[i]), double(b.inv_inertia.y[i]), double(b.inv_inertia.z[i])});
      thinnest = std::min(thinnest, lo / hi);
    }
    EXPECT_LE(thinnest, 1.0001e-12);
    run_scene<T>("needle", s, Model::rigid, kCount * 9 / 10, conserved<T>);
  };
  run(float{});
  run(double{});
}

TEST(HardPairs, LongLeversUpTo1e4RadiiOfGyration) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const SceneRecords<T> r = long_lever_family<T>(kCount, fit, 14);
    double longest = 0;
    for (std::size_t k = 0; k < r.contacts.size(); ++k) {
      // Side a of the family is body 2k for even k, 2k+1 for odd k.
      const BodyRecord<T>& a = r.bodies[k % 2 == 0 ? 2 * k : 2 * k + 1];
      double r2 = 0;
      for (int i = 0; i < 3; ++i) r2 += (double(r.contacts[k].c[i]) - a.p[i]) * (double(r.contacts[k].c[i]) - a.p[i]);
      const double rho = std::sqrt(std::max({double(a.I[0]), double(a.I[1]), double(a.I[2])}) / double(a.m));
      longest = std::max(longest, std::sqrt(r2) / rho);
    }
    EXPECT_GE(longest, 0.999e4);
    run_scene<T>("long-lever", r.scene(), fit, kCount * 9 / 10, conserved<T>);
  };
  each(kRotatingFits, run);
}

TEST(HardPairs, GrazingApproachDownTo1e7) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const SceneRecords<T> r = grazing_family<T>(kCount, fit, 15);
    // vn / |u| from the stored values: the family reaches 1e-7 (up to the
    // rounding of v_a to T) and keeps many contacts far below 1e-5.
    L flattest = 1;
    std::size_t below_1e5 = 0;
    for (const ContactRecord<T>& c : r.contacts) {
      const auto u = relative_velocity(r.bodies[c.a], r.bodies[c.b], c);
      const L vn = u[0] * L(c.n[0]) + u[1] * L(c.n[1]) + u[2] * L(c.n[2]);
      const L ratio = std::abs(vn) / std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      flattest = std::min(flattest, ratio);
      below_1e5 += ratio < L(1e-5);
    }
    EXPECT_LE(flattest, L(2e-7));
    EXPECT_GE(below_1e5, kCount / 4);
    run_scene<T>("grazing", r.scene(), fit, kCount * 3 / 4, conserved<T>);
  };
  each(kAllFits, run);
}

TEST(HardPairs, UnitScalesFrom1e5To1e5) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = unit_scale_family<T>(kCount, fit, 16).scene();
    const BodyView<const T> b = s.bodies.view();
    double lightest = std::numeric_limits<double>::infinity(), heaviest = 0;
    for (std::size_t i = 0; i < b.count; ++i) {
      lightest = std::min(lightest, 1 / double(b.inv_mass[i]));
      heaviest = std::max(heaviest, 1 / double(b.inv_mass[i]));
    }
    EXPECT_GE(heaviest / lightest, 1e10);
    run_scene<T>("unit-scales", s, fit, kCount * 9 / 10, conserved<T>);
  };
  each(kAllFits, run);
}

TEST(HardPairs, SubnormalSpeedsInFloat) {
  for (const Model fit : kAllFits) {
    const Scene<float> s = subnormal_family<float>(kCount, fit, 17).scene();
    run_scene<float>("subnormal", s, fit, kCount * 9 / 10,
                     [](const Scene<float>&, const Outcome<float>& out, const Reference&) {
                       // Subnormal results survive: no flush-to-zero anywhere.
                       const auto j = out.j.view();
                       std::size_t subnormal = 0, nonzero = 0;
                       for (std::size_t k = 0; k < j.count; ++k) {
                         for (const float x : {j.j.x[k], j.j.y[k], j.j.z[k]}) {
                           subnormal += std::fpclassify(x) == FP_SUBNORMAL;
                         }
                         nonzero += j.j.x[k] != 0 || j.j.y[k] != 0 || j.j.z[k] != 0;
                       }
                       EXPECT_GE(subnormal, kCount / 2);
                       EXPECT_GE(nonzero, kCount * 9 / 10);
                     });
  }
}

/// Non-approaching contacts: J = 0 and every body bit for bit as it was.
template <class T>
void expect_untouched(const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
  const auto j = out.j.view();
  std::size_t resting = 0;
  for (std::size_t k = 0; k < j.count; ++k) {
    EXPECT_TRUE(j.j.x[k] == T(0) && j.j.y[k] == T(0) && j.j.z[k] == T(0)) << "contact " << k;
    // Even k separate clearly, odd k rest exactly (in the reference, too).
    if (k % 2 == 0) {
      EXPECT_GT(ref.diag[k].vn, 0) << "contact " << k;
    } else {
      EXPECT_EQ(ref.diag[k].vn, 0) << "contact " << k;
      resting += ref.diag[k].vn == 0;
    }
  }
  EXPECT_EQ(resting, j.count / 2);
  EXPECT_TRUE(test::same_bodies(in.bodies, out.bodies));
}

TEST(HardPairs, ExactlySeparatingAndExactlyRestingLeftBitwiseUnchanged) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = separating_resting_family<T>(kCount, fit, 18).scene();
    run_scene<T>("separating-resting", s, fit, 0, expect_untouched<T>);
  };
  each(kAllFits, run);
}

/// e = 0 without friction leaves no normal relative velocity (up to the
/// bound's rounding); e = 1 without friction keeps the energy.
template <class T>
void expect_restitution_law(const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
  const L eps = std::numeric_limits<T>::epsilon();
  const ContactView<T> c = in.contacts.view();
  const BodyView<const T> b1 = out.bodies.view();
  const BodyView<const T> b0 = in.bodies.view();
  for (std::size_t k = 0; k < c.count; ++k) {
    const bool friction = c.mu != nullptr && c.mu[k] > T(0);
    if (friction) continue;
    SCOPED_TRACE("contact " + std::to_string(k));
    if (c.e[k] == T(0)) {
      BodyRecord<T> a = out.bodies.record(c.a[k]), b = out.bodies.record(c.b[k]);
      const auto u = relative_velocity(a, b, in.contacts.record(k));
      const L vn = u[0] * L(c.n.x[k]) + u[1] * L(c.n.y[k]) + u[2] * L(c.n.z[k]);
      const L speeds = speed_share(b0, c.a[k], c, k) + speed_share(b0, c.b[k], c, k) + speed_share(b1, c.a[k], c, k) +
                       speed_share(b1, c.b[k], c, k);
      EXPECT_LE(std::abs(vn), (test::kErrorBoundEps + 16) * eps * speeds);
    } else {
      expect_conserved(in, out, ref, {c.a[k], c.b[k]}, {k}, true);
    }
  }
  expect_pairs_conserved(in, out, ref);
}

TEST(HardPairs, RestitutionZeroAndOne) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = restitution_family<T>(kCount, fit, 19).scene();
    run_scene<T>("e-0-and-1", s, fit, kCount * 9 / 10, expect_restitution_law<T>);
  };
  each(kAllFits, run);
}

TEST(HardPairs, FrictionAtTheStickSlipBoundary) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = stick_slip_family<T>(kCount, fit, 20).scene();
    run_scene<T>("stick-slip", s, fit, kCount * 9 / 10,
                 [](const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
                   // Both sides of the boundary are populated in the reference.
                   const ContactView<T> c = in.contacts.view();
                   std::size_t slip = 0, stick = 0;
                   for (std::size_t k = 0; k < c.count; ++k) {
                     if (!(ref.diag[k].jt > 0)) continue;
                     const bool slipping = ref.diag[k].jt == L(c.mu[k]) * ref.diag[k].jn;
                     slip += slipping;
                     stick += !slipping;
                   }
                   EXPECT_GE(slip, c.count / 5);
                   EXPECT_GE(stick, c.count / 5);
                   expect_pairs_conserved(in, out, ref);
                 });
  };
  each(kAllFits, run);
}

TEST(HardPairs, SpinDominated) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = spin_family<T>(kCount, fit, 21).scene();
    // |v| / (|w| |r|) reaches 1e-5 or less.
    const BodyView<const T> b = s.bodies.view();
    const ContactView<T> c = s.contacts.view();
    L least = 1;
    for (std::size_t k = 0; k < c.count; ++k) {
      for (const BodyIndex i : {c.a[k], c.b[k]}) {
        const L spin = speed_share(b, i, c, k);
        const L v = std::sqrt(L(b.v.x[i]) * b.v.x[i] + L(b.v.y[i]) * b.v.y[i] + L(b.v.z[i]) * b.v.z[i]);
        least = std::min(least, v / (spin - v));
      }
    }
    EXPECT_LE(least, L(1e-5));
    run_scene<T>("spin-dominated", s, fit, kCount * 9 / 10, conserved<T>);
  };
  each(kRotatingFits, run);
}

TEST(HardPairs, CallersValuesOffUnit) {
  // The fast mode on the caller's values: normals unit only within the
  // input tolerance and quaternions of any length (off_unit_directions).
  // The law normalises both; the fast mode does so in T inside the kernel
  // (q in the rotation, n through |n|^2 in the normal impulse and in the
  // tangent's projection), within the same target as on unit inputs.
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    run_scene<T>("grazing-off-unit", off_unit_directions(grazing_family<T>(kCount, fit, 15), 41).scene(), fit,
                 kCount * 3 / 4, conserved<T>);
    run_scene<T>("mass-ratio-off-unit", off_unit_directions(mass_ratio_family<T>(kCount, fit, 11), 42).scene(), fit,
                 kCount * 9 / 10, conserved<T>);
    run_scene<T>("unit-scales-off-unit", off_unit_directions(unit_scale_family<T>(kCount, fit, 16), 43).scene(), fit,
                 kCount * 9 / 10, conserved<T>);
    run_scene<T>("stick-slip-off-unit", off_unit_directions(stick_slip_family<T>(kCount, fit, 20), 44).scene(), fit,
                 kCount * 9 / 10, conserved<T>);
    if (fit != Model::particle) {
      run_scene<T>("long-lever-off-unit", off_unit_directions(long_lever_family<T>(kCount, fit, 14), 45).scene(), fit,
                   kCount * 9 / 10, conserved<T>);
      run_scene<T>("spin-off-unit", off_unit_directions(spin_family<T>(kCount, fit, 21), 47).scene(), fit,
                   kCount * 9 / 10, conserved<T>);
    }
    if (fit == Model::rigid) {
      run_scene<T>("needle-off-unit", off_unit_directions(needle_family<T>(kCount, 13), 46).scene(), fit,
                   kCount * 9 / 10, conserved<T>);
    }
  };
  each(kAllFits, run);
}

}  // namespace
}  // namespace collide::hard
