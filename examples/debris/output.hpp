// output.hpp - what collide_debris prints and draws: the per-step table, the
// summary of a run, the picture, the table of the orders side by side and
// the --check verdict.
//
// Design notes
// ------------
// * Every line the example prints is formatted here, from figures the run
//   has kept (StepRecord, RunSummary) and the step has returned
//   (StepFigures), so that the simulation's files hold no format strings
//   and the output can be read in one place.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <collide/schedule.hpp>
#include <collide/solve.hpp>

#include "frame.hpp"
#include "options.hpp"
#include "world.hpp"

namespace debris {

/// One step as the picture shows it.
struct StepRecord {
  double t;
  Energy e;
  std::size_t contacts, ground, resolved;
};

/// What a run leaves for the comparison of the orders and for --check.
struct RunSummary {
  collide::Order order = collide::Order::input;
  std::string iteration = "repeat";  // Options::iteration of the run
  bool warm_start = false;
  int passes = 1;
  double e0 = 0, e_end = 0, max_total = 0, lifted = 0, max_excess = 0;
  std::size_t max_contacts = 0, max_resolved = 0, final_contacts = 0;
  double final_max_depth = 0, final_mean_depth = 0;  // [m] the resting pile's overlaps after the last step
  double solve_seconds = 0, wall = 0;
  std::size_t solved_contacts = 0;
  collide::SolveStats stats;
};

/// The run's title and the per-step table's header.
void print_run_header(const Options& o, collide::Order order);

/// One row of the per-step table: step `step`, `record` and the step's
/// figures, the schedule's conflicts and the step's wall time [ms].
void print_step_row(int step, const StepRecord& record, const StepFigures& figures, std::size_t conflicts, double ms);

/// The run's last lines: steps, contacts and solve rate, and the energy.
void print_run_summary(const Options& o, const RunSummary& r);

/// Draws the picture of a run into `png` with gnuplot, unless `png` is
/// empty, and says so; exits with status 1 when gnuplot cannot.
void write_picture(const std::string& png, const std::vector<StepRecord>& history, const World& w);

/// The orders run, side by side.
void print_orders(const std::vector<RunSummary>& runs);

/// --check: whether every run kept its energy bounded, resolved contacts and
/// left the pile resting; prints what failed, or "check: ok".
bool check(const std::vector<RunSummary>& runs);

}  // namespace debris
