// test_iteration.cpp - the accumulated passes (SolverOptions::iteration,
// Iteration::accumulate; contact_kernel.hpp, "The accumulated passes") and
// the residual (SolveStats::residual).
//
// What this proves
// ----------------
// * One accumulated pass from zero is the repeat mode's pass bit for bit,
//   for every model, precision, friction, layout, path and order.
// * The accumulated passes give the same bits on every path, ISA, layout
//   and thread count, in both orders, with and without friction.
// * They converge to the physics: a column of 20 boxes resting on the ground
//   gets the support impulses k m g dt under its k-th box from the top; a box
//   on a slope stays stuck when tan(theta) < mu and slides with the Coulomb
//   impulse when tan(theta) > mu; an impact with restitution e bounces at
//   -e times its approach speed however many passes run.
// * The residual is what it says: the largest change of J in the last pass
//   over the largest |J|, as two solves of k - 1 and k passes show it.
// * The accurate mode refuses the accumulated passes, naming both.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/generated_scenes.hpp"
#include "support/solve_helpers.hpp"
#include "support/unit_boxes.hpp"

namespace collide::test {
namespace {

/// One solve of a copy of `scene`'s bodies with `options`, on a schedule in `order`.
template <class T>
std::pair<BodyBuffer<T>, ImpulseBuffer<T>> solved(const Scene<T>& scene, Model model, const SolverOptions& options,
                                                  Order order = Order::input, SolveStats* stats = nullptr) {
  BodyBuffer<T> bodies = scene.bodies;
  const ContactView<T> c = scene.contacts.view();
  ImpulseBuffer<T> j(c.count);
  Schedule schedule(order);
  schedule.build(c, bodies.view(), options.threads);
  const SolveStats s = Solver(options).solve(model, bodies.view(), c, j.view(), schedule);
  if (stats != nullptr) *stats = s;
  return {std::move(bodies), std::move(j)};
}

template <class T>
Scene<T> debris(bool friction, Model model = Model::rigid) {
  return generated_debris<T>(6000, 11, friction, model);
}

template <class T>
Scene<T> pile(bool friction) {
  GenerateOptions o;
  o.seed = 5;
  o.friction = friction;
  return generate_pile<T>(9, o);
}

template <class T>
void expect_one_pass_is_the_repeat_pass(Model model) {
  for (const bool friction : {false, true}) {
    const Scene<T> scene = debris<T>(friction, model);
    for (const Order order : {Order::input, Order::colour}) {
      for (const Path path : {Path::scalar, Path::simd}) {
        for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
          SCOPED_TRACE(std::string(type_name<T>()) + " " + to_string(model) + (friction ? " friction " : " ") +
                       to_string(order) + " " + to_string(path) + " " + to_string(layout));
          SolverOptions o = options_for(path, 2, 256);
          o.layout = layout;
          const auto [want_bodies, want_j] = solved(scene, model, o, order);
          o.iteration = Iteration::accumulate;
          SolveStats stats;
          const auto [bodies, j] = solved(scene, model, o, order, &stats);
          EXPECT_EQ(stats.iteration, Iteration::accumulate);
          EXPECT_TRUE(same_impulses(j, want_j));
          EXPECT_TRUE(same_bodies(bodies, want_bodies));
        }
      }
    }
  }
}

TEST(Iteration, OneAccumulatedPassIsTheRepeatPassBitForBit) {
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    expect_one_pass_is_the_repeat_pass<float>(model);
    expect_one_pass_is_the_repeat_pass<double>(model);
  }
}

