// report/report_order.cpp - the canonical order of the report's rows
// (sort_report_rows) and which rows are the kernel's (is_kernel_variant).
//
// Design notes
// ------------
// * The table, the JSON and the plot are all written from the same Report,
//   after every measurement, so they agree; rows are put into one canonical
//   order first (scene, friction, then reference, textbook, peer, kernel;
//   kernel rows by model, precision, path and thread count), the order a
//   reader compares them in.
#include <algorithm>
#include <string>
#include <tuple>

#include "report.hpp"

namespace collide {

namespace {

int variant_rank(const std::string& v) {
  if (v == "reference") return 0;
  if (v == "textbook") return 1;
  if (v == "bullet") return 2;
  if (v == "scalar") return 3;
  if (v == "simd") return 4;
  return 5;  // accurate: the SIMD path in Accuracy::accurate
}
int model_rank(const std::string& m) { return m == "rigid" ? 0 : m == "sphere" ? 1 : 2; }
int precision_rank(const std::string& p) { return p == "long double" ? 0 : p == "double" ? 1 : 2; }

}  // namespace

bool is_kernel_variant(const std::string& variant) {
  return variant == "scalar" || variant == "simd" || variant == "accurate";
}

void sort_report_rows(Report& report) {
  auto key = [](const ReportRow& r) {
    const bool kernel = is_kernel_variant(r.variant);
    return std::make_tuple(r.scene == "pairs"    ? 0
                           : r.scene == "debris" ? 1
                           : r.scene == "pile"   ? 2
                                                 : 3,
                           r.friction ? 1 : 0, kernel ? 3 : variant_rank(r.variant), model_rank(r.model),
                           precision_rank(r.precision), variant_rank(r.variant), r.isa, r.threads);
  };
  std::stable_sort(report.rows.begin(), report.rows.end(),
                   [&](const ReportRow& a, const ReportRow& b) { return key(a) < key(b); });
}

}  // namespace collide
