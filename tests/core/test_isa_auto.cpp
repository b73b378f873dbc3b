// test_isa_auto.cpp - Isa::automatic with COLLIDE_ISA unset picks the ISA
// that ran fastest for the kind of solve (collide::fastest_isa, measured once
// per process): a solve says it measured and runs an ISA the CPU has, the
// pick for its model, precision, accuracy and scene kind; forcing any ISA
// gives the same bits, so the measurement cannot change a result; COLLIDE_ISA
// and a named ISA still force one; the pick is stable within a process.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "collide/io/generate.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/isa_env.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

const Isa kConcrete[] = {Isa::sse2, Isa::avx2, Isa::avx512};
const Model kModels[] = {Model::particle, Model::sphere, Model::rigid};
const Accuracy kAccuracies[] = {Accuracy::fast, Accuracy::accurate};

int supported_count() {
  int n = 0;
  for (const Isa isa : kConcrete) n += isa_supported(isa) ? 1 : 0;
  return n;
}

/// True when most of the schedule's contacts are in non-contiguous batches:
/// the scene kind the solver measures for.
bool mostly_scattered(const Schedule& schedule) {
  std::size_t scattered = 0;
  for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
    if (!schedule.batch_is_contiguous(k)) scattered += schedule.batch_begin(k + 1) - schedule.batch_begin(k);
  }
  return 2 * scattered > schedule.contact_count();
}

/// One scene solved with Isa::automatic and with every ISA the CPU has,
/// compared bit for bit.
template <class T>
void automatic_matches_every_isa(const Scene<T>& scene, Model model, Accuracy accuracy, bool expect_scattered,
                                 const std::string& what) {
  SCOPED_TRACE(what + " " + type_name<T>() + " " + to_string(model) + " " + to_string(accuracy));
  const ContactView<T> contacts = scene.contacts.view();
  Schedule schedule;
  {
    BodyBuffer<T> b = scene.bodies;
    schedule.build(contacts, b.view());
  }
  const bool scattered = mostly_scattered(schedule);
  ASSERT_EQ(scattered, expect_scattered) << "the scene is not of the kind the test means";

  auto run = [&](Isa isa, BodyBuffer<T>& bodies, ImpulseBuffer<T>& j) {
    SolverOptions o = options_for(Path::simd, 2, 40);  // blocks end mid-group: tails run too
    o.isa = isa;
    o.accuracy = accuracy;
    bodies = scene.bodies;
    j.resize(contacts.count);
    const Solver solver(o);
    return solver.solve(model, bodies.view(), contacts, j.view(), schedule);
  };

  BodyBuffer<T> auto_bodies;
  ImpulseBuffer<T> auto_j;
  const SolveStats a = run(Isa::automatic, auto_bodies, auto_j);
  EXPECT_EQ(a.isa_choice, IsaChoice::measured);
  EXPECT_NE(a.isa, Isa::automatic);
  EXPECT_TRUE(isa_supported(a.isa)) << to_string(a.isa);
  EXPECT_EQ(a.isa, fastest_isa<T>(model, accuracy, scattered));
  EXPECT_EQ(a.lanes, simd_width<T>(a.isa));
  EXPECT_EQ(a.accuracy, accuracy);
  std::size_t acted = 0;
  for (std::size_t k = 0; k < auto_j.size(); ++k) acted += auto_j.view().j.x[k] != 0;
  EXPECT_GT(acted, 0u) << "nothing happened: the comparison would prove little";

  int ran = 0;
  for (const Isa isa : kConcrete) {
    if (!isa_supported(isa)) continue;
    SCOPED_TRACE(to_string(isa));
    BodyBuffer<T> bodies;
    ImpulseBuffer<T> j;
    const SolveStats s = run(isa, bodies, j);
    EXPECT_EQ(s.isa, isa);
    EXPECT_EQ(s.isa_choice, IsaChoice::forced);
    EXPECT_EQ(s.isa_calibration_seconds, 0.0);
    EXPECT_TRUE(same_bodies(auto_bodies, bodies));
    EXPECT_TRUE(same_impulses(auto_j, j));
    ++ran;
  }
  EXPECT_GE(ran, 1);
}

