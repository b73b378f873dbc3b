// test_hard_shared.cpp - hard cases where contacts share bodies.
//
// What this proves
// ----------------
// * Newton's cradles of 2 to 20 spheres (axis-aligned, where the particle
//   model fits by geometry, and along a random axis), in float and double:
//   every model that fits gives the long double reference's impulses within
//   the bound, the reference being the law applied in input order, which is
//   the kernel's schedule order; the chain of a cradle is one batch per
//   contact; with equal masses and e = 1 the last sphere leaves with the
//   first one's velocity and the others stop; listed last to first, only
//   the first two spheres exchange velocity (the order is the input's, not
//   the geometry's); momentum is conserved and, for e = 1, energy too. Every
//   cradle is within kImpulseErrorTargetEps: along a random axis every link
//   has the same stored normal, unit only to a few eps, and a kernel that
//   took it as unit would scale each link's impulse by |n|^2 and pass the
//   factor down the chain; fast_normal_impulse folds |n|^2 into K
//   (docs/decisions/0010-the-fast-modes-normal-impulse.md).
// * A star (one body in 1000 contacts, movable or immovable): the bound on
//   every contact along the 1000-long chain, conservation, 1000 batches for
//   a movable hub and one for an immovable one.
// * A dense cluster (80 bodies, ~1000 contacts, each body in ~25): the
//   bound, momentum conserved and energy not increased.
// * Determinism on all three: identical bytes for 1, 2 and 8 threads (small
//   blocks, so batches really split) and for the scalar path.
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include "hard/hard_check.hpp"

namespace collide::hard {
namespace {

std::vector<std::size_t> iota(std::size_t n) {
  std::vector<std::size_t> v(n);
  std::iota(v.begin(), v.end(), std::size_t{0});
  return v;
}

/// Momentum and energy over the whole scene (no immovable body in it).
template <class T>
void expect_scene_conserved(const Scene<T>& in, const Outcome<T>& out, const Reference& ref, bool elastic) {
  expect_conserved(in, out, ref, iota(in.bodies.size()), iota(in.contacts.size()), elastic);
}

template <class T>
std::size_t batches(const Scene<T>& s) {
  Schedule schedule;
  schedule.build(s.contacts.view(), s.bodies.size(), s.bodies.view().inv_mass);
  return schedule.batch_count();
}

/// Identical bytes for threads 1, 2 and 8 (blocks of 8 contacts, so a batch
/// of more than 16 contacts runs on several threads) and the scalar path.
class HardShared : public ::testing::Test {
 protected:
  // Let 8-thread arenas really have 8 threads on a small machine.
  tbb::global_control workers_{tbb::global_control::max_allowed_parallelism, 8};

