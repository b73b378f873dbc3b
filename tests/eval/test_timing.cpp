// test_timing.cpp - collide/eval/timing.hpp: the one rule by which the
// report's rows and sweep and the benchmark's rows time a solve.
//
// What this proves
// ----------------
// * With a fake clock whose time the restore and the solve advance: the
//   warm-up solve is not timed (the clock is not read around it), the
//   restore runs before every solve, the warm-up's included, and is never
//   inside a timed interval, and each timed run is exactly its solve's time.
// * The figure is the median of the timed runs: the middle one for an odd
//   count, the mean of the two middle ones for an even count, whatever
//   their order; a slow warm-up does not move it.
// * RunPlan: a fixed count; at least `at_least`, more while the total is
//   below `fill_seconds`, never more than `at_most`; fewer than one run is
//   refused.
// * RunSeries (Google Benchmark's loop): the warm-up at construction, one
//   timed run per next(), the same median.
// * The real clock: time_solve on steady_clock gives non-negative runs.
// * bandwidth_fraction: collisions/s x bytes_per_collision() over the
//   triad, 0 when the triad or the bytes are unknown.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/timing.hpp"
#include "collide/eval/traffic.hpp"
#include "collide/model.hpp"

namespace collide::test {
namespace {

/// A scripted machine: the restore takes `restore_seconds`, solve k takes
/// `solve_seconds[k]` (solve 0 is the warm-up); every event is logged.
struct FakeMachine {
  double now = 0;
  double restore_seconds = 100;  // large, so that timing it by mistake shows
  std::vector<double> solve_seconds;
  std::size_t solves = 0;
  std::vector<std::string> log;

