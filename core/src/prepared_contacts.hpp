// prepared_contacts.hpp - the contacts copied into the schedule's order
// before a colour-order solve, and J copied back after it (private to the
// library; solve.cpp).
//
// Design notes
// ------------
// * Why: a colour of a window holds every few contacts of a stretch of the
//   input, so a kernel that reads the caller's arrays through the order
//   loads each of their lines once per colour, as a gather of W lanes per
//   field. Copied in solve order, every batch's contacts are consecutive:
//   the kernel loads each field as one vector (its `contiguous` case) and
//   writes J the same way, and the copies themselves are two streaming
//   passes, shared by every pass of SolverOptions::passes. Box2D stores its
//   contact constraints per colour for the same reason (constraint_graph.c);
//   Bepu prepares them into bundles per batch (TypeBatch).
// * What: a, b, the point (when the model reads it), n, e (unless uniform),
//   mu (with friction) and J, one array each, in the order's positions;
//   and `identity` (0, 1, 2, ...), the order of the prepared arrays, for the
//   paths that walk an order (a run of tiny batches). In float that is at
//   most 56 bytes a contact; the arrays grow to the largest solve and are
//   kept, and each is written in full by the prepare before anything reads
//   it (ScratchVector leaves new elements uninitialised).
// * When: allocate() sizes the arrays and touches the pages of those that
//   grew, on the solve's threads, before the solve's kernels run (the
//   Solver's allocate phase, first_touch.hpp); prepare() then only copies.
// * With several passes (fast mode, frictionless), the velocity-free half of
//   the law of every contact (GeometryView: offsets, lever arms, K terms,
//   inverse masses; 64 bytes a contact in float) is formed by the prepare,
//   each part right after its copy while it is in cache, and every pass takes
//   the velocity step alone (KernelJob::stepped), as Jolt's
//   CalculateConstraintProperties serves every velocity iteration. A pass
//   then reads the velocities and the stored half instead of positions,
//   orientations and inertias, and skips the rotations and the lever arms:
//   120 bytes a contact of scratch in float, against the 56 of one pass.
// * The bits: the law reads the same values in the same sequence, so the
//   result is the same as through the order (tests/core/test_colour_order.cpp
//   holds every path to the sequential law).
#pragma once

#include <cstddef>
#include <cstdint>

#include <oneapi/tbb/task_arena.h>

#include "collide/contacts.hpp"
#include "kernel_table.hpp"
#include "scratch_vector.hpp"

namespace collide::detail {

template <class T>
class PreparedContacts {
 public:
  /// Sizes the arrays a prepare of `job` uses to its contact count (with
  /// `geometry`, those of the velocity-free half too) and touches the pages
  /// of every array that had to grow, on the threads of `arena`; writes the
  /// identity order when it grew. Returns whether anything grew: nothing is
  /// allocated when the count is within every count before.
  bool allocate(tbb::task_arena& arena, const KernelJob<T>& job, bool geometry);

  /// Copies the job's contacts order[0], order[1], ... (contacts.count of
  /// them) into the prepared arrays, on the threads of `arena`; with `form`
  /// (the run geometry kernel of the solve's ISA), forms their geometry too,
  /// from the job's bodies. Returns the job on the prepared arrays: their
  /// contacts and J, the identity order, and with `form` the geometry
  /// (KernelJob::stepped). allocate() must have sized the arrays for the
  /// job (with geometry when `form` is given); nothing is allocated here.
  KernelJob<T> prepare(tbb::task_arena& arena, const KernelJob<T>& job, RunGeometryKernel<T> form = nullptr);

  /// J of position i to impulses[order[i]], for every prepared contact.
  void write_back(tbb::task_arena& arena, const ImpulseView<T>& impulses, const std::uint32_t* order) const;

 private:
  ScratchVector<BodyIndex> a_, b_;
  ScratchVector<T> c_[3], n_[3], e_, mu_, j_[3];
  ScratchVector<std::uint32_t> identity_;
  ScratchVector<T> geometry_[16];
  ImpulseView<T> impulses_;
};

extern template class PreparedContacts<float>;
extern template class PreparedContacts<double>;

}  // namespace collide::detail
