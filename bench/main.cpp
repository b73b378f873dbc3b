// bench/main.cpp - collide_bench's entry: its own flags, then the start-up
// check, the rows and the summary.
//
// Design notes
// ------------
// What runs and in which order is registration.cpp's, how a row is timed
// rows.cpp's, the summary summary.cpp's. Flags of our own, removed before
// Google Benchmark sees argv:
//   --quick          float only, N in {64Ki, 4Mi}: the rows the summary reads
//   --sizes=a,b,...  the N to run (default 1e4, 64Ki, 256Ki, 1Mi, 4Mi, 16Mi)
//   --scene=B,C      also the rows of one group on the scene in the files B
//                    (bodies) and C (contacts), CSV or binary (.npz) by name,
//                    named solve/file/..., schedule/file/... (N: its contacts)
//   --timing-check   no rows: every instrument times the same solve and the
//                    figures must agree (timing_check.hpp); with
//                    --collide=PATH (default: collide beside collide_bench),
//                    --timing-dir=DIR (scene files; default a temporary one),
//                    --timing-scenes=KIND:N,... (default pairs:1e6,pairs:4e6,
//                    debris:1e6,pile:2980000), --timing-runs=R (3),
//                    --timing-rounds=K (3: alternated rounds, medians),
//                    --timing-tolerance=F (0.1). Exit 1 when they disagree.
// Any --benchmark_filter gets "|^triad/" appended so that the bound is always
// measured. The console table is tabular unless --benchmark_counters_tabular=
// false is given; --benchmark_min_time defaults to 0.2 (seconds). With a
// --benchmark_format other than console the summary goes to stderr.
// Handy: --benchmark_filter='f32.*n:65536' for one size, --benchmark_filter=
// '^solve/pairs' for one scene, --benchmark_repetitions=3 on a noisy machine
// (the summary then uses the medians).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "check.hpp"
#include "options.hpp"
#include "registration.hpp"
#include "scenes.hpp"
#include "summary.hpp"
#include "support.hpp"
#include "timing_check.hpp"

namespace collide_bench {
namespace {

Options parse_own_flags(int& argc, char** argv) {
  Options options;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      options.quick = true;
      options.sizes = {kCacheN, kStreamN};
    } else if (arg.rfind("--scene=", 0) == 0) {
      const std::string files = arg.substr(8);
      const std::size_t comma = files.find(',');
      if (comma == std::string::npos || comma == 0 || comma + 1 == files.size()) {
        std::fprintf(stderr, "collide_bench: --scene needs BODIES,CONTACTS, got '%s'\n", files.c_str());
        std::exit(2);
      }
      options.scene_bodies = files.substr(0, comma);
      options.scene_contacts = files.substr(comma + 1);
    } else if (arg == "--timing-check") {
      options.timing.enabled = true;
    } else if (arg.rfind("--collide=", 0) == 0) {
      options.timing.collide = arg.substr(10);
    } else if (arg.rfind("--timing-dir=", 0) == 0) {
      options.timing.dir = arg.substr(13);
    } else if (arg.rfind("--timing-runs=", 0) == 0) {
      options.timing.runs = std::atoi(arg.c_str() + 14);
      if (options.timing.runs < 1 || options.timing.runs > 1000) {
        std::fprintf(stderr, "collide_bench: --timing-runs must be from 1 to 1000, got '%s'\n", arg.c_str() + 14);
        std::exit(2);
      }
    } else if (arg.rfind("--timing-rounds=", 0) == 0) {
      options.timing.rounds = std::atoi(arg.c_str() + 16);
      if (options.timing.rounds < 1 || options.timing.rounds > 1000) {
        std::fprintf(stderr, "collide_bench: --timing-rounds must be from 1 to 1000, got '%s'\n", arg.c_str() + 16);
        std::exit(2);
      }
    } else if (arg.rfind("--timing-tolerance=", 0) == 0) {
      options.timing.tolerance = std::atof(arg.c_str() + 19);
      if (!(options.timing.tolerance > 0)) {
        std::fprintf(stderr, "collide_bench: --timing-tolerance must be above 0, got '%s'\n", arg.c_str() + 19);
        std::exit(2);
      }
    } else if (arg.rfind("--timing-scenes=", 0) == 0) {
      options.timing.scenes.clear();
      std::stringstream list(arg.substr(16));
      std::string item;
      while (std::getline(list, item, ',')) {
        const std::size_t colon = item.find(':');
        const std::string kind = item.substr(0, colon);
        const double n = colon == std::string::npos ? 0 : std::atof(item.c_str() + colon + 1);
        if ((kind != "pairs" && kind != "debris" && kind != "pile") || !(n >= 1 && n <= 2147483647.0)) {
          std::fprintf(stderr, "collide_bench: --timing-scenes takes pairs:N, debris:N or pile:N, got '%s'\n",
                       item.c_str());
          std::exit(2);
        }
        options.timing.scenes.emplace_back(kind, static_cast<std::size_t>(n));
      }
    } else if (arg.rfind("--sizes=", 0) == 0) {
      options.sizes.clear();
      std::stringstream list(arg.substr(8));
      std::string item;
      while (std::getline(list, item, ',')) {
        if (!item.empty()) {
          options.sizes.push_back(static_cast<std::size_t>(std::stod(item)));
        }
      }
    } else {
      if (arg.rfind("--benchmark_format=", 0) == 0 && arg != "--benchmark_format=console") {
        options.console = false;
      }
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  return options;
}

}  // namespace
}  // namespace collide_bench

