// collide/io/scene_values.hpp - the values a solve sees of a scene: the one
// conversion from a scene value to the precision of the solve, which every
// route a scene takes to the solver uses (docs/collision-law.md, "Scene
// values").
//
// Design notes
// ------------
// * A scene value is a double: the double nearest a CSV field's text, or
//   what a binary column stores ('<f8', or '<f4', widened exactly). A solve
//   in float sees the float nearest that double, ties to even: one rounding
//   of the double, which is what static_cast<float> and NumPy's
//   astype(numpy.float32) do. Rounding the text straight to float is another
//   rounding (text that is not the shortest form of its float can round to
//   the neighbouring float), so the CSV reader parses every number as a
//   double first, whatever the precision, and the same scene gives the same
//   bits from CSV, .npz, NumPy arrays or a generator.
// * A finite double whose float is not finite (|x| at or above FLT_MAX plus
//   half an ulp) has no value in float: every route refuses it with one
//   reason, "value 1e+39 is out of the range of float", formed from the
//   double (shortest round-trip text), as the rules form theirs. NaN and inf
//   are values of every precision, and so are the subnormal floats rounding
//   may give: the rules (collide/rules.hpp) judge them on the rounded value
//   (a mass or moment whose inverse overflows, a quaternion whose |q|^2 is
//   not normal), the same on every route.
// * Where a route converts whole columns (the binary reader, Python's
//   from_physical, narrow_bodies), the defect it reports is the one the CSV
//   reader reports for the same values: the first row, in row order, with a
//   value out of range or a broken rule, and in that row a value out of
//   range (the first such column) before any rule (first_body_defect_before).
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "collide/io/scene_io.hpp"

namespace collide {

/// The value a solve in T sees of the scene value x: the T nearest x, ties
/// to even (docs/collision-law.md, "Scene values"). Exact for double and
/// long double.
template <class T>
constexpr T scene_value(double x) noexcept {
  static_assert(std::is_floating_point_v<T>, "scene values are real");
  return static_cast<T>(x);
}

/// Whether x has a value in T: false for a finite x whose T value is not
/// finite (it overflows T). NaN and inf are left to the rules.
template <class T>
bool scene_value_fits(double x) noexcept {
  if constexpr (sizeof(T) >= sizeof(double)) {
    return true;
  } else {
    return !(std::isinf(scene_value<T>(x)) && !std::isinf(x));
  }
}

/// The reason a value out of T's range is refused:
/// "value 1e+39 is out of the range of float".
template <class T>
std::string out_of_range_reason(double x);

/// Converts n scene values, doubles at `doubles` (any alignment), into `out`
/// in T (scene_value), rows in parallel. Returns the first row whose value
/// does not fit T (scene_value_fits; its `out` is then inf), or n.
template <class T>
std::size_t narrow_column(const void* doubles, std::size_t n, T* out);

/// The defect the readers report for bodies converted to T column by column
/// whose first value out of T's range (least row, then first column) is
/// `range`: the first body before range.row that breaks a rule
/// (first_body_defect), else `range`. The CSV reader finds the same, row by
/// row.
template <class T>
RowDefect first_body_defect_before(const BodyColumns<T>& columns, RowDefect range);

/// Bodies in physical units given as scene values (double columns, e.g. a
/// caller's arrays) as a solve in T sees them: `table` receives every value
/// (scene_value), and the result is the first defect of the bodies, a value
/// out of T's range or a broken rule, as every reader reports it for the
/// same values; nothing when they are all fine. What Python's from_physical
/// uses, and what a C++ caller with double columns hands to SolveBodies<T>
/// (columns_of(table)).
template <class T>
std::optional<RowDefect> narrow_bodies(const BodyColumns<double>& scene, BodyTable<T>& table);

}  // namespace collide