template <class T>
void expect_same_bits_everywhere(const Scene<T>& scene, bool pile_scene) {
  for (const Order order : {Order::input, Order::colour}) {
    SCOPED_TRACE(std::string(type_name<T>()) + (pile_scene ? " pile " : " debris ") + to_string(order));
    SolverOptions base = options_for(Path::scalar, 1);
    base.passes = 5;
    base.iteration = Iteration::accumulate;
    base.layout = BodyLayout::soa;
    const auto [want_bodies, want_j] = solved(scene, Model::rigid, base, order);
    for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
      if (!isa_supported(isa)) continue;
      for (const int threads : {1, 2, 3}) {
        for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
          SCOPED_TRACE(std::string(to_string(isa)) + " " + std::to_string(threads) + " threads " + to_string(layout));
          SolverOptions o = options_for(Path::simd, threads, 64);
          o.isa = isa;
          o.passes = base.passes;
          o.iteration = Iteration::accumulate;
          o.layout = layout;
          const auto [bodies, j] = solved(scene, Model::rigid, o, order);
          EXPECT_TRUE(same_impulses(j, want_j));
          EXPECT_TRUE(same_bodies(bodies, want_bodies));
        }
      }
    }
  }
}

TEST(Iteration, AccumulatedPassesGiveTheSameBitsOnEveryPathIsaLayoutAndThreadCount) {
  for (const bool friction : {false, true}) {
    expect_same_bits_everywhere(debris<float>(friction), false);
    expect_same_bits_everywhere(debris<double>(friction), false);
    expect_same_bits_everywhere(pile<float>(friction), true);
  }
}

TEST(Iteration, AColumnOfBoxesGetsTheSupportImpulses) {
  constexpr std::size_t kBoxes = 20;
  const double fall = 9.81 / 60;  // one step of gravity at 60 Hz [m/s]
  const Scene<double> scene = column<double>(kBoxes, fall);
  for (const Order order : {Order::input, Order::colour}) {
    SCOPED_TRACE(to_string(order));
    SolverOptions o;
    // K is the column's tridiagonal 2, -1 (1 at the ground), whose
    // Gauss-Seidel passes contract by about cos(pi / (2n + 1))^2 each
    // (0.9942 for 20 contacts): 4000 passes leave under 1e-10 of the error.
    o.passes = 4000;
    o.iteration = Iteration::accumulate;
    SolveStats stats;
    const auto [bodies, j] = solved(scene, Model::rigid, o, order, &stats);
    EXPECT_LT(stats.residual, 1e-9);
    const auto jv = j.view();
    for (std::size_t i = 0; i < kBoxes; ++i) {
      // Contact i (listed top first) is under box kBoxes - i, the (i + 1)-th
      // from the top, and holds up i + 1 boxes.
      const double want = static_cast<double>(i + 1) * fall;
      EXPECT_NEAR(jv.j.y[i], want, 1e-8 * want) << "contact " << i;
      EXPECT_EQ(jv.j.x[i], 0.0);
      EXPECT_EQ(jv.j.z[i], 0.0);
    }
    // Every box at rest.
    for (std::size_t b = 1; b <= kBoxes; ++b) EXPECT_NEAR(bodies.view().v.y[b], 0.0, 1e-8 * fall) << "box " << b;
  }
}

/// One box on an immovable ground tilted by `theta`, falling at `fall`
/// straight down: its velocity after the solve.
std::array<double, 3> on_a_slope(double theta, double mu, double fall, int passes) {
  Scene<double> s;
  s.bodies.push_back(ground_at<double>(-1));
  s.bodies.push_back(box_at<double>(0, -fall));
  ContactRecord<double> c;
  c.a = 1;
  c.b = 0;  // at the centre of mass: no lever arm
  c.n[0] = -std::sin(theta);
  c.n[1] = std::cos(theta);
  c.n[2] = 0;
  c.e = 0;
  c.mu = mu;
  s.contacts.push_back(c);
  SolverOptions o;
  o.passes = passes;
  o.iteration = Iteration::accumulate;
  const auto [bodies, j] = solved(s, Model::rigid, o);
  const auto v = bodies.view();
  return {v.v.x[1], v.v.y[1], v.v.z[1]};
}

