// report/report_order.cpp - the canonical order of the report's rows
// (sort_report_rows), which rows are the kernel's (is_kernel_variant), and
// which rows make the speed-against-error frontier (report_frontier).
//
// Design notes
// ------------
// * The table, the JSON and the plot are all written from the same Report,
//   after every measurement, so they agree; rows are put into one canonical
//   order first (scene, friction, then reference, textbook, peer, kernel;
//   kernel rows by model, precision, path and thread count), the order a
//   reader compares them in.
// * The frontier is what the summary prints first: of each scene and
//   friction setting, the rows no other row beats on both speed and error,
//   the choices a user actually has. Error is panel 1's axis, max err x eps
//   (|J - Jref| / impulse scale, so float, double and long double compare);
//   kernel rows count at the run's largest thread count only, as in panel 1,
//   since a row at fewer threads is the same answer at less speed.
#include <algorithm>
#include <cstddef>
#include <string>
#include <tuple>
#include <vector>

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

std::vector<std::size_t> report_frontier(const Report& report) {
  int threads = 1;
  for (const ReportRow& r : report.rows) threads = std::max(threads, r.threads);
  const auto candidate = [&](const ReportRow& r) { return !is_kernel_variant(r.variant) || r.threads == threads; };
  const auto error = [](const ReportRow& r) { return r.max_err_eps * r.eps; };
  const auto group = [](const ReportRow& r) { return std::make_pair(r.scene, r.friction); };
  std::vector<std::size_t> frontier;
  std::size_t begin = 0;
  while (begin < report.rows.size()) {
    std::size_t end = begin;
    while (end < report.rows.size() && group(report.rows[end]) == group(report.rows[begin])) ++end;
    std::vector<std::size_t> kept;
    for (std::size_t i = begin; i < end; ++i) {
      const ReportRow& r = report.rows[i];
      if (!candidate(r)) continue;
      bool beaten = false;
      for (std::size_t j = begin; j < end && !beaten; ++j) {
        const ReportRow& s = report.rows[j];
        beaten = j != i && candidate(s) &&
                 ((s.collisions_per_second > r.collisions_per_second && error(s) <= error(r)) ||
                  (s.collisions_per_second >= r.collisions_per_second && error(s) < error(r)));
      }
      if (!beaten) kept.push_back(i);
    }
    std::stable_sort(kept.begin(), kept.end(), [&](std::size_t a, std::size_t b) {
      return report.rows[a].collisions_per_second > report.rows[b].collisions_per_second;
    });
    frontier.insert(frontier.end(), kept.begin(), kept.end());
    begin = end;
  }
  return frontier;
}

}  // namespace collide
