// bench/memory_twin.hpp - the memory-only twin of a body model's kernel.
//
// Design notes
// ------------
// The triad streams three arrays. A body model's kernel streams many more:
// on the pairs scene the rigid model reads 17 body arrays, 9 contact arrays
// (the two indices, c, n, e; 10 with mu) and writes 6 body arrays and 3
// impulse arrays, all at once. On the CPUs measured, a core's bandwidth falls with
// the number of concurrent streams (the prefetchers follow a limited number
// of them), so the triad overstates what any kernel with this data layout can
// reach. The twin measures that directly: the same arrays, visited in the
// same blocks and groups as the SIMD kernel visits them (one group = one
// vector of contacts, their 2W bodies; blocks of 1024 contacts over TBB,
// like collide::Solver), with the kernel's own vector loads and stores
// (lanes.hpp) and one add per value instead of the law. Every array is
// swept over the same range (the two index arrays through one value per
// group: their cache lines are what costs) and the written arrays are
// written once. What it moves
// per collision is the model's bytes per collision (collide/eval/traffic.hpp), so
// kernel GB/s over twin GB/s is the fraction of the layout's own ceiling that
// the arithmetic leaves.
//
// Pairs layout only (contact k joins bodies 2k and 2k + 1, as generate_pairs
// builds it): a debris twin would have to gather, and would measure the
// random-access rate the debris rows already show.
#pragma once

#include <oneapi/tbb/task_arena.h>

#include <cstddef>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/model.hpp"

namespace collide_bench {

/// Makes one twin pass over the arrays `model` reads and writes (mu too when
/// `contacts.mu` is set) on the threads of `arena`. Adds a multiple of zero
/// to every written value: v, w and J keep their values unless an input is
/// inf or NaN. Precondition: the pairs layout.
template <class T>
void memory_twin_pass(collide::Model model, oneapi::tbb::task_arena& arena, const collide::BodyView<T>& bodies,
                      const collide::ContactView<T>& contacts, const collide::ImpulseView<T>& impulses);

}  // namespace collide_bench
