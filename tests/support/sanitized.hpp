// support/sanitized.hpp - whether the test runs under a sanitizer (ASan,
// UBSan with ASan, TSan: scripts/ci-sanitizers.sh), and the scene size a
// sweep of many solves uses there.
//
// A sanitized run looks for memory errors, undefined behaviour and races: a
// wrong index, a lane past an array's end, an unsynchronised write. Those
// live in the code paths a scene takes (its batches, chunks, threads and
// tails), not in how many contacts take them, so the sweeps that repeat a
// solve over every path, thread count and layout run a smaller scene of the
// same kind there, and the Release stage runs the full one. A test whose
// point is the size itself (a window boundary, a batch over a threshold)
// keeps its size everywhere.
#pragma once

#include <cstddef>

namespace collide::test {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

/// The contacts of a sweep's scene: `full`, or a quarter of it under the
/// sanitizers.
constexpr std::size_t sweep_contacts(std::size_t full) { return kSanitized ? full / 4 : full; }

}  // namespace collide::test
