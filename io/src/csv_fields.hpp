// csv_fields.hpp - the text of one CSV field (private to the library): the
// readers' field splitting, trimming and number parsing, and the writers'
// number formatting.
//
// Design notes
// ------------
// * Numbers are read with std::from_chars (correctly rounded, locale-free,
//   accepts inf, infinity and nan case-insensitively) as doubles, whatever
//   the precision: the scene's value is the double nearest the text, and a
//   float reader stores the float nearest that double (scene_value,
//   collide/io/scene_values.hpp), as every other route does. A leading '+'
//   is allowed. Text beyond the range of double is an error; text that
//   underflows rounds to a subnormal or zero (strtod semantics). A double
//   with no value in T (scene_value_fits) is refused with the reason every
//   route gives for it.
// * Two readers of a field, as the row readers have two paths
//   (csv_read.cpp): fast_numbers for plain numbers, inlined into the row
//   loop, and parse_value / parse_body_id, which trim, take a '+' and form
//   the reason of a refused field. Both accept exactly the same values.
// * Numbers are written with std::to_chars: the shortest text that reads
//   back to the same T as the readers read it, the double nearest the text
//   rounded to T ("inf" for infinity). That is the shortest round-trip
//   text of T, but for one float (put_number).
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

#include "collide/io/scene_io.hpp"
#include "collide/io/scene_values.hpp"

namespace collide::detail {

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// The field without leading blanks and trailing blanks and CRs.
inline std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// The field text as quoted in a message, shortened if long.
std::string quoted(std::string_view field);

/// Walks the comma-separated fields of one line.
class FieldCursor {
 public:
  FieldCursor(const char* begin, const char* end) : p_(begin), end_(end) {}
  /// The next field; false when the line has no more fields.
  bool next(std::string_view& field) {
    if (done_) return false;
    const auto* comma = static_cast<const char*>(std::memchr(p_, ',', static_cast<std::size_t>(end_ - p_)));
    if (comma == nullptr) {
      field = std::string_view(p_, static_cast<std::size_t>(end_ - p_));
      done_ = true;
    } else {
      field = std::string_view(p_, static_cast<std::size_t>(comma - p_));
      p_ = comma + 1;
    }
    return true;
  }
  [[nodiscard]] bool done() const { return done_; }

 private:
  const char* p_;
  const char* end_;
  bool done_ = false;
};

/// Parses a real: the double nearest the text, stored in T as scene_value
/// gives it. The reader's own checks (the field is a number within the
/// range of double, whose value fits T), else false with the reason. The
/// value rules are rules.hpp's. For float and double.
template <class T>
bool parse_value(std::string_view field, T& value, std::string& reason);

/// Parses a body id: a non-negative integer that fits BodyIndex, else false
/// with the reason. Whether it is below the body count is a rule
/// (rules.hpp), checked with the row; an id too large for BodyIndex gets
/// that rule's message here.
bool parse_body_id(std::string_view field, std::size_t body_count, BodyIndex& id, std::string& reason);

/// Reads N plain comma-separated numbers filling the whole of [p, e): no
/// blanks, no '+', nothing out of range. False on anything else, which the
/// careful path then parses or rejects with a message. Each number as
/// parse_value stores it: the double, then scene_value.
template <std::size_t N, class T>
bool fast_numbers(const char* p, const char* e, T* out) {
  for (std::size_t k = 0; k < N; ++k) {
    std::from_chars_result r;
    if constexpr (std::is_same_v<T, double>) {
      r = std::from_chars(p, e, out[k]);  // its own scene value, parsed in place
      if (r.ec != std::errc()) return false;
    } else {
      double x;
      r = std::from_chars(p, e, x);
      if (r.ec != std::errc() || !scene_value_fits<T>(x)) return false;
      out[k] = scene_value<T>(x);
    }
    const char* const ptr = r.ptr;
    if (k + 1 < N) {
      if (ptr == e || *ptr != ',') return false;
      p = ptr + 1;
    } else if (ptr != e) {
      return false;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

/// Upper bound on the characters of one number (double: 24, float: 15).
inline constexpr std::size_t kMaxNumberChars = 26;
/// Upper bound on the characters of one body id (2^32 - 1: 10).
inline constexpr std::size_t kMaxIdChars = 12;

/// The bits of the one positive float whose shortest text does not read
/// back to it as a scene value: the double nearest "7.038531e-26" is
/// within half a double's spacing of the midpoint above the float, so it
/// rounds to that midpoint and then, ties to even, to the float above.
/// Every other finite float's shortest text does read back (all 2^31
/// positive ones were tried: to_chars, then from_chars as a double, then
/// static_cast<float>).
inline constexpr std::uint32_t kFloatWhoseShortestTextMisreads = 0x15AE43FD;

/// Writes `value` at p (room for kMaxNumberChars) and returns the end: the
/// shortest text that reads back to the same T as a scene value (double,
/// then T: scene_values.hpp), which is the shortest round-trip text of T
/// for every value but 7.038531e-26 in float, written with one digit more.
template <class T>
inline char* put_number(char* p, T value) {
  if constexpr (std::is_same_v<T, float>) {
    std::uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    if ((bits & 0x7FFFFFFFU) == kFloatWhoseShortestTextMisreads) {
      return std::to_chars(p, p + kMaxNumberChars, value, std::chars_format::scientific, 7).ptr;  // 7.0385307e-26
    }
  }
  // Shortest round trip; to_chars writes inf as "inf" already.
  return std::to_chars(p, p + kMaxNumberChars, value).ptr;
}

}  // namespace collide::detail
