// test_warm_start.cpp - the warm start of the accumulated passes
// (SolverOptions::warm_start; contact_kernel.hpp, warm_start_step).
//
// What this proves
// ----------------
// * A warm start gives the same bits on every path, ISA, layout and thread
//   count, in both orders, with and without friction, at 1 and 3 passes.
// * Started from the converged J of the frame before, a column of 20 boxes
//   on the ground (each box falling at g dt after one step of gravity, as in
//   the frame before) is within 1e-6 of its support impulses after one
//   pass, where a cold pass is off by far more; the residual says so.
// * A pass takes back what the warm start gave too much: two boxes that
//   part, started from a J that pushes them harder, end with J = 0 and the
//   velocities they came with.
// * Restitution acts once from a warm start too: an impact with e = 0.5
//   parts at -e times its approach speed, started from zero or from its
//   own answer.
// * Bad warm starts are refused before anything is written, naming the
//   first contact by index (whatever the thread count): a NaN, a J that
//   points against its normal; and the repeat mode refuses a warm start. A
//   J a little against its normal (a normal turned since the frame before)
//   is taken, its normal part as 0.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "support/generated_scenes.hpp"
#include "support/solve_helpers.hpp"
#include "support/unit_boxes.hpp"

namespace collide::test {
namespace {

/// A solve of a copy of `scene`'s bodies with `options` on a schedule in
/// `order`, from the J in `warm` (a warm start when options.warm_start).
template <class T>
std::pair<BodyBuffer<T>, ImpulseBuffer<T>> solved_from(const Scene<T>& scene, const ImpulseBuffer<T>& warm,
                                                       const SolverOptions& options, Order order = Order::input,
                                                       SolveStats* stats = nullptr) {
  BodyBuffer<T> bodies = scene.bodies;
  const ContactView<T> c = scene.contacts.view();
  ImpulseBuffer<T> j = warm;
  Schedule schedule(order);
  schedule.build(c, bodies.view(), options.threads);
  const SolveStats s = Solver(options).solve(Model::rigid, bodies.view(), c, j.view(), schedule);
  if (stats != nullptr) *stats = s;
  return {std::move(bodies), std::move(j)};
}

SolverOptions accumulating(Path path, int threads, int passes, bool warm) {
  SolverOptions o = options_for(path, threads, 64);
  o.iteration = Iteration::accumulate;
  o.passes = passes;
  o.warm_start = warm;
  return o;
}

template <class T>
Scene<T> debris(bool friction) {
  return generated_debris<T>(6000, 23, friction);
}

template <class T>
void expect_same_bits_everywhere(const Scene<T>& scene, const char* what) {
  for (const Order order : {Order::input, Order::colour}) {
    // The warm start: J of 4 cold passes on the same input.
    SolverOptions cold = accumulating(Path::scalar, 1, 4, false);
    const ImpulseBuffer<T> zero(scene.contacts.size());
    const ImpulseBuffer<T> warm = solved_from(scene, zero, cold, order).second;
    for (const int passes : {1, 3}) {
      SCOPED_TRACE(std::string(type_name<T>()) + " " + what + " " + to_string(order) + " " + std::to_string(passes) +
                   " passes");
      SolverOptions base = accumulating(Path::scalar, 1, passes, true);
      base.layout = BodyLayout::soa;
      const auto [want_bodies, want_j] = solved_from(scene, warm, base, order);
      for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
        if (!isa_supported(isa)) continue;
        for (const int threads : {1, 2, 3}) {
          for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
            SCOPED_TRACE(std::string(to_string(isa)) + " " + std::to_string(threads) + " threads " + to_string(layout));
            SolverOptions o = accumulating(Path::simd, threads, passes, true);
            o.isa = isa;
            o.layout = layout;
            const auto [bodies, j] = solved_from(scene, warm, o, order);
            EXPECT_TRUE(same_impulses(j, want_j));
            EXPECT_TRUE(same_bodies(bodies, want_bodies));
          }
        }
      }
    }
  }
}

TEST(WarmStart, GivesTheSameBitsOnEveryPathIsaLayoutAndThreadCount) {
  for (const bool friction : {false, true}) {
    expect_same_bits_everywhere(debris<float>(friction), friction ? "debris friction" : "debris");
    expect_same_bits_everywhere(debris<double>(friction), friction ? "debris friction" : "debris");
    GenerateOptions o;
    o.seed = 5;
    o.friction = friction;
    expect_same_bits_everywhere(generate_pile<float>(9, o), friction ? "pile friction" : "pile");
  }
}

/// The largest |J_y - (i + 1) fall| over the column's contacts, over (n fall).
double support_error(const ImpulseBuffer<double>& j, double fall) {
  const auto v = j.view();
  double worst = 0;
  for (std::size_t i = 0; i < v.count; ++i) {
    worst = std::max(worst, std::abs(v.j.y[i] - static_cast<double>(i + 1) * fall));
  }
  return worst / (static_cast<double>(v.count) * fall);
}

