// bench/packed_twin.hpp - the memory-only twin of a packed solve on a
// scattered scene (issue 11): the ceiling of the packed layout with the
// debris index pattern.
//
// It does what Solver::solve does on the caller's packed records, minus the
// law: the contacts are copied into schedule order (the same
// OrderedContacts pass), the batches run one after another with blocks of
// 1024 contacts over TBB, each contact's two records are prefetched the same
// distance ahead, every value of both records and of the contact is read,
// v and w of the movable bodies and J are written (one add of a multiple of zero
// per value instead of the law), and J goes back into input order. Kernel
// throughput over twin throughput is the fraction of the layout's own
// ceiling that the arithmetic leaves.
#pragma once

#include <oneapi/tbb/task_arena.h>

#include "collide/contacts.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"

namespace collide_bench {

/// One twin pass over rigid records in `arena`; `schedule` was built for the
/// contacts. Values keep their bits unless an input is inf or NaN.
template <class T>
void packed_twin_pass(oneapi::tbb::task_arena& arena, const collide::PackedView<collide::PackedRigid<T>>& records,
                      const collide::ContactView<T>& contacts, const collide::ImpulseView<T>& impulses,
                      const collide::Schedule& schedule);

}  // namespace collide_bench
