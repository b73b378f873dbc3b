// bench/summary.hpp - the summary collide_bench prints after its run: the
// run's ratios, the body-model and throughput tables and the
// memory of every scene, all from the rows of the same run (summary.cpp).
#pragma once

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "options.hpp"

namespace collide_bench {

/// The counters of one row the summary reads.
struct Result {
  double coll_per_s = 0, gbs = 0, bw_frac = 0;
  bool valid = false;
  std::string label;  ///< the row's label (solve rows: "<isa>, <lanes> lanes")
};

/// Wraps the display reporter chosen by the flags and keeps each row's
/// counters for the summary.
class CollectingReporter : public benchmark::BenchmarkReporter {
 public:
  explicit CollectingReporter(benchmark::BenchmarkReporter* inner) : inner_(inner) {}
  bool ReportContext(const Context& context) override { return inner_->ReportContext(context); }
  /// Keeps the counters of each row that ran (the median with repetitions),
  /// then passes the runs on to the display reporter.
  void ReportRuns(const std::vector<Run>& runs) override;
  void Finalize() override { inner_->Finalize(); }

  /// The name as registered: Google Benchmark appends "/manual_time".
  static std::string row_key(const Run& run);

  /// True when some row ran with repetitions (the summary uses medians).
  [[nodiscard]] bool medians() const { return medians_; }

  [[nodiscard]] Result get(const std::string& name) const {
    const auto it = results_.find(name);
    return it == results_.end() ? Result{} : it->second;
  }

 private:
  std::unique_ptr<benchmark::BenchmarkReporter> inner_;
  std::map<std::string, Result> results_;
  std::map<std::string, bool> had_median_;
  bool medians_ = false;
};

/// Prints the summary of the rows `reporter` kept to `out`. `checks_ok` is
/// the start-up check's verdict, `load_before` the load average before the
/// run.
void print_summary(const CollectingReporter& reporter, const Options& options, bool checks_ok, double load_before,
                   std::ostream& out);

}  // namespace collide_bench