  template <class T>
  static void expect_deterministic(const Scene<T>& s, Model model) {
    const Outcome<T> base = kernel_result(s, s.bodies, model, test::options_for(Path::simd, 1));
    for (const int threads : {2, 8}) {
      SCOPED_TRACE("threads " + std::to_string(threads));
      const Outcome<T> other = kernel_result(s, s.bodies, model, test::options_for(Path::simd, threads, 8));
      EXPECT_TRUE(test::same_bodies(base.bodies, other.bodies));
      EXPECT_TRUE(test::same_impulses(base.j, other.j));
    }
    const Outcome<T> scalar = kernel_result(s, s.bodies, model, test::options_for(Path::scalar, 8, 8));
    EXPECT_TRUE(test::same_bodies(base.bodies, scalar.bodies));
    EXPECT_TRUE(test::same_impulses(base.j, scalar.j));
  }
};

constexpr std::size_t kLongest = 20;

/// Cradles of 2 .. 20 spheres hold (20 * 21 / 2 - 1) bodies and 19 * 20 / 2 contacts.
constexpr std::size_t kCradleContacts = (kLongest - 1) * kLongest / 2;

/// Equal masses, e = 1: after the chain, sphere n-1 of each cradle moves at
/// the first one's initial velocity and every other sphere is at rest - or,
/// listed last to first, only sphere 1 moves. Each contact's rounding
/// passes down the chain, hence the tolerance of C eps v0 per contact.
template <class T>
void expect_cradle_motion(const Scene<T>& in, const Outcome<T>& out, bool reversed) {
  const BodyView<const T> b0 = in.bodies.view();
  const BodyView<const T> b1 = out.bodies.view();
  const L eps = std::numeric_limits<T>::epsilon();
  std::size_t first = 0;
  for (std::size_t n = 2; n <= kLongest; ++n) {
    const L v0[3] = {b0.v.x[first], b0.v.y[first], b0.v.z[first]};
    const L speed = std::sqrt(v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]);
    const std::size_t mover = first + (reversed ? 1 : n - 1);
    for (std::size_t i = first; i < first + n; ++i) {
      const L v1[3] = {b1.v.x[i], b1.v.y[i], b1.v.z[i]};
      L d = 0;
      for (int x = 0; x < 3; ++x) {
        const L expected = i == mover ? v0[x] : L(0);
        d += (v1[x] - expected) * (v1[x] - expected);
      }
      EXPECT_LE(std::sqrt(d), test::kErrorBoundEps * L(n) * eps * speed)
          << "cradle of " << n << ", sphere " << i - first;
    }
    first += n;
  }
}

TEST_F(HardShared, NewtonsCradleInInputOrder) {
  auto run = [](auto zero) {
    using T = decltype(zero);
    const V3 x_axis{1, 0, 0};
    SceneRng rng(31);
    const V3 random_axis = rng.unit_vector();
    for (const bool aligned : {true, false}) {
      const V3& axis = aligned ? x_axis : random_axis;
      const Model fit = aligned ? Model::particle : Model::sphere;
      for (const bool reversed : {false, true}) {
        SCOPED_TRACE(std::string(aligned ? "aligned" : "random axis") + (reversed ? " reversed" : ""));
        // Equal masses, elastic: the textbook motion.
        const Scene<T> classic = cradle_scene<T>(kLongest, axis, true, true, reversed, 32).scene();
        ASSERT_EQ(classic.contacts.size(), kCradleContacts);
        EXPECT_EQ(batches(classic), kLongest - 1);
        run_scene<T>("cradle", classic, fit, reversed ? kLongest - 1 : kCradleContacts,
                     [reversed](const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
                       expect_cradle_motion(in, out, reversed);
                       expect_scene_conserved(in, out, ref, true);
                     });
        expect_deterministic(classic, fit);
        // Mixed masses and restitution: whatever the motion, the bound and
        // the conservation laws.
        const Scene<T> mixed = cradle_scene<T>(kLongest, axis, false, false, reversed, 33).scene();
        run_scene<T>("cradle-mixed", mixed, fit, kLongest - 1,
                     [](const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
                       expect_scene_conserved(in, out, ref, false);
                     });
      }
    }
  };
  run(float{});
  run(double{});
}

TEST_F(HardShared, StarOneBodyInAThousandContacts) {
  auto run = [](auto zero, Model fit, bool fixed_hub) {
    using T = decltype(zero);
    SCOPED_TRACE(fixed_hub ? "immovable hub" : "movable hub");
    const Scene<T> s = star_scene<T>(1000, fixed_hub, fit, 34).scene();
    EXPECT_EQ(batches(s), fixed_hub ? 1u : 1000u);
    run_scene<T>(fixed_hub ? "star-fixed-hub" : "star", s, fit, 500,
                 [fixed_hub](const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
                   if (!fixed_hub) expect_scene_conserved(in, out, ref, false);
                   // Every satellite's single contact leaves the others alone;
                   // an immovable hub is never written.
                   if (fixed_hub) {
                     EXPECT_TRUE(test::same_bodies(in.bodies, out.bodies, [](std::size_t i) { return i != 0; }));
                   }
                 });
    expect_deterministic(s, fit);
  };
  for (const Model fit : {Model::particle, Model::sphere, Model::rigid}) {
    for (const bool fixed_hub : {false, true}) {
      run(float{}, fit, fixed_hub);
      run(double{}, fit, fixed_hub);
    }
  }
}

TEST_F(HardShared, DenseCluster) {
  auto run = [](auto zero, Model fit) {
    using T = decltype(zero);
    const Scene<T> s = cluster_scene<T>(80, 1.0, fit, 35).scene();
    ASSERT_GE(s.contacts.size(), 800u);
    EXPECT_GE(batches(s), 20u);
    run_scene<T>("cluster", s, fit, s.contacts.size() / 4,
                 [](const Scene<T>& in, const Outcome<T>& out, const Reference& ref) {
                   expect_scene_conserved(in, out, ref, false);
                 });
    expect_deterministic(s, fit);
  };
  for (const Model fit : {Model::particle, Model::sphere, Model::rigid}) {
    run(float{}, fit);
    run(double{}, fit);
  }
}

}  // namespace
}  // namespace collide::hard
