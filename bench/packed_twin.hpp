// bench/packed_twin.hpp - the memory-only twin of a packed solve on a
// scattered scene: the ceiling of the packed layout with the
// debris index pattern.
//
// It does what Solver::solve does on the caller's packed records, minus the
// law: the batches run one after another with blocks of 1024 contacts over
// TBB, each contact is read through the schedule's order with its own lines
// prefetched twice as far ahead as its two records (as the kernel does),
// every value of both records (as 16-byte rows; a rigid body's inverse mass
// from the view's array) and of the contact is read, v (and w) of the
// movable bodies and J are written (one add of a multiple of zero per value instead
// of the law). Kernel throughput over twin throughput is the fraction of the
// layout's own ceiling that the arithmetic leaves.
#pragma once

#include <cstddef>

#include <oneapi/tbb/task_arena.h>

#include "collide/contacts.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"

namespace collide_bench {

/// Values of a record the kernel writes: v, and w where the model rotates
/// (collide/packed.hpp).
template <class Record>
inline constexpr std::size_t kWrittenValues = 6;
template <class T>
inline constexpr std::size_t kWrittenValues<collide::PackedParticle<T>> = 3;

/// One twin pass over the records (PackedRigid, PackedSphere or
/// PackedParticle of float or double) in `arena`; `schedule` was built for
/// the contacts. Values keep their bits unless an input is inf or NaN.
template <class Record>
void packed_twin_pass(oneapi::tbb::task_arena& arena, const collide::PackedView<Record>& records,
                      const collide::ContactView<typename collide::PackedValue<Record>::type>& contacts,
                      const collide::ImpulseView<typename collide::PackedValue<Record>::type>& impulses,
                      const collide::Schedule& schedule);

}  // namespace collide_bench
