// bench/timing_check.hpp - collide_bench --timing-check: every instrument of
// collide timing the same solve, and whether they agree (timing_check.cpp).
#pragma once

#include <ostream>

#include "options.hpp"

namespace collide_bench {

/// For each scene of `options.scenes` (float, rigid, frictionless, the SIMD
/// path on collide::default_isa() at 2 threads, seed 1) measures the median
/// seconds of one solve four ways, or five for pairs:
///   * the report's kernel row (collide::measure_kernel_speed);
///   * the report's N sweep at that N (collide::measure_sweep_report; pairs only);
///   * collide_bench's row isa/<scene>/f32/<isa>/t:2/n:N (solve_row);
///   * `collide solve --stats` kernel_seconds on the scene written by
///     `collide gen --format npz`, the median of `runs` processes;
/// prints them with the range of the host's 2-thread triad over the rounds,
/// and fails a scene when a figure is further than `tolerance` from the
/// scene's median. Returns the exit status: 0 when every
/// scene passed, 1 otherwise. Google Benchmark must be initialised.
int run_timing_check(const TimingCheckOptions& options, std::ostream& out);

}  // namespace collide_bench
