// run_schedule.hpp - a solve's walk over its schedule: the batches in order,
// each on the threads of the solve's arena, pass after pass (private to the
// library; the driver's, compiled for the baseline).
//
// Design notes
// ------------
// * The walk is data: a sequence of steps that every thread derives from
//   the schedule alone, in the same order. A batch large enough to split is
//   a parallel step of several items (ranges of its contacts, a multiple of
//   the lane width each); a stretch of consecutive batches too small to split
//   is one serial step, run by one thread in the schedule's order with no
//   hand-off between its batches (in it, a stretch of batches smaller than
//   the lanes is a run, resolved contact after contact by the run kernel).
//   Items are numbered across the steps and passes.
// * A stop flag (SolverOptions::stop) is read by each thread as it reaches
//   the end of a pass, once per pass: a thread that reads it set walks no
//   further, and one that read it clear claims every item of the next pass
//   the others leave, so the walk always ends on a whole pass, whichever
//   threads saw the flag when. The walk counts the passes started.
// * The threads of the arena start once per solve and walk the steps
//   together. Before it claims an item of a step, a thread waits until every
//   item of the earlier steps has finished: a counter of finished items,
//   which only ever counts items of steps no later than the earliest
//   unfinished one, so reaching the step's first item number means the
//   steps before are done (Box2D's stage counter, b2ExecuteMainStage, does
//   the same with a stage index). A thread that waits and finds a pipelined
//   run in progress forms its geometry (run_pipeline.hpp) instead of
//   spinning.
// * Each thread has a home among a step's items: thread w of T starts at
//   item w * items / T, claims forward until it meets an item another thread
//   took, then backward from its home (Box2D's b2ExecuteStage and
//   b2GetWorkerStartIndex). The items of every batch are ranges in the same
//   place of the batch, and the colours of a window, and the levels of a
//   pile, each reach the bodies in about the same sequence, so a thread keeps
//   finding the bodies it wrote in its own cache instead of in the other
//   core's; a thread that arrives late takes what its home's neighbours
//   left.
// * Nothing depends on which thread runs what: the contacts of a batch share
//   no movable body, so splitting a batch differently cannot change a bit,
//   and a thread that never arrives (the arena busy elsewhere) leaves its
//   items to the others.
#pragma once

#include <atomic>
#include <cstddef>

#include <oneapi/tbb/task_arena.h>

#include "collide/schedule.hpp"
#include "kernel_table.hpp"

namespace collide::detail {

/// How a solve walks its schedule.
struct WalkPlan {
  bool simd = true;        ///< the SIMD kernels of the table, else the one-lane kernel
  std::size_t width = 1;   ///< lanes of the kernel that runs
  std::size_t block = 1;   ///< contacts per item of a large batch (a multiple of width)
  std::size_t passes = 1;  ///< times the schedule is walked; J is summed over them
  /// Read at the end of each pass but the last; once set, no pass starts
  /// (SolverOptions::stop). Null: every pass runs.
  const std::atomic<bool>* stop = nullptr;
  /// The job's contacts are in the schedule's order (prepared_contacts.hpp):
  /// every batch's contacts are consecutive in its arrays.
  bool prepared = false;
  /// The walk continues a solve whose earlier passes have run: its first
  /// pass is a later one (J added, or the totals moved).
  bool continues = false;
};

/// Resolves every contact of `schedule` `plan.passes` times with `job`'s
/// kernels from `table`, on the threads of `arena`. The first pass writes J,
/// the later ones add to it (or, accumulating, move the totals and write
/// J); with plan.continues every pass is a later one. Returns the passes run: plan.passes, or fewer
/// when plan.stop was set (at least one; plan.passes for an empty schedule).
template <class T>
std::size_t walk_schedule(const KernelTable& table, const WalkPlan& plan, tbb::task_arena& arena,
                          const KernelJob<T>& job, const Schedule& schedule);

extern template std::size_t walk_schedule<float>(const KernelTable&, const WalkPlan&, tbb::task_arena&,
                                                 const KernelJob<float>&, const Schedule&);
extern template std::size_t walk_schedule<double>(const KernelTable&, const WalkPlan&, tbb::task_arena&,
                                                  const KernelJob<double>&, const Schedule&);

}  // namespace collide::detail
