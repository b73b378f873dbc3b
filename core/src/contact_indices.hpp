// contact_indices.hpp - the check every contact's body indices pass before
// anything reads a body through them (private to the library): both indices
// below the body count and a != b. Schedule::build and validate() run the
// same screen and name the same first bad contact in the same words.
//
// Design notes
// ------------
// The screen is branch-free, so that it vectorises, and compares in 32 bits:
// SSE2 has no unsigned 32-bit compare, so with GCC on x86-64 it is also
// compiled for AVX2 and picked at load time (an ifunc), which has one (its
// gain: docs/decisions/0013-python-call-overhead.md).
// With 2^32 or more bodies its bound is one too strict for index 2^32 - 1,
// which the exact scan (first_bad_contact) then accepts. The scan runs only
// when the screen fails, so the message never depends on the screen.
#pragma once

#include <cstddef>
#include <string>

#include "collide/contacts.hpp"

namespace collide::detail {

/// The bound indices_below() compares with for `body_count` bodies.
BodyIndex index_bound(std::size_t body_count);

/// Whether every contact of [0, count) has both indices < bound and a != b.
bool indices_below(const BodyIndex* a, const BodyIndex* b, std::size_t count, BodyIndex bound);

/// The first contact of [begin, end) with an index >= body_count or a == b,
/// or end when there is none.
std::size_t first_bad_contact(const BodyIndex* a, const BodyIndex* b, std::size_t begin, std::size_t end,
                              std::size_t body_count);

/// What is wrong with contact k, which first_bad_contact found:
/// "contacts.a[17] = 40: out of range (8 bodies)" or
/// "contacts.b[3] = 2: a contact of a body with itself".
std::string bad_contact_message(const BodyIndex* a, const BodyIndex* b, std::size_t k, std::size_t body_count);

/// Throws std::invalid_argument("<where>" + bad_contact_message) for the
/// first bad contact of [begin, end); returns when there is none. Out of line
/// and cold: only a failed screen calls it.
[[gnu::cold]] void throw_first_bad_contact(const char* where, const BodyIndex* a, const BodyIndex* b, std::size_t begin,
                                           std::size_t end, std::size_t body_count);

/// Throws as throw_first_bad_contact unless every contact of [begin, end)
/// passes: the screen, then the scan only if it failed.
inline void check_contact_indices(const char* where, const BodyIndex* a, const BodyIndex* b, std::size_t begin,
                                  std::size_t end, std::size_t body_count) {
  if (__builtin_expect(!indices_below(a + begin, b + begin, end - begin, index_bound(body_count)), 0)) {
    throw_first_bad_contact(where, a, b, begin, end, body_count);
  }
}

}  // namespace collide::detail