template <class T>
void every_model_accuracy_and_kind() {
  const IsaEnv env(nullptr);
  for (const Model model : kModels) {
    for (const Accuracy accuracy : kAccuracies) {
      for (const bool friction : {false, true}) {
        GenerateOptions g;
        g.seed = 11;
        g.friction = friction;
        g.model = model;
        const std::string f = friction ? " friction" : "";
        automatic_matches_every_isa(generate_pairs<T>(1003, g), model, accuracy, false, "pairs" + f);
        automatic_matches_every_isa(generate_debris<T>(4005, g), model, accuracy, true, "debris" + f);
      }
    }
  }
}

TEST(IsaAuto, MeasuredSolvesMatchEveryIsaFloat) { every_model_accuracy_and_kind<float>(); }
TEST(IsaAuto, MeasuredSolvesMatchEveryIsaDouble) { every_model_accuracy_and_kind<double>(); }

// The caller's packed records go through the same choice.
TEST(IsaAuto, PackedRecordsAreMeasuredToo) {
  const IsaEnv env(nullptr);
  GenerateOptions g;
  g.seed = 5;
  Scene<float> scene = generate_debris<float>(4005, g);
  PackedBuffer<PackedRigid<float>> records(scene.bodies.size());
  pack(std::as_const(scene.bodies).view(), packed_view(records));
  Schedule schedule;
  schedule.build(scene.contacts.view(), scene.bodies.view());
  ImpulseBuffer<float> j(scene.contacts.size());
  const SolveStats s = Solver().solve(packed_view(records), scene.contacts.view(), j.view(), schedule);
  EXPECT_EQ(s.isa_choice, IsaChoice::measured);
  EXPECT_EQ(s.layout, BodyLayout::packed);
  EXPECT_EQ(s.isa, fastest_isa<float>(Model::rigid, Accuracy::fast, mostly_scattered(schedule)));
}

TEST(IsaAuto, EnvironmentAndOptionsForceOne) {
  GenerateOptions g;
  g.seed = 3;
  const Scene<float> scene = generate_pairs<float>(501, g);
  Schedule schedule;
  {
    BodyBuffer<float> b = scene.bodies;
    schedule.build(scene.contacts.view(), b.view());
  }
  auto solve = [&](const SolverOptions& o) {
    BodyBuffer<float> bodies = scene.bodies;
    ImpulseBuffer<float> j(scene.contacts.size());
    return Solver(o).solve(bodies.view(), scene.contacts.view(), j.view(), schedule);
  };
  for (const Isa isa : kConcrete) {
    if (!isa_supported(isa)) continue;
    SCOPED_TRACE(to_string(isa));
    {
      const IsaEnv env(to_string(isa));
      const Solver solver;
      EXPECT_EQ(solver.isa(), isa);
      EXPECT_EQ(solver.isa_choice(), IsaChoice::environment);
      const SolveStats s = solve(SolverOptions{});
      EXPECT_EQ(s.isa, isa);
      EXPECT_EQ(s.isa_choice, IsaChoice::environment);
      EXPECT_EQ(s.isa_calibration_seconds, 0.0);
      // A named ISA wins over the environment.
      SolverOptions o;
      o.isa = Isa::sse2;
      const SolveStats f = solve(o);
      EXPECT_EQ(f.isa, Isa::sse2);
      EXPECT_EQ(f.isa_choice, IsaChoice::forced);
    }
    {
      const IsaEnv env(nullptr);
      SolverOptions o;
      o.isa = isa;
      EXPECT_EQ(Solver(o).isa_choice(), IsaChoice::forced);
      const SolveStats s = solve(o);
      EXPECT_EQ(s.isa, isa);
      EXPECT_EQ(s.isa_choice, IsaChoice::forced);
    }
  }
  {
    // "auto" in the environment is the same as unset: measured.
    const IsaEnv env("auto");
    EXPECT_EQ(Solver().isa(), Isa::automatic);
    EXPECT_EQ(Solver().isa_choice(), IsaChoice::measured);
    EXPECT_EQ(solve(SolverOptions{}).isa_choice, IsaChoice::measured);
  }
  {
    // The scalar path runs the baseline's kernel, whatever was asked.
    const IsaEnv env(nullptr);
    const SolveStats s = solve(options_for(Path::scalar, 1));
    EXPECT_EQ(s.isa, Isa::sse2);
    EXPECT_EQ(s.isa_choice, IsaChoice::baseline);
    EXPECT_EQ(s.lanes, 1u);
  }
}