  void restore() {
    log.emplace_back("restore");
    now += restore_seconds;
  }
  void solve() {
    log.emplace_back("solve");
    now += solve_seconds.at(solves++);
  }
};

/// A clock reading the fake machine's time.
struct FakeClock {
  FakeMachine* machine;
  double operator()() const {
    machine->log.emplace_back("clock");
    return machine->now;
  }
};

RunTimes time_fake(FakeMachine& m, const RunPlan& plan) {
  return time_solve(
      plan, [&] { m.restore(); }, [&] { m.solve(); }, FakeClock{&m});
}

TEST(Timing, WarmUpIsNotTimedAndRestoreComesBeforeEverySolve) {
  FakeMachine m;
  m.solve_seconds = {50, 3, 1, 2};  // a slow warm-up, then three runs
  const RunTimes t = time_fake(m, RunPlan::fixed(3));
  ASSERT_EQ(t.runs(), 3);
  EXPECT_EQ(t.seconds, (std::vector<double>{3, 1, 2}));  // neither the warm-up nor a restore is in them
  EXPECT_EQ(t.median, 2);
  EXPECT_EQ(m.solves, 4u);
  const std::vector<std::string> expected = {"restore", "solve",  // the warm-up: the clock is not read
                                             "restore", "clock", "solve", "clock",   // run 1
                                             "restore", "clock", "solve", "clock",   // run 2
                                             "restore", "clock", "solve", "clock"};  // run 3
  EXPECT_EQ(m.log, expected);
}

TEST(Timing, IntOverloadIsAFixedCount) {
  FakeMachine m;
  m.solve_seconds = {9, 4, 1, 3, 2};
  const RunTimes t = time_solve(
      4, [&] { m.restore(); }, [&] { m.solve(); }, FakeClock{&m});
  EXPECT_EQ(t.runs(), 4);
  EXPECT_EQ(t.median, 2.5);  // even count: the mean of 2 and 3
}

TEST(Timing, MedianOddAndEven) {
  EXPECT_EQ(median_seconds({}), 0);
  EXPECT_EQ(median_seconds({7}), 7);
  EXPECT_EQ(median_seconds({5, 1}), 3);
  EXPECT_EQ(median_seconds({3, 1, 2}), 2);
  EXPECT_EQ(median_seconds({4, 1, 3, 2}), 2.5);
  EXPECT_EQ(median_seconds({10, 1, 1, 1, 10}), 1);  // outliers on both sides
  EXPECT_EQ(median_seconds({1, 2, 100, 3, 4, 5}), 3.5);
}

TEST(Timing, OddAndEvenRunCounts) {
  for (int runs = 1; runs <= 6; ++runs) {
    FakeMachine m;
    m.solve_seconds.push_back(1000);                               // warm-up
    for (int r = runs; r >= 1; --r) m.solve_seconds.push_back(r);  // runs, runs-1, ..., 1
    const RunTimes t = time_fake(m, RunPlan::fixed(runs));
    ASSERT_EQ(t.runs(), runs);
    // The median of 1..runs is (runs + 1) / 2 for either parity.
    EXPECT_EQ(t.median, (runs + 1) / 2.0) << runs << " runs";
  }
}

TEST(Timing, PlanFillsATimeBetweenItsLeastAndMost) {
  // Run times of binary fractions, so that their sums are exact.
  {
    FakeMachine m;
    m.solve_seconds.assign(100, 0.125);
    const RunTimes t = time_fake(m, RunPlan{2, 0.625, 10});
    EXPECT_EQ(t.runs(), 5);  // 5 x 0.125 reaches 0.625 (the warm-up and the restores do not count)
  }
  {
    FakeMachine m;
    m.solve_seconds.assign(100, 0.125);
    EXPECT_EQ(time_fake(m, RunPlan{2, 1.0, 4}).runs(), 4);  // capped by at_most
  }
  {
    FakeMachine m;
    m.solve_seconds.assign(100, 1.0);
    EXPECT_EQ(time_fake(m, RunPlan{3, 0.5, 200}).runs(), 3);  // at least at_least
  }
  {
    FakeMachine m;
    m.solve_seconds.assign(100, 0.125);
    EXPECT_EQ(time_fake(m, RunPlan{3, 0.5, 0}).runs(), 3);  // at_most 0: at_least
  }
  FakeMachine m;
  m.solve_seconds.assign(10, 1.0);
  EXPECT_THROW(time_fake(m, RunPlan::fixed(0)), std::invalid_argument);
  EXPECT_EQ(m.solves, 0u);  // refused before any solve
}

TEST(Timing, RunSeriesWarmsUpAtConstruction) {
  FakeMachine m;
  m.solve_seconds = {50, 4, 1, 3, 2};
  RunSeries series(
      [&] {
        m.restore();
        m.solve();
      },
      [&] { return timed_run([&] { m.restore(); }, [&] { m.solve(); }, FakeClock{&m}); });
  EXPECT_EQ(m.solves, 1u);  // the warm-up, untimed
  EXPECT_EQ(m.log, (std::vector<std::string>{"restore", "solve"}));
  EXPECT_EQ(series.count(), 0);
  EXPECT_EQ(series.next(), 4);
  EXPECT_EQ(series.next(), 1);
  EXPECT_EQ(series.next(), 3);
  EXPECT_EQ(series.median(), 3);
  EXPECT_EQ(series.next(), 2);
  EXPECT_EQ(series.count(), 4);
  EXPECT_EQ(series.total(), 10);
  EXPECT_EQ(series.median(), 2.5);
  EXPECT_EQ(series.result().seconds, (std::vector<double>{4, 1, 3, 2}));
}

TEST(Timing, MeasureRunsDiscardsTheWarmUpOfACompositeRun) {
  // A run whose timed part is several pieces (the report's Bullet row):
  // measure_runs takes the seconds the run returns, the first run's
  // discarded.
  std::vector<double> returned = {99, 5, 6, 7};
  std::size_t k = 0;
  const RunTimes t = measure_runs(RunPlan::fixed(3), [&] { return returned.at(k++); });
  EXPECT_EQ(k, 4u);
  EXPECT_EQ(t.seconds, (std::vector<double>{5, 6, 7}));
  EXPECT_EQ(t.median, 6);
}

TEST(Timing, SteadyClockRuns) {
  int restores = 0, solves = 0;
  volatile double sink = 0;
  const RunTimes t = time_solve(
      3, [&] { ++restores; },
      [&] {
        ++solves;
        for (int i = 0; i < 1000; ++i) sink = sink + i;
      });
  EXPECT_EQ(restores, 4);
  EXPECT_EQ(solves, 4);
  ASSERT_EQ(t.runs(), 3);
  for (const double s : t.seconds) EXPECT_GE(s, 0);
  EXPECT_GE(t.median, 0);
}

TEST(Timing, BandwidthFraction) {
  const double bytes = static_cast<double>(bytes_per_collision(Model::rigid, sizeof(float), false));
  EXPECT_EQ(bytes, 232);
  EXPECT_DOUBLE_EQ(bandwidth_fraction(1e8, Model::rigid, sizeof(float), false, 4.64e10), 0.5);
  EXPECT_DOUBLE_EQ(bandwidth_fraction(1e8, Model::particle, sizeof(double), true, 1e10),
                   1e8 * static_cast<double>(bytes_per_collision(Model::particle, sizeof(double), true)) / 1e10);
  EXPECT_DOUBLE_EQ(bandwidth_fraction(1e8, bytes, 4.64e10), 0.5);
  EXPECT_EQ(bandwidth_fraction(1e8, Model::rigid, sizeof(float), false, 0), 0);  // no triad measured
  EXPECT_EQ(bandwidth_fraction(1e8, 0.0, 4.64e10), 0);                           // no bytes (schedule rows)
}

}  // namespace
}  // namespace collide::test
