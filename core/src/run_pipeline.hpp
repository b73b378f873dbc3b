// run_pipeline.hpp - a run of one-contact batches (a chain, a stack) on two
// threads: one forms the geometry of the pieces ahead while the other walks
// the contacts in order.
//
// Design notes
// ------------
// * A run is applied contact after contact (kernel_isa.cpp, solve_run): each
//   contact reads the velocities the one before left, one dependency chain
//   that no lane and no thread can share. But most of a contact's
//   arithmetic does not depend on velocities: its offsets, lever arms and K
//   terms (the whole of the rigid float kernel's double-lane work), which
//   solve_run forms piece by piece in lanes before walking the piece. Here a
//   helper thread forms them for the pieces ahead, so the walking thread
//   does the walk alone.
// * The pieces sit in kSlots slots, each stamped with the number of the
//   piece it holds once its geometry is complete (release; the walker
//   acquires). A piece is claimed by whoever takes it first from one
//   counter: the helper, at most kSlots pieces ahead of the walk (it waits
//   for the walk to free a slot), or the walker itself when it reaches a
//   piece nobody has claimed. So the walker never waits for a piece that is
//   not being formed.
// * The calling thread walks; the helper is a task another thread of the
//   arena may take (tbb::task_group). If none does, the calling thread runs
//   it after the walk, when every piece is claimed and it returns at once.
//   So the helper waits for the walk only while the walk runs on another
//   thread, nothing can deadlock, and the walk ends whether the helper runs
//   at once, late or never (an arena thread busy elsewhere).
// * The same geometry and the same walk as solve_run, in the same order for
//   every contact: the same bits on one thread or two.
// * SoA layouts only: the geometry reads positions, orientations and inverse
//   masses, never the velocities the walk writes (a packed record holds
//   both, so packed runs stay on one thread).
#pragma once

#include <oneapi/tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <thread>

#include "kernel_table.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace collide::detail {

/// Pieces in flight between the helper and the walker: enough for the helper
/// to stay ahead, few enough (32 KiB in float) to stay in L1 and L2.
inline constexpr std::size_t kRunSlots = 4;

/// Runs of at least this many pieces are worth a second thread.
inline constexpr std::size_t kPipelinedRunPieces = 4;

/// One step of a spin-wait.
inline void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

/// Resolves order[begin, end) as solve_run does, with the pieces' geometry
/// formed on a second thread of the calling arena where one is free.
/// Preconditions: fast mode, no friction, a SoA body layout.
template <class T>
void run_pipelined(RunGeometryKernel<T> geometry, RunWalkKernel<T> walk, const KernelJob<T>& job, std::size_t begin,
                   std::size_t end) {
  struct Slot {
    RunPiece<T> piece;
    std::atomic<std::size_t> holds{0};  // 1 + the piece whose geometry is complete here
  };
  const std::size_t pieces = (end - begin + kRunPiece - 1) / kRunPiece;
  std::array<Slot, kRunSlots> slots;
  std::atomic<std::size_t> claimed{0};  // pieces taken by the helper or the walker, in order
  std::atomic<std::size_t> walked{0};   // pieces the walk is done with
  const auto first_of = [&](std::size_t i) { return begin + i * kRunPiece; };
  const auto count_of = [&](std::size_t i) { return std::min(kRunPiece, end - first_of(i)); };
  const auto form = [&](std::size_t i) {
    Slot& slot = slots[i % kRunSlots];
    geometry(job, first_of(i), count_of(i), slot.piece);
    slot.holds.store(i + 1, std::memory_order_release);
  };
  const auto walker = [&] {
    for (std::size_t i = 0; i < pieces; ++i) {
      std::size_t unclaimed = i;
      if (claimed.compare_exchange_strong(unclaimed, i + 1, std::memory_order_relaxed)) {
        form(i);
      } else {
        while (slots[i % kRunSlots].holds.load(std::memory_order_acquire) != i + 1) spin_pause();
      }
      walk(job, first_of(i), count_of(i), slots[i % kRunSlots].piece);
      // Release: the walk's reads of the slot come before the helper refills it.
      walked.store(i + 1, std::memory_order_release);
    }
  };
  const auto helper = [&] {
    for (;;) {
      std::size_t i = claimed.load(std::memory_order_relaxed);
      if (i >= pieces) return;
      const std::size_t done = walked.load(std::memory_order_acquire);
      if (i >= done + kRunSlots) {
        // The slot of piece i still holds one the walk has not finished;
        // the walk runs on the calling thread meanwhile.
        spin_pause();
        continue;
      }
      if (claimed.compare_exchange_weak(i, i + 1, std::memory_order_relaxed)) form(i);
    }
  };
  tbb::task_group group;
  group.run(helper);
  walker();
  group.wait();
}

}  // namespace collide::detail
