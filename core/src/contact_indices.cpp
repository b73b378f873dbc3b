// contact_indices.cpp - the index screen and scan of contact_indices.hpp.
#include "contact_indices.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace collide::detail {

BodyIndex index_bound(std::size_t body_count) {
  return static_cast<BodyIndex>(std::min<std::size_t>(body_count, std::numeric_limits<BodyIndex>::max()));
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
bool indices_below(const BodyIndex* a, const BodyIndex* b, std::size_t count, BodyIndex bound) {
  std::uint32_t bad = 0;
  for (std::size_t k = 0; k < count; ++k) {
    bad |= static_cast<std::uint32_t>(a[k] >= bound) | static_cast<std::uint32_t>(b[k] >= bound) |
           static_cast<std::uint32_t>(a[k] == b[k]);
  }
  return bad == 0;
}

std::size_t first_bad_contact(const BodyIndex* a, const BodyIndex* b, std::size_t begin, std::size_t end,
                              std::size_t body_count) {
  for (std::size_t k = begin; k < end; ++k) {
    // One branch per contact: all three rules at once.
    if (!(a[k] < body_count && b[k] < body_count && a[k] != b[k])) return k;
  }
  return end;
}

std::string bad_contact_message(const BodyIndex* a, const BodyIndex* b, std::size_t k, std::size_t body_count) {
  const bool a_bad = a[k] >= body_count;
  std::string what = std::string("contacts.") + (a_bad ? "a" : "b") + "[" + std::to_string(k) +
                     "] = " + std::to_string(a_bad ? a[k] : b[k]) + ": ";
  if (a_bad || b[k] >= body_count) return what + "out of range (" + std::to_string(body_count) + " bodies)";
  return what + "a contact of a body with itself";
}

void throw_first_bad_contact(const char* where, const BodyIndex* a, const BodyIndex* b, std::size_t begin,
                             std::size_t end, std::size_t body_count) {
  const std::size_t k = first_bad_contact(a, b, begin, end, body_count);
  if (k != end) throw std::invalid_argument(where + bad_contact_message(a, b, k, body_count));
}

}  // namespace collide::detail
