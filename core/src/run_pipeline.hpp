// run_pipeline.hpp - a run of one-contact batches (a chain, a stack) on two
// threads: one walks the contacts in order while the other forms the
// geometry of the pieces ahead.
//
// Design notes
// ------------
// * A run is applied contact after contact (kernel/loops.hpp, run_loop): each
//   contact reads the velocities the one before left, one dependency chain
//   that no lane and no thread can share. But most of a contact's
//   arithmetic does not depend on velocities: its offsets, lever arms and K
//   terms (the whole of the rigid float kernel's double-lane work), which
//   run_loop forms piece by piece in lanes before walking the piece. Here a
//   helper thread forms them for the pieces ahead, so the walking thread
//   does the walk alone.
// * The pieces sit in kSlots slots, each stamped with the number of the
//   piece it holds once its geometry is complete (release; the walker
//   acquires). A piece is claimed by whoever takes it first from one
//   counter: the helper, at most kSlots pieces ahead of the walk (it waits
//   for the walk to free a slot), or the walker itself when it reaches a
//   piece nobody has claimed. So the walker never waits for a piece that is
//   not being formed.
// * One thread walks; the others, waiting for the run to end (the schedule
//   walk, run_schedule.cpp), help. A helper waits for the walk only while
//   the walk runs on another thread, nothing can deadlock, and the walk ends
//   whether a helper comes at once, late or never.
// * The same geometry and the same walk as run_loop, in the same order for
//   every contact: the same bits on one thread or two.
// * SoA layouts only: the geometry reads positions, orientations and inverse
//   masses, never the velocities the walk writes (a packed record holds
//   both, so packed runs stay on one thread).
#pragma once

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

/// A wait for another thread of the solve: a few microseconds of pauses,
/// the time a hand-over between two running threads takes, then a yield of
/// the processor at every step, so that on a machine with more threads
/// running than cores the thread waited for gets the core instead of the
/// waiting one spinning through its time slice.
class SpinWait {
 public:
  void pause() {
    if (spins_ < kSpins) {
      ++spins_;
#if defined(__x86_64__) || defined(__i386__)
      _mm_pause();
#endif
    } else {
      std::this_thread::yield();
    }
  }

 private:
  static constexpr int kSpins = 256;
  int spins_ = 0;
};

/// A run of contacts order[begin, end) resolved as run_loop does, its
/// pieces' geometry formed by whichever threads call help() while one thread
/// calls walk(). Preconditions: fast mode, no friction, a SoA body layout.
template <class T>
class PipelinedRun {
 public:
  PipelinedRun(RunGeometryKernel<T> geometry, RunWalkKernel<T> walk, const KernelJob<T>& job, std::size_t begin,
               std::size_t end)
      : geometry_(geometry),
        walk_(walk),
        job_(job),
        begin_(begin),
        end_(end),
        pieces_((end - begin + kRunPiece - 1) / kRunPiece) {}

  /// The walk, on the calling thread: every piece in order, forming those
  /// no helper has claimed. Returns when the run is resolved.
  void walk() {
    for (std::size_t i = 0; i < pieces_; ++i) {
      std::size_t unclaimed = i;
      if (claimed_.compare_exchange_strong(unclaimed, i + 1, std::memory_order_relaxed)) {
        form(i);
      } else {
        SpinWait wait;
        while (slots_[i % kRunSlots].holds.load(std::memory_order_acquire) != i + 1) wait.pause();
      }
      walk_(job_, first_of(i), count_of(i), slots_[i % kRunSlots].piece.view());
      // Release: the walk's reads of the slot come before a helper refills it.
      walked_.store(i + 1, std::memory_order_release);
    }
  }

  /// Forms pieces ahead of the walk, at most kRunSlots ahead of it; returns
  /// once every piece is claimed (by a helper or the walker).
  void help() {
    SpinWait wait;
    for (;;) {
      std::size_t i = claimed_.load(std::memory_order_relaxed);
      if (i >= pieces_) return;
      const std::size_t done = walked_.load(std::memory_order_acquire);
      if (i >= done + kRunSlots) {
        // The slot of piece i still holds one the walk has not finished.
        wait.pause();
        continue;
      }
      if (claimed_.compare_exchange_weak(i, i + 1, std::memory_order_relaxed)) form(i);
    }
  }

 private:
  struct Slot {
    RunPiece<T> piece;
    std::atomic<std::size_t> holds{0};  // 1 + the piece whose geometry is complete here
  };

  [[nodiscard]] std::size_t first_of(std::size_t i) const { return begin_ + i * kRunPiece; }
  [[nodiscard]] std::size_t count_of(std::size_t i) const { return std::min(kRunPiece, end_ - first_of(i)); }
  void form(std::size_t i) {
    Slot& slot = slots_[i % kRunSlots];
    geometry_(job_, first_of(i), count_of(i), slot.piece.view());
    slot.holds.store(i + 1, std::memory_order_release);
  }

  RunGeometryKernel<T> geometry_;
  RunWalkKernel<T> walk_;
  const KernelJob<T>& job_;
  std::size_t begin_;
  std::size_t end_;
  std::size_t pieces_;
  std::array<Slot, kRunSlots> slots_;
  std::atomic<std::size_t> claimed_{0};  // pieces taken by a helper or the walker, in order
  std::atomic<std::size_t> walked_{0};   // pieces the walk is done with
};

}  // namespace collide::detail
