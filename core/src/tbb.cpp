// tbb.cpp - make_solver of collide/tbb.hpp: a Solver in the caller's arena.
#include "collide/tbb.hpp"

namespace collide {

Solver make_solver(tbb::task_arena& arena, const SolverOptions& options) {
  return Solver(ExternalArena{arena}, options);
}

}  // namespace collide
