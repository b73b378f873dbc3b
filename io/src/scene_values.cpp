// scene_values.cpp - scene values in the precision of a solve
// (collide/io/scene_values.hpp): the reason of a value out of range, whole
// columns converted, and the first defect of converted bodies.
//
// Design notes
// ------------
// * A column is converted in parallel blocks, each converting every row and
//   keeping its first row that does not fit; the least of them is the
//   column's, whatever the threads.
#include "collide/io/scene_values.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_reduce.h>

#include "collide/rules.hpp"

namespace collide {

template <class T>
std::string out_of_range_reason(double x) {
  std::string s = "value ";
  append_number(s, x);  // the writers' shortest round-trip text
  s += " is out of the range of ";
  s += precision_name<T>();
  return s;
}

template <class T>
std::size_t narrow_column(const void* doubles, std::size_t n, T* out) {
  const auto* bytes = static_cast<const unsigned char*>(doubles);
  const auto load = [bytes](std::size_t i) {
    double x;
    std::memcpy(&x, bytes + i * sizeof(double), sizeof(double));
    return x;
  };
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  return oneapi::tbb::parallel_reduce(
      Range(0, n, std::size_t{1} << 16), n,
      [&](const Range& r, std::size_t first) {
        bool fits = true;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const double x = load(i);
          out[i] = scene_value<T>(x);
          fits &= scene_value_fits<T>(x);
        }
        if (fits) return first;
        // The block's first row that does not fit, looked for only here.
        std::size_t i = r.begin();
        while (scene_value_fits<T>(load(i))) ++i;
        return std::min(first, i);
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

template <class T>
RowDefect first_body_defect_before(const BodyColumns<T>& columns, RowDefect range) {
  BodyColumns<T> before = columns;
  before.count = std::min(range.row, columns.count);
  if (std::optional<RowDefect> bad = first_body_defect(before)) return std::move(*bad);
  return range;
}

template <class T>
std::optional<RowDefect> narrow_bodies(const BodyColumns<double>& scene, BodyTable<T>& table) {
  const std::size_t n = scene.count;
  table.resize(n);
  std::optional<RowDefect> range;
  for (std::size_t k = 0; k < kBodyColumns.size(); ++k) {
    const std::size_t row = narrow_column(scene.column[k], n, table.column[k].data());
    // The least row, and in it the first column: columns are visited in order.
    if (row < n && (!range || row < range->row)) {
      range = RowDefect{row, Defect{kBodyColumns[k], out_of_range_reason<T>(scene.column[k][row])}};
    }
  }
  if (range) return first_body_defect_before(columns_of(table), std::move(*range));
  return first_body_defect(columns_of(table));
}

#define COLLIDE_SCENE_VALUES_INSTANTIATE(T)                                         \
  template std::string out_of_range_reason<T>(double);                              \
  template std::size_t narrow_column<T>(const void*, std::size_t, T*);              \
  template RowDefect first_body_defect_before<T>(const BodyColumns<T>&, RowDefect); \
  template std::optional<RowDefect> narrow_bodies<T>(const BodyColumns<double>&, BodyTable<T>&);

COLLIDE_SCENE_VALUES_INSTANTIATE(float)
COLLIDE_SCENE_VALUES_INSTANTIATE(double)

#undef COLLIDE_SCENE_VALUES_INSTANTIATE

}  // namespace collide