int main(int argc, char** argv) {
  using namespace collide_bench;
  const Options options = parse_own_flags(argc, argv);
  set_scene_files(options.scene_bodies, options.scene_contacts);

  // Tabular counters by default: one aligned column per counter.
  std::vector<char*> args(argv, argv + argc);
  bool tabular_given = false, min_time_given = false, listing = false;
  for (char* a : args) {
    tabular_given |= std::strncmp(a, "--benchmark_counters_tabular", 28) == 0;
    min_time_given |= std::strncmp(a, "--benchmark_min_time", 20) == 0;
    listing |= std::strcmp(a, "--benchmark_list_tests") == 0 || std::strcmp(a, "--benchmark_list_tests=true") == 0;
  }
  std::string tabular = "--benchmark_counters_tabular=true";
  if (!tabular_given) {
    args.push_back(tabular.data());
  }
  // 0.2 s of measured time per row rather than 0.5: the smallest rows still
  // repeat hundreds of times, the largest run once whatever the setting.
  std::string min_time = "--benchmark_min_time=0.2";
  if (!min_time_given) {
    args.push_back(min_time.data());
  }
  int args_count = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&args_count, args.data());
  if (benchmark::ReportUnrecognizedArguments(args_count, args.data())) {
    return 1;
  }

  std::ostream& info = options.console ? std::cout : std::cerr;
  if (options.timing.enabled) {
    return run_timing_check(options.timing, info);
  }
  // Listing the rows needs no check. (Looked up before Initialize, which
  // removes the flags it knows from argv.)
  const bool checks_ok = listing || check_kernels(info);

  // The cache-evict buffer is resident from the start, so that every scene's
  // memory figures include it alike (the summary lists it).
  evict_caches();

  // The caller's scene runs at its own N, its contacts (a bad file stops
  // here with the reader's message).
  std::size_t file_contacts = 0;
  if (!options.scene_bodies.empty()) {
    try {
      file_contacts = scene_file_contacts();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "collide_bench: %s\n", e.what());
      return 1;
    }
    if (file_contacts == 0) {
      std::fprintf(stderr, "collide_bench: %s has no contacts to solve\n", options.scene_contacts.c_str());
      return 1;
    }
  }
  register_rows(options, file_contacts);

  std::string spec = benchmark::GetBenchmarkFilter();
  if (!spec.empty() && spec != "." && spec != "all" && spec[0] != '-') {
    spec = "(" + spec + ")|^triad/";
  }
  CollectingReporter reporter(benchmark::CreateDefaultDisplayReporter());
  const double load_before = load_average();
  benchmark::RunSpecifiedBenchmarks(&reporter, spec);
  print_summary(reporter, options, checks_ok, load_before, info);
  benchmark::Shutdown();
  return 0;
}
