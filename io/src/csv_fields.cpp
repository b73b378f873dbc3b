// csv_fields.cpp - the careful readers of one CSV field: the ones that
// trim, take a '+' and say what is wrong (the design notes are in
// csv_fields.hpp).
#include "csv_fields.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <system_error>

#include "collide/rules.hpp"

namespace collide::detail {

std::string quoted(std::string_view field) {
  field = trim(field);
  constexpr std::size_t kMax = 40;
  std::string s = "'";
  if (field.size() > kMax) {
    s.append(field.substr(0, kMax));
    s += "...";
  } else {
    s.append(field);
  }
  s += "'";
  return s;
}

namespace {

enum class NumberStatus { ok, empty, syntax, overflow };

/// The double nearest the text of a field.
NumberStatus parse_real(std::string_view field, double& value) {
  field = trim(field);
  if (field.empty()) return NumberStatus::empty;
  const char* first = field.data();
  const char* last = first + field.size();
  // from_chars takes no '+'; a scene file may well have one ("+inf").
  if (*first == '+') {
    ++first;
    if (first == last || *first == '+' || *first == '-') return NumberStatus::syntax;
  }
  const auto [ptr, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ptr != last) return NumberStatus::syntax;
  if (ec == std::errc()) return NumberStatus::ok;
  if (ec != std::errc::result_out_of_range) return NumberStatus::syntax;
  // Out of range: overflow is an error; underflow rounds to a subnormal or
  // zero as strtod does (the rare path, so a copy is fine).
  const std::string copy(first, last);
  errno = 0;
  const double v = std::strtod(copy.c_str(), nullptr);
  if (std::isinf(v)) return NumberStatus::overflow;
  value = v;
  return NumberStatus::ok;
}

}  // namespace

template <class T>
bool parse_value(std::string_view field, T& value, std::string& reason) {
  double x = 0;
  switch (parse_real(field, x)) {
    case NumberStatus::ok:
      break;
    case NumberStatus::empty:
      reason = "empty value";
      return false;
    case NumberStatus::syntax:
      reason = "not a number: " + quoted(field);
      return false;
    case NumberStatus::overflow:
      // The text has no double, so no scene value, in either precision.
      reason = quoted(field) + " is out of the range of double";
      return false;
  }
  if (!scene_value_fits<T>(x)) {
    reason = out_of_range_reason<T>(x);
    return false;
  }
  value = scene_value<T>(x);
  return true;
}

bool parse_body_id(std::string_view field, std::size_t body_count, BodyIndex& id, std::string& reason) {
  field = trim(field);
  if (field.empty()) {
    reason = "empty value";
    return false;
  }
  const char* first = field.data();
  const char* last = first + field.size();
  if (*first == '+' && last - first > 1) ++first;
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    reason = "body id must be a non-negative integer, got " + quoted(field);
    return false;
  }
  if (ec == std::errc::result_out_of_range || v > std::numeric_limits<BodyIndex>::max()) {
    reason = body_id_out_of_range(ec == std::errc() ? std::to_string(v) : std::string(first, last), body_count);
    return false;
  }
  id = static_cast<BodyIndex>(v);
  return true;
}

template bool parse_value<float>(std::string_view, float&, std::string&);
template bool parse_value<double>(std::string_view, double&, std::string&);

}  // namespace collide::detail
