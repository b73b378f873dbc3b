// collide/eval/timing.hpp - how collide's instruments time a solve: the rows
// and the N sweep of `collide report`, the rows of collide_bench, and the
// check that compares them (collide_bench --timing-check).
//
// Design notes
// ------------
// * One rule for every instrument. A run is an untimed restore of the state
//   the solve changes (its velocities), then the solve alone between two
//   readings of the clock. One run comes first and is not timed, the
//   warm-up: the solver's worker threads started, its buffers sized and
//   first touched, code and data where a frame loop would have them. Then
//   the timed runs; the figure is their median, so that one run disturbed
//   by another process does not move it.
// * The number of timed runs is the caller's (RunPlan): a fixed count, or
//   as many as fill a time, between a least and a most. Google Benchmark
//   decides its own count; there a RunSeries applies the same rule, the
//   warm-up at construction and one timed run per iteration of its loop.
// * The clock is a callable that returns seconds (SteadyClock by default),
//   so that a test can feed a fake one.
// * The bandwidth fraction is the same quotient everywhere: collisions per
//   second times bytes_per_collision() (traffic.hpp) over the triad's bytes
//   per second at the same thread count (bandwidth.hpp).
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/eval/traffic.hpp"
#include "collide/model.hpp"

namespace collide {

/// Seconds on std::chrono::steady_clock since the clock object was made.
class SteadyClock {
 public:
  double operator()() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - origin_).count();
  }

 private:
  std::chrono::steady_clock::time_point origin_ = std::chrono::steady_clock::now();
};

/// The median of run times, 0 for none; for an even count, the mean of the
/// two middle values.
inline double median_seconds(std::vector<double> seconds) {
  if (seconds.empty()) return 0;
  const auto mid = seconds.begin() + static_cast<std::ptrdiff_t>(seconds.size() / 2);
  std::nth_element(seconds.begin(), mid, seconds.end());
  if (seconds.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(seconds.begin(), mid));
}

/// One run: `restore()` untimed, then `solve()` between two readings of
/// `clock`. Returns the seconds of solve() alone.
template <class Restore, class Solve, class Clock = SteadyClock>
double timed_run(Restore&& restore, Solve&& solve, Clock&& clock = Clock{}) {
  restore();
  const double t0 = clock();
  solve();
  const double t1 = clock();
  return t1 - t0;
}

/// How many timed runs follow the warm-up: at least `at_least`, then more
/// while their total is below `fill_seconds`, up to `at_most` (0: no more
/// than `at_least`).
struct RunPlan {
  int at_least = 3;
  double fill_seconds = 0;
  int at_most = 0;

  /// Exactly `runs` timed runs.
  static RunPlan fixed(int runs) { return RunPlan{runs, 0, runs}; }
};

/// The timed runs of one measurement (the warm-up is not among them).
struct RunTimes {
  std::vector<double> seconds;  ///< each timed run, in order
  double median = 0;            ///< median_seconds(seconds): the measurement's figure
  [[nodiscard]] int runs() const { return static_cast<int>(seconds.size()); }
};

/// The runs of one measurement, for a caller that decides their number
/// itself (Google Benchmark's loop): the warm-up at construction, then one
/// timed run per next(). `Run` is a callable that performs one run and
/// returns the seconds of its timed part (timed_run, or a run whose timed
/// part is several pieces, such as the report's Bullet row).
template <class Run>
class RunSeries {
 public:
  /// The warm-up is `warm_up()`, called once here and not timed (for a
  /// solve: its restore, then the solve).
  template <class WarmUp>
  RunSeries(WarmUp&& warm_up, Run run) : run_(std::move(run)) {
    warm_up();
  }
  /// The warm-up is one run whose time is discarded (a run of several timed
  /// pieces, whose warm-up is the whole run).
  explicit RunSeries(Run run) : run_(std::move(run)) { (void)run_(); }

