// iteration_scratch.hpp - what a solve of several passes keeps between them
// (private to the library; solve.cpp): the totals of the accumulated passes
// (Iteration::accumulate) and J as it stood before the last pass, from which
// the residual is measured (SolveStats::residual).
//
// Design notes
// ------------
// * The totals are indexed as the job's J is (the caller's contact index, or
//   the prepared position in a colour-order solve), so the kernels read and
//   write them with the same loads as J.
// * Like the solver's other scratch, the arrays grow to the largest solve and
//   are kept; allocate() touches the pages of what grew on the solve's
//   threads (first_touch.hpp), in the solve's allocate phase, so the passes
//   pay no page faults. Every element is written before it is read: the
//   first pass writes the totals (or warm() does), save() the copy of J.
// * A warm start's J is checked where it is turned into totals, in the
//   solve's order of positions but reported by the smallest contact index,
//   so the message does not depend on how the threads split the work.
// * The residual is a maximum over contacts, which is exact and does not
//   depend on how the contacts are split among threads.
#pragma once

#include <cstddef>
#include <cstdint>

#include <oneapi/tbb/task_arena.h>

#include "collide/contacts.hpp"
#include "kernel_table.hpp"
#include "scratch_vector.hpp"

namespace collide::detail {

template <class T>
class IterationScratch {
 public:
  /// Sizes the arrays a solve of `contacts` contacts uses: the totals when
  /// `totals` (their friction part with `friction`), the copy of J when
  /// `residual`; touches the pages of what grew on the threads of `arena`.
  /// Returns whether anything grew.
  bool allocate(tbb::task_arena& arena, std::size_t contacts, bool totals, bool friction, bool residual);

  /// The totals' arrays (allocate(..., totals = true, ...) sized them).
  [[nodiscard]] AccumulatedView<T> totals(bool friction);

  /// The totals of a warm start (SolverOptions::warm_start) from the J the
  /// caller's impulse arrays hold, and, with `save`, that J as the copy the
  /// residual is measured from: at position p, contact order[p] (the
  /// prepared contacts of a colour-order solve), or contact p when `order`
  /// is null. Throws std::invalid_argument naming the first contact (by
  /// index) whose J is not finite or pulls its bodies together (J . n < 0
  /// beyond rounding). allocate(..., totals = true, ..., residual = save)
  /// sized the arrays.
  void warm(tbb::task_arena& arena, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
            const std::uint32_t* order, bool friction, bool save);

  /// Copies J (impulses.count values) before the last pass.
  void save(tbb::task_arena& arena, const ImpulseView<T>& impulses);

  /// max |J - J saved| over max |J| (0 when every J is 0).
  [[nodiscard]] double residual(tbb::task_arena& arena, const ImpulseView<T>& impulses) const;

 private:
  ScratchVector<T> normal_, target_, friction_[3], saved_[3];
};

extern template class IterationScratch<float>;
extern template class IterationScratch<double>;

}  // namespace collide::detail
