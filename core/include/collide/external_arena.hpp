// collide/external_arena.hpp - a caller's tbb::task_arena, as a Solver
// borrows it (Solver(const ExternalArena&, ...) in collide/solve.hpp;
// collide::make_solver in collide/tbb.hpp builds the Solver from the arena
// alone). Like tbb.hpp it needs TBB's headers, which the rest of the public
// API does not.
#pragma once

#include <oneapi/tbb/task_arena.h>

namespace collide {

/// A caller's arena, borrowed by a Solver (see Solver(const ExternalArena&, ...)).
struct ExternalArena {
  tbb::task_arena& arena;
};

}  // namespace collide