  /// One timed run; returns its seconds.
  double next() {
    seconds_.push_back(run_());
    return seconds_.back();
  }
  [[nodiscard]] int count() const { return static_cast<int>(seconds_.size()); }
  [[nodiscard]] double total() const { return std::accumulate(seconds_.begin(), seconds_.end(), 0.0); }
  [[nodiscard]] const std::vector<double>& seconds() const { return seconds_; }
  [[nodiscard]] double median() const { return median_seconds(seconds_); }
  [[nodiscard]] RunTimes result() const { return RunTimes{seconds_, median()}; }

 private:
  Run run_;
  std::vector<double> seconds_;
};

/// The timed runs of `series` (its warm-up done) as `plan` says: at least
/// plan.at_least of them, so none when it is below 1.
template <class Run>
RunTimes run_plan(const RunPlan& plan, RunSeries<Run>& series) {
  const int most = std::max(plan.at_least, plan.at_most);
  while (series.count() < plan.at_least || (series.count() < most && series.total() < plan.fill_seconds)) {
    series.next();
  }
  return series.result();
}

/// `warm_up()` once, untimed, then as many runs of `run` as `plan` says
/// (see RunSeries for `run`). Throws std::invalid_argument, before the
/// warm-up, when plan.at_least < 1.
template <class WarmUp, class Run>
RunTimes measure_runs(const RunPlan& plan, WarmUp&& warm_up, Run&& run) {
  if (plan.at_least < 1) throw std::invalid_argument("measure_runs: at least one timed run");
  RunSeries<std::decay_t<Run>> series(std::forward<WarmUp>(warm_up), std::forward<Run>(run));
  return run_plan(plan, series);
}

/// The same, the warm-up being one run of `run` whose time is discarded.
template <class Run>
RunTimes measure_runs(const RunPlan& plan, Run&& run) {
  if (plan.at_least < 1) throw std::invalid_argument("measure_runs: at least one timed run");
  RunSeries<std::decay_t<Run>> series(std::forward<Run>(run));
  return run_plan(plan, series);
}

/// A solve measured by the rule: restore() then solve(), untimed (the
/// warm-up; the clock is not read), then for every timed run restore()
/// untimed and solve() timed by `clock`; the runs as `plan` says; their
/// median.
template <class Restore, class Solve, class Clock = SteadyClock>
RunTimes time_solve(const RunPlan& plan, Restore&& restore, Solve&& solve, Clock&& clock = Clock{}) {
  return measure_runs(
      plan,
      [&] {
        restore();
        solve();
      },
      [&] { return timed_run(restore, solve, clock); });
}

/// The same with exactly `runs` timed runs.
template <class Restore, class Solve, class Clock = SteadyClock>
RunTimes time_solve(int runs, Restore&& restore, Solve&& solve, Clock&& clock = Clock{}) {
  return time_solve(RunPlan::fixed(runs), std::forward<Restore>(restore), std::forward<Solve>(solve),
                    std::forward<Clock>(clock));
}

/// Items per second times bytes per item over the triad's bytes per
/// second: the fraction of the bandwidth bound. 0 when either the bytes or
/// the triad is unknown (not above 0).
constexpr double bandwidth_fraction(double items_per_second, double bytes_per_item, double triad_bytes_per_second) {
  return bytes_per_item > 0 && triad_bytes_per_second > 0 ? items_per_second * bytes_per_item / triad_bytes_per_second
                                                          : 0.0;
}

/// A solve's fraction of the bandwidth bound: collisions per second times
/// bytes_per_collision(model, value_bytes, friction) over the triad's bytes
/// per second at the same thread count.
constexpr double bandwidth_fraction(double collisions_per_second, Model model, std::size_t value_bytes, bool friction,
                                    double triad_bytes_per_second) {
  return bandwidth_fraction(collisions_per_second,
                            static_cast<double>(bytes_per_collision(model, value_bytes, friction)),
                            triad_bytes_per_second);
}

}  // namespace collide
