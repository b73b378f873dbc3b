// bench/options.hpp - collide_bench's flags of its own (parsed in main.cpp),
// as registration and the summary read them.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace collide_bench {

/// The two sizes of the summary's ratios and of the tables of
/// docs/performance.md: in cache (64Ki contacts) and streaming (4Mi).
inline constexpr std::size_t kCacheN = 65536, kStreamN = 4194304;

struct Options {
  /// --sizes=a,b,...: the N of the generated scenes.
  std::vector<std::size_t> sizes{10000, 65536, 262144, 1048576, 4194304, 16777216};
  /// --quick: float only, N in {kCacheN, kStreamN}, the rows the summary reads.
  bool quick = false;
  /// Summary to stdout (else stderr, to keep JSON/CSV output clean).
  bool console = true;
  /// --scene=B,C: the bodies and contacts files of the file rows (empty: none).
  std::string scene_bodies, scene_contacts;
};

}  // namespace collide_bench
