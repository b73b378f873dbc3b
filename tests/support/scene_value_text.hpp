// support/scene_value_text.hpp - decimal text for scene values where the two
// roundings part: the float nearest the text against the float nearest the
// double nearest the text (docs/collision-law.md, "Scene values"). The route
// tests (tests/io/test_scene_routes.cpp) and fuzz/fuzz_routes.cpp draw
// scenes of such text.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

namespace collide::test {

/// How a value near a float f is written.
enum class ValueText : std::uint8_t {
  float_shortest,     ///< the shortest text of f: both roundings give f
  float_long,         ///< f with 17 significant digits: not its shortest form, still f
  midpoint_shortest,  ///< the shortest text of the double halfway from f to the next float up
  above_midpoint,     ///< 40 digits a quarter of a double's spacing above that halfway point
  below_midpoint,     ///< 40 digits a quarter of a double's spacing below it
  kCount
};

/// The next float up from f (towards +inf); f itself at the top.
inline float next_float_up(float f) { return std::nextafter(f, std::numeric_limits<float>::infinity()); }

/// The double halfway from f to the next float up (exact: a double holds
/// every such midpoint).
inline double float_midpoint(float f) { return (static_cast<double>(f) + static_cast<double>(next_float_up(f))) / 2; }

/// `value` with `digits` significant digits, correctly rounded.
inline std::string digits_text(long double value, int digits) {
  char buf[128];
  const auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::scientific, digits - 1);
  return std::string(buf, r.ptr);
}

/// The shortest text of a double or float (what collide's writers write).
template <class T>
std::string shortest_text(T value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, r.ptr);
}

/// Text of kind `kind` for a value near the finite float f (below the
/// largest float for the midpoint kinds).
inline std::string value_text(float f, ValueText kind) {
  const double m = float_midpoint(f);
  // A quarter of the double spacing at m, in long double (64-bit
  // significand): m plus or minus it is nearest to m among doubles.
  const long double quarter =
      (static_cast<long double>(std::nextafter(m, std::numeric_limits<double>::infinity())) - m) / 4;
  switch (kind) {
    case ValueText::float_shortest:
      return shortest_text(f);
    case ValueText::float_long:
      return digits_text(static_cast<long double>(f), 17);
    case ValueText::midpoint_shortest:
      return shortest_text(m);
    case ValueText::above_midpoint:
      return digits_text(static_cast<long double>(m) + quarter, 40);
    case ValueText::below_midpoint:
      return digits_text(static_cast<long double>(m) - quarter, 40);
    case ValueText::kCount:
      break;
  }
  return shortest_text(f);
}

/// Whether the float nearest `text` and the float nearest its double differ
/// (strtof and strtod are correctly rounded).
inline bool roundings_part(const std::string& text) {
  const float direct = std::strtof(text.c_str(), nullptr);
  const float via_double = static_cast<float>(std::strtod(text.c_str(), nullptr));
  return std::memcmp(&direct, &via_double, sizeof(float)) != 0;
}

}  // namespace collide::test
