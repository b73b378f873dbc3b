// one_batch.hpp - whether a scene is one batch, found on every thread
// (private to the library): a scene in which no movable body is in two
// contacts (a scene of independent pairs, one colour of a broadphase) is one
// batch in input order, in either solve order.
//
// Design notes
// ------------
// Instead of a sequential pass, each thread claims the movable bodies of its
// chunk of contacts in a byte table (its chunk's number, 1 to 254), failing
// at the first body it claimed already, and after the join checks that every
// body of its chunk still carries its number: of two chunks that claimed one
// body, the later write stands and the other chunk sees it, in whatever order
// or interleaving the chunks ran. Claims are relaxed atomic bytes; the check
// decides. Any failure (a shared body, a bad index) hands the scene to the
// schedule's own passes, which name the first bad contact; a first look at
// the scene's first contacts on the calling thread (repeated_bodies.hpp)
// turns a pile, a chain or a scattered scene away before the table is
// touched.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "schedule_input.hpp"

namespace collide::detail {

/// Whether no movable body is in two of the contacts, found on up to
/// `workers` threads (one chunk each, or one for a small scene); if so,
/// order[0, count) is the identity. The answer does not depend on
/// `workers`. `table` holds a byte per body; `probe_set` is the first
/// look's scratch.
template <class T>
bool one_batch(const ContactIndices& contacts, const InverseMasses<T>& inv_mass, std::size_t workers,
               std::uint8_t* table, std::uint32_t* order, std::vector<std::uint32_t>& probe_set);

}  // namespace collide::detail