TEST(Iteration, ABoxOnASlopeSticksBelowTheFrictionAngleAndSlidesAbove) {
  const double fall = 9.81 / 60;
  const double theta = 0.4;  // tan = 0.423
  for (const int passes : {1, 4}) {
    SCOPED_TRACE(std::to_string(passes) + " passes");
    const auto stuck = on_a_slope(theta, 0.5, fall, passes);
    for (const double x : stuck) EXPECT_NEAR(x, 0.0, 1e-12);
    // Sliding: the normal impulse stops the approach, fall cos(theta); the
    // friction impulse is mu times it, against the slide down the slope,
    // whose speed fall sin(theta) drops by mu fall cos(theta).
    const double mu = 0.2;
    const auto slides = on_a_slope(theta, mu, fall, passes);
    const double speed = std::hypot(slides[0], slides[1]);
    EXPECT_NEAR(speed, fall * (std::sin(theta) - mu * std::cos(theta)), 1e-12);
    // Along the slope, downhill: (-cos, -sin) for a normal (-sin, cos).
    EXPECT_NEAR(slides[0] * -std::sin(theta) + slides[1] * std::cos(theta), 0.0, 1e-12);
    EXPECT_LT(slides[1], 0.0);
  }
}

TEST(Iteration, RestitutionActsOnceHoweverManyPassesRun) {
  // Two free boxes meeting head on at 2 m/s, e = 0.5: they part at 1 m/s.
  const Scene<double> s = head_on_pair<double>(-2, 0.5);
  for (const Iteration iteration : {Iteration::accumulate, Iteration::repeat}) {
    SolverOptions o;
    o.passes = 8;
    o.iteration = iteration;
    const auto [bodies, j] = solved(s, Model::rigid, o);
    const double parting = bodies.view().v.y[1] - bodies.view().v.y[0];
    if (iteration == Iteration::accumulate) {
      EXPECT_DOUBLE_EQ(parting, 1.0);
      EXPECT_DOUBLE_EQ(j.view().j.y[0], 1.5);
    } else {
      EXPECT_DOUBLE_EQ(parting, 1.0);  // the later passes see it separating: nothing happens
    }
  }
}

TEST(Iteration, TheResidualIsTheLastPassesChangeOverTheLargestImpulse) {
  const Scene<float> scene = pile<float>(false);
  for (const Iteration iteration : {Iteration::repeat, Iteration::accumulate}) {
    SCOPED_TRACE(to_string(iteration));
    SolverOptions o = options_for(Path::simd, 2, 256);
    o.iteration = iteration;
    SolveStats one;
    (void)solved(scene, Model::rigid, o, Order::colour, &one);
    EXPECT_EQ(one.residual, 1.0);
    double last = 2;
    for (const int passes : {2, 4, 16}) {
      o.passes = passes - 1;
      const auto [b0, before] = solved(scene, Model::rigid, o, Order::colour);
      o.passes = passes;
      SolveStats stats;
      const auto [b1, after] = solved(scene, Model::rigid, o, Order::colour, &stats);
      double change = 0;
      double total = 0;
      const auto x = before.view();
      const auto y = after.view();
      for (std::size_t k = 0; k < x.count; ++k) {
        const double dx = double(y.j.x[k]) - double(x.j.x[k]);
        const double dy = double(y.j.y[k]) - double(x.j.y[k]);
        const double dz = double(y.j.z[k]) - double(x.j.z[k]);
        change = std::max(change, std::sqrt(dx * dx + dy * dy + dz * dz));
        const double jx = y.j.x[k], jy = y.j.y[k], jz = y.j.z[k];
        total = std::max(total, std::sqrt(jx * jx + jy * jy + jz * jz));
      }
      EXPECT_EQ(stats.residual, change / total) << passes << " passes";
      EXPECT_LT(stats.residual, last) << passes << " passes";
      last = stats.residual;
    }
  }
}

TEST(Iteration, TheAccurateModeRefusesTheAccumulatedPasses) {
  SolverOptions o;
  o.accuracy = Accuracy::accurate;
  o.iteration = Iteration::accumulate;
  try {
    const Solver solver(o);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("iteration accumulate runs in the fast mode"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parse_iteration("accumulate"), Iteration::accumulate);
  EXPECT_EQ(parse_iteration("repeat"), Iteration::repeat);
  EXPECT_THROW((void)parse_iteration("sum"), std::invalid_argument);
}

}  // namespace
}  // namespace collide::test
