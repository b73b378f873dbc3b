// run_schedule.cpp - the walk of run_schedule.hpp.
#include "run_schedule.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>

#include <oneapi/tbb/task_group.h>

#include "run_pipeline.hpp"

namespace collide::detail {
namespace {

/// Fewest contacts an item of a split batch gets: a hand-over between
/// threads costs about what the kernel spends on a few dozen contacts.
constexpr std::size_t kMinItem = 64;

/// Most items per thread a batch splits into. Small items would have each
/// thread leap from stretch to stretch of the arrays, and the hardware's
/// stream prefetchers restart at every leap: a few long items per thread
/// stream, and still even out a thread that runs late.
constexpr std::size_t kItemsPerThread = 4;

/// Most items of one step, whatever the thread count (the claim stamps are a
/// fixed array: a walk allocates nothing).
constexpr std::size_t kMaxItems = 256;

/// One step of the walk: batches [first_batch, end_batch) of pass `pass`,
/// which are items [first_item, first_item + items) of the walk.
struct Step {
  std::size_t pass = 0;
  std::size_t first_batch = 0;
  std::size_t end_batch = 0;
  std::uint64_t first_item = 0;
  std::size_t items = 0;  // > 1: one batch split; 1: a serial step
};

template <class T>
class Walk {
 public:
  Walk(const KernelTable& table, const WalkPlan& plan, int threads, const KernelJob<T>& job, const Schedule& schedule)
      : plan_(plan),
        threads_(threads),
        schedule_(schedule),
        kernels_(job_kernels(table, job, plan.simd)),
        first_(job),
        later_(job) {
    // The repeat mode adds each later pass's J; the accumulated passes write
    // J (their totals), the first recording the totals. A walk that
    // continues a solve has no first pass.
    if (job.accumulates()) {
      first_.first_pass = !plan.continues;
      later_.first_pass = false;
    } else {
      later_.accumulate = true;
      first_.accumulate = plan.continues;
    }
  }

  /// What every thread of the walk does, thread `worker` of the arena's:
  /// step after step, once the steps before are done, claims items from its
  /// home forward, then backward, and runs them; returns when all have
  /// finished.
  void work(int worker) {
    Step step;  // the empty step before the first
    while (next_step(step)) {
      wait_for(step.first_item);
      const std::size_t home = static_cast<std::size_t>(worker) * step.items / static_cast<std::size_t>(threads_);
      for (std::size_t i = home; i < step.items && claim(step, i); ++i) run_claimed(step, i);
      for (std::size_t i = home; i-- > 0 && claim(step, i);) run_claimed(step, i);
    }
    wait_for(step.first_item + step.items);
  }

  /// The passes run, once every thread has returned from work().
  [[nodiscard]] std::size_t passes() const {
    return schedule_.batch_count() == 0 ? plan_.passes : passes_.load(std::memory_order_relaxed);
  }

 private:
  [[nodiscard]] std::size_t size(std::size_t k) const {
    return schedule_.batch_begin(k + 1) - schedule_.batch_begin(k);
  }

  /// The items a batch of n contacts splits into: blocks of plan.block
  /// contacts, at most kItemsPerThread per thread, and at least one per
  /// thread once each gets kMinItem.
  [[nodiscard]] std::size_t items_of(std::size_t n) const {
    if (threads_ == 1 || n < 2 * kMinItem) return 1;
    const auto threads = static_cast<std::size_t>(threads_);
    const std::size_t blocks = (n + plan_.block - 1) / plan_.block;
    return std::min(kMaxItems, std::max(std::min(blocks, kItemsPerThread * threads), std::min(threads, n / kMinItem)));
  }

  /// Takes item i of step s for this thread; false if another took it. A
  /// stamp holds one more than the first item number of the step that last
  /// took it, which only grows from step to step.
  bool claim(const Step& s, std::size_t i) {
    const std::uint64_t mine = s.first_item + 1;
    std::uint64_t seen = stamps_[i].load(std::memory_order_relaxed);
    while (seen < mine) {
      if (stamps_[i].compare_exchange_weak(seen, mine, std::memory_order_relaxed)) return true;
    }
    return false;
  }

  void run_claimed(const Step& s, std::size_t i) {
    run_item(s, i);
    finished_.fetch_add(1, std::memory_order_acq_rel);
  }

  /// The step after `s`; false after the last, and at the end of a pass
  /// once the stop flag is set.
  bool next_step(Step& s) {
    std::size_t k = s.end_batch;
    std::size_t pass = s.pass;
    const std::size_t batches = schedule_.batch_count();
    if (k == batches) {
      if (++pass >= plan_.passes || batches == 0 || stopped()) return false;
      started(pass);
      k = 0;
    }
    Step next;
    next.pass = pass;
    next.first_batch = k;
    next.first_item = s.first_item + s.items;
    next.items = items_of(size(k));
    next.end_batch = k + 1;
    if (next.items == 1) {
      while (next.end_batch < batches && items_of(size(next.end_batch)) == 1) ++next.end_batch;
    }
    s = next;
    return true;
  }