// Every key: the same answer on every call, an ISA the CPU has, and a
// measurement that agrees with it. The calibration time is reported, not
// judged: speed belongs to the benchmark.
TEST(IsaAuto, FastestIsaIsStableWithinAProcess) {
  const int isas = supported_count();
  double total = 0;
  for (const bool is_float : {true, false}) {
    for (const Model model : kModels) {
      for (const Accuracy accuracy : kAccuracies) {
        for (const bool scattered : {false, true}) {
          SCOPED_TRACE(std::string(is_float ? "float " : "double ") + to_string(model) + " " + to_string(accuracy) +
                       (scattered ? " scattered" : " streaming"));
          const Isa first = is_float ? fastest_isa<float>(model, accuracy, scattered)
                                     : fastest_isa<double>(model, accuracy, scattered);
          const Isa second = is_float ? fastest_isa<float>(model, accuracy, scattered)
                                      : fastest_isa<double>(model, accuracy, scattered);
          EXPECT_EQ(first, second);
          EXPECT_TRUE(isa_supported(first) && first != Isa::automatic) << to_string(first);
          const IsaMeasurement m = is_float ? isa_measurement<float>(model, accuracy, scattered)
                                            : isa_measurement<double>(model, accuracy, scattered);
          EXPECT_EQ(m.fastest, first);
          if (isas < 2) {
            EXPECT_EQ(m.contacts, 0u);  // nothing to choose between: nothing measured
            continue;
          }
          EXPECT_GT(m.contacts, 0u);
          EXPECT_GT(m.rounds, 0);
          EXPECT_GT(m.calibration_seconds, 0.0);
          for (const Isa isa : kConcrete) {
            const double seconds = m.seconds[static_cast<int>(isa) - static_cast<int>(Isa::sse2)];
            EXPECT_EQ(seconds > 0, isa_supported(isa)) << to_string(isa);
            if (isa_supported(isa)) {
              EXPECT_LE(m.seconds[static_cast<int>(first) - static_cast<int>(Isa::sse2)], seconds) << to_string(isa);
            }
          }
          std::printf("  %-6s %-8s %-8s %-10s -> %-6s  calibration %.2f ms\n", is_float ? "float" : "double",
                      to_string(model), to_string(accuracy), scattered ? "scattered" : "streaming", to_string(first),
                      1e3 * m.calibration_seconds);
          total += m.calibration_seconds;
        }
      }
    }
  }
  RecordProperty("calibration_ms_all_keys", std::to_string(1e3 * total));
  std::printf("  all 24 kinds: %.1f ms of calibration\n", 1e3 * total);
}

// Concurrent first solves of one kind wait for one measurement: they agree,
// and at most one of them reports having measured.
TEST(IsaAuto, ConcurrentFirstSolvesMeasureOnce) {
  const IsaEnv env(nullptr);
  GenerateOptions g;
  g.seed = 9;
  g.model = Model::sphere;
  const Scene<double> scene = generate_debris<double>(4005, g);
  Schedule schedule;
  {
    BodyBuffer<double> b = scene.bodies;
    schedule.build(scene.contacts.view(), b.view());
  }
  SolverOptions o = options_for(Path::simd, 1);
  o.accuracy = Accuracy::accurate;
  constexpr int kThreads = 4;
  std::vector<SolveStats> stats(kThreads);
  std::vector<std::thread> threads;
  threads.reserve(kThreads);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      BodyBuffer<double> bodies = scene.bodies;
      ImpulseBuffer<double> j(scene.contacts.size());
      stats[static_cast<std::size_t>(t)] =
          Solver(o).solve(Model::sphere, bodies.view(), scene.contacts.view(), j.view(), schedule);
    });
  }
  for (std::thread& t : threads) t.join();
  int measured = 0;
  for (const SolveStats& s : stats) {
    EXPECT_EQ(s.isa, stats.front().isa);
    EXPECT_EQ(s.isa_choice, IsaChoice::measured);
    if (s.isa_calibration_seconds > 0) {
      ++measured;
      EXPECT_EQ(
          s.isa_calibration_seconds,
          isa_measurement<double>(Model::sphere, Accuracy::accurate, mostly_scattered(schedule)).calibration_seconds);
    }
  }
  EXPECT_LE(measured, 1);
  // Later solves of the same kind measure nothing.
  BodyBuffer<double> bodies = scene.bodies;
  ImpulseBuffer<double> j(scene.contacts.size());
  const SolveStats again = Solver(o).solve(Model::sphere, bodies.view(), scene.contacts.view(), j.view(), schedule);
  EXPECT_EQ(again.isa_calibration_seconds, 0.0);
  EXPECT_EQ(again.isa, stats.front().isa);
}

}  // namespace
}  // namespace collide::test