TEST(WarmStart, AConvergedColumnStaysConvergedInOnePass) {
  constexpr std::size_t kBoxes = 20;
  const double fall = 9.81 / 60;
  const Scene<double> scene = column<double>(kBoxes, fall);
  const ImpulseBuffer<double> zero(kBoxes);
  for (const Order order : {Order::input, Order::colour}) {
    SCOPED_TRACE(to_string(order));
    SolverOptions o = accumulating(Path::simd, 2, 4000, false);
    const ImpulseBuffer<double> converged = solved_from(scene, zero, o, order).second;
    ASSERT_LT(support_error(converged, fall), 1e-9);
    // The next frame: the boxes at rest after the frame before, and one step
    // of gravity, fall again: the same input, warm-started.
    for (const int passes : {1, 2}) {
      SCOPED_TRACE(std::to_string(passes) + " passes");
      o.passes = passes;
      o.warm_start = true;
      SolveStats warm_stats;
      const auto [bodies, j] = solved_from(scene, converged, o, order, &warm_stats);
      EXPECT_LT(support_error(j, fall), 1e-9);
      EXPECT_LT(warm_stats.residual, 1e-9);
      for (std::size_t b = 1; b <= kBoxes; ++b) EXPECT_NEAR(bodies.view().v.y[b], 0.0, 1e-9 * fall) << "box " << b;
      o.warm_start = false;
      SolveStats cold_stats;
      const ImpulseBuffer<double> cold = solved_from(scene, zero, o, order, &cold_stats).second;
      EXPECT_GT(support_error(cold, fall), 0.1);
      EXPECT_GT(cold_stats.residual, 0.01);
    }
  }
}

ImpulseBuffer<double> one_impulse(double jy) {
  ImpulseBuffer<double> j(1);
  j.view().j.y[0] = jy;
  return j;
}

TEST(WarmStart, APassTakesBackWhatTheWarmStartGaveTooMuch) {
  const Scene<double> parting = head_on_pair(1.0, 0.0);  // already separating at 1 m/s
  const auto [bodies, j] = solved_from(parting, one_impulse(5.0), accumulating(Path::simd, 1, 1, true));
  EXPECT_EQ(j.view().j.y[0], 0.0);
  EXPECT_NEAR(bodies.view().v.y[1] - bodies.view().v.y[0], 1.0, 1e-12);
  // A J a little against the normal, as one from a frame whose normal has
  // turned since, is taken with its normal part 0 (and no friction to keep).
  ImpulseBuffer<double> turned(1);
  turned.view().j.x[0] = 1.0;
  turned.view().j.y[0] = -0.4;
  const auto [b2, j2] = solved_from(parting, turned, accumulating(Path::simd, 1, 1, true));
  EXPECT_EQ(j2.view().j.x[0], 0.0);
  EXPECT_EQ(j2.view().j.y[0], 0.0);
  EXPECT_TRUE(same_bodies(b2, bodies));
}

TEST(WarmStart, RestitutionActsOnceFromAWarmStart) {
  // Meeting at 2 m/s with e = 0.5: they part at 1 m/s, J = 1.5 N s.
  const Scene<double> impact = head_on_pair(-2.0, 0.5);
  for (const double start : {0.0, 1.5, 0.7}) {
    for (const int passes : {1, 8}) {
      SCOPED_TRACE("from J = " + std::to_string(start) + ", " + std::to_string(passes) + " passes");
      const auto [bodies, j] = solved_from(impact, one_impulse(start), accumulating(Path::simd, 1, passes, true));
      EXPECT_NEAR(bodies.view().v.y[1] - bodies.view().v.y[0], 1.0, 1e-12);
      EXPECT_NEAR(j.view().j.y[0], 1.5, 1e-12);
    }
  }
}

template <class T>
void expect_refused(ImpulseBuffer<T> warm, std::size_t bad, const std::string& why, int threads) {
  const Scene<T> scene = debris<T>(true);
  BodyBuffer<T> bodies = scene.bodies;
  const ContactView<T> c = scene.contacts.view();
  const ImpulseBuffer<T> given = warm;
  const SolverOptions o = accumulating(Path::simd, threads, 2, true);
  Schedule schedule;
  schedule.build(c, bodies.view());
  try {
    (void)Solver(o).solve(bodies.view(), c, warm.view(), schedule);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("warm start impulses.j[" + std::to_string(bad) + "] = ("), std::string::npos) << what;
    EXPECT_NE(what.find(why), std::string::npos) << what;
  }
  EXPECT_TRUE(same_bodies(bodies, scene.bodies));
  EXPECT_TRUE(same_impulses(warm, given));
  EXPECT_EQ(first_refused_warm_start(c, std::as_const(given).view()), bad);
}

TEST(WarmStart, RefusesABadJNamingTheFirstContact) {
  const Scene<float> scene = debris<float>(true);
  const std::size_t m = scene.contacts.size();
  ImpulseBuffer<float> j(m);
  for (std::size_t k = 0; k < m; ++k) {
    j.view().j.x[k] = scene.contacts.view().n.x[k];  // J = n: accepted
    j.view().j.y[k] = scene.contacts.view().n.y[k];
    j.view().j.z[k] = scene.contacts.view().n.z[k];
  }
  for (const int threads : {1, 2}) {
    ImpulseBuffer<float> nan = j;
    nan.view().j.y[m - 7] = std::numeric_limits<float>::quiet_NaN();
    nan.view().j.x[m / 2] = std::numeric_limits<float>::infinity();
    expect_refused(nan, m / 2, "is not finite", threads);
    ImpulseBuffer<float> pulls = j;
    for (const std::size_t k : {m - 3, std::size_t{4000}}) {
      pulls.view().j.x[k] = -pulls.view().j.x[k];
      pulls.view().j.y[k] = -pulls.view().j.y[k];
      pulls.view().j.z[k] = -pulls.view().j.z[k];
    }
    expect_refused(pulls, 4000, "points against the normal (J . n = ", threads);
  }
}

TEST(WarmStart, TheRepeatModeRefusesAWarmStart) {
  SolverOptions o;
  o.warm_start = true;
  try {
    const Solver solver(o);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a warm start needs iteration accumulate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace collide::test
