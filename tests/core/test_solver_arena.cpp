// test_solver_arena.cpp - a Solver can run in the caller's tbb::task_arena
// (collide/tbb.hpp) and reports the schedule's statistics.
//
// What it proves: a solver borrowing an arena gives bitwise the results of a
// solver owning one (threads never change a bit), reports the arena's
// concurrency, refuses a thread count of its own, leaves the arena usable by
// the caller, and SolveStats carries the schedule's batches, largest batch and
// conflicts.
#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include <oneapi/tbb/task_arena.h>

#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/tbb.hpp"
#include "support/scenes.hpp"

namespace collide {
namespace {

TEST(SolverArena, BorrowedArenaMatchesOwnedBitwise) {
  test::SceneOptions o;
  o.seed = 7;
  o.friction = true;
  auto scene = test::shared_scene<float>(40000, 9000, o);
  auto copy = scene;
  Schedule schedule;
  schedule.build(scene.contacts.view(), scene.bodies.view());

  ImpulseBuffer<float> owned_j(scene.contacts.size()), borrowed_j(scene.contacts.size());
  SolverOptions small_blocks;
  small_blocks.block = 64;  // many parallel blocks even in small batches
  const SolveStats owned =
      Solver(small_blocks).solve(scene.bodies.view(), scene.contacts.view(), owned_j.view(), schedule);

  tbb::task_arena arena(2);
  const Solver solver = make_solver(arena, small_blocks);
  const SolveStats borrowed = solver.solve(copy.bodies.view(), copy.contacts.view(), borrowed_j.view(), schedule);

  EXPECT_EQ(borrowed.threads, arena.max_concurrency());
  EXPECT_EQ(owned.batches, borrowed.batches);
  EXPECT_EQ(0, std::memcmp(owned_j.view().j.x, borrowed_j.view().j.x, sizeof(float) * scene.contacts.size()));
  EXPECT_EQ(0, std::memcmp(scene.bodies.view().v.z, copy.bodies.view().v.z, sizeof(float) * scene.bodies.size()));
  EXPECT_EQ(borrowed.batches, schedule.batch_count());
  EXPECT_EQ(borrowed.largest_batch, schedule.largest_batch());
  EXPECT_EQ(borrowed.conflicts, schedule.conflicts());
  EXPECT_GT(borrowed.conflicts, 0u);

  int ran = 0;
  arena.execute([&] { ran = 1; });  // the caller's arena is still the caller's
  EXPECT_EQ(ran, 1);
}

TEST(SolverArena, RefusesAThreadCountOfItsOwn) {
  tbb::task_arena arena(2);
  SolverOptions options;
  options.threads = 4;
  EXPECT_THROW(make_solver(arena, options), std::invalid_argument);
}

TEST(SolverArena, SolverMovesWithItsArena) {
  tbb::task_arena arena(1);
  Solver a = make_solver(arena);
  Solver b = std::move(a);
  EXPECT_EQ(b.options().threads, 0);
}

}  // namespace
}  // namespace collide
