// bench/options.hpp - collide_bench's flags of its own (parsed in main.cpp),
// as registration and the summary read them.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace collide_bench {

/// The two sizes of the summary's ratios and of the tables of
/// docs/performance.md: in cache (64Ki contacts) and streaming (4Mi).
inline constexpr std::size_t kCacheN = 65536, kStreamN = 4194304;

/// --timing-check and its settings (timing_check.hpp).
struct TimingCheckOptions {
  bool enabled = false;
  /// --collide=PATH: the `collide` tool (default: `collide` beside collide_bench).
  std::string collide;
  /// --timing-dir=DIR: where the scene files go (default: a fresh directory
  /// under $TMPDIR or /tmp, removed at the end).
  std::string dir;
  /// --timing-scenes=KIND:N,...: pairs, debris or pile (N contacts: the
  /// largest pile within N), in that order.
  std::vector<std::pair<std::string, std::size_t>> scenes{
      {"pairs", 1000000}, {"pairs", 4000000}, {"debris", 1000000}, {"pile", 2980000}};
  /// --timing-runs=R: timed runs of the report's figures, and processes of
  /// `collide solve`.
  int runs = 3;
  /// --timing-rounds=K: alternated rounds of the instruments; each
  /// instrument's figure is the median of its K rounds.
  int rounds = 3;
  /// --timing-tolerance=F: the largest relative distance of a figure from
  /// the scene's median that passes.
  double tolerance = 0.10;
};

struct Options {
  /// --sizes=a,b,...: the N of the generated scenes.
  std::vector<std::size_t> sizes{10000, 65536, 262144, 1048576, 4194304, 16777216};
  /// --quick: float only, N in {kCacheN, kStreamN}, the rows the summary reads.
  bool quick = false;
  /// Summary to stdout (else stderr, to keep JSON/CSV output clean).
  bool console = true;
  /// --scene=B,C: the bodies and contacts files of the file rows (empty: none).
  std::string scene_bodies, scene_contacts;
  /// --timing-check: compare the instruments instead of running the rows.
  TimingCheckOptions timing;
};

}  // namespace collide_bench