  void run_item(const Step& s, std::size_t item) {
    const KernelJob<T>& job = s.pass == 0 ? first_ : later_;
    if (s.items == 1) {
      run_serial(job, s.first_batch, s.end_batch);
      return;
    }
    const std::size_t k = s.first_batch;
    const std::size_t begin = schedule_.batch_begin(k);
    const std::size_t end = schedule_.batch_begin(k + 1);
    const std::size_t w = plan_.width;
    const std::size_t per_item = ((end - begin + s.items - 1) / s.items + w - 1) / w * w;
    const std::size_t b = begin + item * per_item;
    if (b < end) kernels_.range(job, consecutive(k), b, std::min(end, b + per_item));
  }

  [[nodiscard]] bool stopped() const { return plan_.stop != nullptr && plan_.stop->load(std::memory_order_relaxed); }

  /// Counts pass `pass` (from 0) as started: this thread runs it to its end.
  void started(std::size_t pass) {
    std::size_t seen = passes_.load(std::memory_order_relaxed);
    while (seen < pass + 1 && !passes_.compare_exchange_weak(seen, pass + 1, std::memory_order_relaxed)) {
    }
  }

  /// Batch k's contacts are consecutive in the job's arrays.
  [[nodiscard]] bool consecutive(std::size_t k) const { return plan_.prepared || schedule_.batch_is_contiguous(k); }
  /// A contact or a few per batch: shorter than the lanes (SIMD), or every
  /// batch of a serial step (the one-lane kernel walks contacts in order).
  [[nodiscard]] bool runs_alone(std::size_t n) const { return !plan_.simd || n < plan_.width; }

  /// Batches [k, end) in order on this thread. Stretches of batches that
  /// run alone are one run, resolved contact after contact in the
  /// schedule's order (the law's order; the run kernel keeps the one-lane
  /// loop's bits, JobKernels::run in kernel_table.hpp).
  void run_serial(const KernelJob<T>& job, std::size_t k, std::size_t end) {
    while (k < end) {
      const std::size_t begin = schedule_.batch_begin(k);
      std::size_t last = k + 1;
      if (runs_alone(size(k))) {
        while (last < end && runs_alone(size(last))) ++last;
      }
      const std::size_t stop = schedule_.batch_begin(last);
      if (last == k + 1) {
        kernels_.range(job, consecutive(k), begin, stop);
      } else if (!plan_.simd) {
        kernels_.one_lane(job, false, begin, stop);
      } else if (threads_ > 1 && !job.packed() && !job.accurate && !job.friction && !job.stepped &&
                 !job.accumulates() && stop - begin >= kPipelinedRunPieces * kRunPiece) {
        run_pipelined(job, begin, stop);
      } else {
        kernels_.run(job, begin, stop);
      }
      k = last;
    }
  }

  /// A long run, its pieces' geometry formed by the threads waiting for it.
  void run_pipelined(const KernelJob<T>& job, std::size_t begin, std::size_t end) {
    PipelinedRun<T> run(kernels_.geometry, kernels_.walk, job, begin, end);
    run_.store(&run, std::memory_order_seq_cst);
    run.walk();
    run_.store(nullptr, std::memory_order_seq_cst);
    SpinWait wait;
    while (helping_.load(std::memory_order_seq_cst) != 0) wait.pause();
  }

  /// Waits until `items` items have finished, helping a pipelined run meanwhile.
  void wait_for(std::uint64_t items) {
    SpinWait wait;
    while (finished_.load(std::memory_order_acquire) < items) {
      if (run_.load(std::memory_order_relaxed) != nullptr) {
        helping_.fetch_add(1, std::memory_order_seq_cst);
        if (PipelinedRun<T>* run = run_.load(std::memory_order_seq_cst)) run->help();
        helping_.fetch_sub(1, std::memory_order_seq_cst);
      }
      wait.pause();
    }
  }

  const WalkPlan& plan_;
  const int threads_;
  const Schedule& schedule_;
  const JobKernels<T> kernels_;  // the job's loops, looked up once (first_ and later_ differ only in accumulate)
  KernelJob<T> first_;           // the first pass: J written
  KernelJob<T> later_;           // the passes after: J added
  std::array<std::atomic<std::uint64_t>, kMaxItems> stamps_{};
  std::atomic<std::uint64_t> finished_{0};
  std::atomic<std::size_t> passes_{1};  // passes a thread has started (the first is every thread's)
  std::atomic<PipelinedRun<T>*> run_{nullptr};
  std::atomic<int> helping_{0};
};

}  // namespace

template <class T>
std::size_t walk_schedule(const KernelTable& table, const WalkPlan& plan, tbb::task_arena& arena,
                          const KernelJob<T>& job, const Schedule& schedule) {
  return arena.execute([&] {
    const int threads = std::max(1, arena.max_concurrency());
    Walk<T> walk(table, plan, threads, job, schedule);
    if (threads == 1) {
      walk.work(0);
      return walk.passes();
    }
    // The other threads are tasks of the arena: one that starts late finds
    // its items claimed, and one that never starts is run by wait() once
    // every item is done, and returns at once.
    tbb::task_group helpers;
    for (int t = 1; t < threads; ++t) helpers.run([&walk, t] { walk.work(t); });
    walk.work(0);
    helpers.wait();
    return walk.passes();
  });
}

template std::size_t walk_schedule<float>(const KernelTable&, const WalkPlan&, tbb::task_arena&,
                                          const KernelJob<float>&, const Schedule&);
template std::size_t walk_schedule<double>(const KernelTable&, const WalkPlan&, tbb::task_arena&,
                                           const KernelJob<double>&, const Schedule&);

}  // namespace collide::detail
