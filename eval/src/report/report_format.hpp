// report/report_format.hpp - the printf-style number text the table, the
// JSON and the plot of `collide report` share; private to the report engine.
//
// Design notes
// ------------
// * The report keeps its own formatting rather than io's append_number
//   (shortest round-trip text, "inf") or check.cpp's JSON numbers (%.9g): the
//   report's columns, its JSON (%.6g, null for inf and NaN) and gnuplot's
//   inputs have fixed formats of their own, which readers of the report parse.
#pragma once

#include <cstdio>
#include <string>

namespace collide::report_detail {

/// `x` printed with one printf conversion, `fmt` (e.g. "%.6g").
inline std::string format(const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

}  // namespace collide::report_detail
