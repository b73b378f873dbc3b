// collide/tbb.hpp - running collide in the caller's tbb::task_arena.
//
// The rest of the public API is TBB-free, so that a program that only hands
// over arrays needs no TBB headers. A program that already schedules its own
// work with TBB includes this header to make the solver use its arena: the
// solver's parallel loops then share the caller's threads and limits instead
// of a second pool. Include it only if you compile against TBB and link
// TBB::tbb yourself.
#pragma once

#include <oneapi/tbb/task_arena.h>

#include "collide/external_arena.hpp"
#include "collide/solve.hpp"

namespace collide {

/// A solver that runs in `arena`, which must outlive it. options.threads must
/// be 0: the arena decides the concurrency. Results do not depend on it.
Solver make_solver(tbb::task_arena& arena, const SolverOptions& options = {});

}  // namespace collide
