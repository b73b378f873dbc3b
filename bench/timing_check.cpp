// bench/timing_check.cpp - collide_bench --timing-check (timing_check.hpp):
// every instrument of collide on the same scene, and whether their figures
// for one solve agree.
//
// Design notes
// ------------
// * The same solve for every instrument: float, rigid, no friction, seed 1,
//   the SIMD path on collide::default_isa() (named, so that no instrument's
//   own ISA choice differs: `collide solve` gets --isa, the benchmark its
//   isa/ row), 2 threads, the input order. The report's figures come from the
//   engine's functions that its run uses (measure_kernel_speed,
//   measure_sweep_report); the benchmark's from its registered row run by
//   Google Benchmark in this process; `collide solve`'s from the tool itself
//   on the files `collide gen --format npz` writes, outputs to /dev/null.
// * The figure is the seconds of one solve: the median run of the report's
//   row and sweep and of the benchmark's row (the rule of
//   collide/eval/timing.hpp), and of `collide solve`, which times one solve
//   per process, the median kernel_seconds of `runs` processes.
// * What is compared on purpose although it differs: `collide solve` solves
//   once in a fresh process (its kernel_seconds is a first solve: threads
//   started, arrays first touched), and the benchmark's row of a scene
//   larger than the last-level cache starts every solve from cold caches
//   (its label says so). The check prints each instrument's figure and its
//   distance from the median, so that such a difference shows.
// * The instruments take turns: `rounds` rounds, each instrument measuring
//   once a round, and each instrument's figure the median of its rounds. On
//   a machine whose speed drifts (other guests of the host), instruments
//   run one after another would each meet a different machine.
// * A scene passes when every figure is within `tolerance` of the median
//   of the scene's figures. Timings move with the machine's load: the check
//   prints the load average, and is worth running only on an idle machine.
// * What the host's other guests do shows in no load average: the memory
//   bandwidth of a shared host moves by tens of percent within minutes. So
//   every round starts with a reading of the 2-thread triad (the arrays of
//   collide_bench's triad rows, allocated once), one more follows the last
//   round, and the scene's line gives their range. Where it is wider than
//   the tolerance the verdict says so: the instruments met different
//   machines, and a failure then says more of the host than of collide. The
//   verdict itself is the figures'.
#include "timing_check.hpp"

#include <benchmark/benchmark.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include "collide/eval/bandwidth.hpp"
#include "collide/eval/timing.hpp"
#include "collide/io/generate.hpp"
#include "collide/isa.hpp"
#include "collide/solve.hpp"
#include "report.hpp"
#include "row_names.hpp"
#include "rows.hpp"
#include "scenes.hpp"
#include "summary.hpp"
#include "support.hpp"

namespace collide_bench {
namespace {

constexpr int kThreads = 2;

/// One instrument's figure for a scene.
struct Figure {
  std::string instrument;
  double seconds = 0;  ///< one solve; 0 when the instrument gave none
  std::string detail;
};

/// Keeps nothing on the console: the check prints its own lines.
class QuietReporter : public benchmark::BenchmarkReporter {
 public:
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>&) override {}
};

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// Runs `command` with its stdout and stderr into `output`; true on exit 0.
bool run_command(const std::string& command, std::string& output) {
  output.clear();
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return false;
  char buffer[4096];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, got);
  return ::pclose(pipe) == 0;
}

/// The number after "key": in a JSON object's text, NaN if absent.
double json_number(const std::string& text, const std::string& key) {
  const std::string needle = "\"" + key + "\":";
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(text.c_str() + at + needle.size(), nullptr);
}

/// `collide` beside this executable.
std::string default_collide() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("collide") : (self.parent_path() / "collide").string();
}

Kind bench_kind(const std::string& kind) {
  if (kind == "debris") return Kind::debris;
  if (kind == "pile") return Kind::pile;
  return Kind::pairs;
}

/// The benchmark's row isa/<scene>/f32/<isa>/t:2/n:N, run by Google
/// Benchmark in this process.
Figure bench_figure(Kind kind, std::size_t n, collide::Isa isa) {
  const std::string name = isa_name(kind, "f32", isa, kThreads, n);
  benchmark::ClearRegisteredBenchmarks();  // a round registers the row again
  benchmark::RegisterBenchmark(
      name.c_str(), [=](benchmark::State& s) { solve_row<float>(s, kind, n, collide::Path::simd, kThreads, isa); })
      ->UseManualTime()
      ->Unit(benchmark::kMicrosecond);
  CollectingReporter reporter(new QuietReporter);
  benchmark::RunSpecifiedBenchmarks(&reporter, "^" + name + "(/|$)");
  const Result r = reporter.get(name);
  Figure f{"collide_bench row", 0, name};
  if (r.valid && r.coll_per_s > 0) {
    f.seconds = static_cast<double>(n) / r.coll_per_s;
    if (!r.label.empty()) f.detail += " (" + r.label + ")";
  } else {
    f.detail += ": did not run";
  }
  return f;
}

/// `collide solve --stats` on the scene's files, `runs` processes: the median
/// kernel_seconds.
Figure solve_figure(const std::string& collide, const std::filesystem::path& dir, collide::Isa isa, int runs,
                    std::ostream& out) {
  const std::string command = shell_quote(collide) + " solve --bodies " + shell_quote((dir / "bodies.npz").string()) +
                              " --contacts " + shell_quote((dir / "contacts.npz").string()) +
                              " --out-bodies /dev/null --out-impulses /dev/null --format npz --precision float" +
                              " --threads " + std::to_string(kThreads) + " --path simd --isa " +
                              collide::to_string(isa) + " --model rigid --stats";
  std::vector<double> seconds;
  std::string output;
  for (int r = 0; r < runs; ++r) {
    if (!run_command(command, output)) {
      out << "  collide solve failed: " << command << "\n" << output;
      return Figure{"collide solve --stats", 0, "failed"};
    }
    const double s = json_number(output, "kernel_seconds");
    if (std::isfinite(s)) seconds.push_back(s);
  }
  return Figure{"collide solve --stats", collide::median_seconds(seconds),
                "kernel_seconds, median of " + std::to_string(seconds.size()) + " processes"};
}

/// The host's memory bandwidth now [bytes/s]: the best of three passes of
/// the 2-thread triad over collide_bench's triad arrays.
class HostBandwidth {
 public:
  HostBandwidth() : arrays_(kThreads) {}
  double measure() { return collide::measure_triad(arrays_, 3).bytes_per_second; }

 private:
  collide::TriadArrays arrays_;
};

/// One instrument: its name, and how it measures one figure.
struct Instrument {
  std::string name;
  std::function<Figure()> measure;
};

/// Runs the check of one scene; true when it passed.
bool check_scene(const std::string& kind, std::size_t asked, const TimingCheckOptions& options,
                 const std::string& collide, const std::filesystem::path& root, HostBandwidth& host,
                 std::ostream& out) {
  const collide::Isa isa = collide::default_isa();
  const bool pile = kind == "pile";
  const std::size_t side = pile ? collide::pile_side_for_contacts(asked) : 0;
  const std::size_t n = pile ? collide::pile_contact_count(side) : asked;
  out << kind << " n=" << n << (pile ? " (" + std::to_string(side) + "^3 boxes)" : std::string()) << "\n";
  out.flush();

  // `collide solve` on the files of `collide gen`.
  const std::filesystem::path dir = root / (kind + "-" + std::to_string(n));
  std::string output;
  const std::string gen = shell_quote(collide) + " gen --" + kind + " " + std::to_string(pile ? side : n) + " --out " +
                          shell_quote(dir.string()) + " --format npz --precision float --seed 1";
  if (!run_command(gen, output)) {
    out << "  collide gen failed: " << gen << "\n" << output;
    return false;
  }

  collide::ReportOptions report;
  report.n = report.debris_n = report.pile_n = asked;
  report.threads = {kThreads};
  report.runs = options.runs;
  report.seed = 1;
  std::vector<Instrument> instruments;
  instruments.push_back({"collide solve --stats", [&] { return solve_figure(collide, dir, isa, options.runs, out); }});
  // The report's kernel row and, for pairs, its sweep at the same N.
  instruments.push_back({"report kernel row", [&] {
                           const collide::ReportRow row = collide::measure_kernel_speed(report, kind);
                           return Figure{
                               "report kernel row", row.seconds,
                               std::to_string(row.runs) + " runs after a warm-up; " + row.isa + ", " + row.layout};
                         }});
  if (kind == "pairs") {
    instruments.push_back(
        {"report sweep", [&] {
           collide::ReportOptions sweep_options = report;
           sweep_options.sweep_n = {n};
           const std::vector<collide::SweepPoint> sweep = collide::measure_sweep_report(sweep_options, "rigid");
           const double rate = sweep.empty() ? 0 : sweep.front().collisions_per_second;
           return Figure{"report sweep", rate > 0 ? static_cast<double>(n) / rate : 0,
                         std::to_string(sweep.empty() ? 0 : sweep.front().runs) + " runs after a warm-up"};
         }});
  }
  instruments.push_back({"collide_bench row", [&] { return bench_figure(bench_kind(kind), n, isa); }});

  // Rounds alternate the instruments, each measuring once a round, so that
  // the machine's drift over the check falls on all of them alike; each
  // instrument's figure is the median of its rounds.
  std::vector<std::vector<double>> rounds(instruments.size());
  std::vector<Figure> figures(instruments.size());
  std::vector<double> host_bytes_per_second;
  for (int r = 0; r < options.rounds; ++r) {
    host_bytes_per_second.push_back(host.measure());
    for (std::size_t i = 0; i < instruments.size(); ++i) {
      const Figure f = instruments[i].measure();
      if (f.seconds > 0) rounds[i].push_back(f.seconds);
      figures[i] = f;
    }
  }
  for (std::size_t i = 0; i < instruments.size(); ++i) {
    figures[i].seconds = rounds[i].size() == static_cast<std::size_t>(options.rounds)
                             ? collide::median_seconds(rounds[i])
                             : 0;  // a round without a figure fails the scene
    figures[i].detail += "; median of " + std::to_string(rounds[i].size()) + " alternated rounds";
  }
  host_bytes_per_second.push_back(host.measure());
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);

  std::vector<double> seconds(figures.size());
  std::transform(figures.begin(), figures.end(), seconds.begin(), [](const Figure& f) { return f.seconds; });
  const double median = collide::median_seconds(seconds);
  bool ok = median > 0;
  for (const Figure& f : figures) {
    const double off = median > 0 ? f.seconds / median - 1 : 0;
    const bool within = f.seconds > 0 && std::abs(off) <= options.tolerance;
    ok &= within;
    char line[512];
    std::snprintf(line, sizeof line, "  %-22s %9.3f ms %8.1f Mcoll/s %+7.1f%%  %-4s %s\n", f.instrument.c_str(),
                  1e3 * f.seconds, f.seconds > 0 ? static_cast<double>(n) / f.seconds / 1e6 : 0.0, 100 * off,
                  within ? "ok" : "OFF", f.detail.c_str());
    out << line;
  }
  const auto [low, high] = std::minmax_element(host_bytes_per_second.begin(), host_bytes_per_second.end());
  const double host_spread = *low > 0 ? *high / *low : 0;
  char line[400];
  std::snprintf(line, sizeof line, "  host: 2-thread triad %.1f to %.1f GB/s over the rounds (%.2fx)\n", *low / 1e9,
                *high / 1e9, host_spread);
  out << line;
  const bool host_moved = !(host_spread > 0 && host_spread - 1 <= options.tolerance);
  std::snprintf(line, sizeof line, "  median %.3f ms: %s%s\n", 1e3 * median, ok ? "PASS" : "FAIL",
                host_moved ? " (the host's bandwidth moved more than the tolerance during the rounds: the instruments"
                             " met different machines)"
                           : "");
  out << line;
  out.flush();
  return ok;
}

}  // namespace

int run_timing_check(const TimingCheckOptions& options, std::ostream& out) {
  const std::string collide = options.collide.empty() ? default_collide() : options.collide;
  std::filesystem::path root = options.dir;
  bool own_root = false;
  if (root.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/collide-timing-XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) {
      out << "collide_bench: cannot create a directory from " << pattern << "\n";
      return 1;
    }
    root = pattern;
    own_root = true;
  } else {
    std::filesystem::create_directories(root);
  }

  char line[512];
  std::snprintf(line, sizeof line,
                "timing check: one solve (float, rigid, no friction, simd %s, %d threads) timed by every instrument;\n"
                "a figure more than %.0f%% from its scene's median fails. Load average %.2f%s.\n",
                collide::to_string(collide::default_isa()), kThreads, 100 * options.tolerance, load_average(),
                load_average() > 0.5 ? " (other processes are running: expect noise)" : "");
  out << line;
  std::size_t failed = 0;
  HostBandwidth host;
  for (const auto& [kind, n] : options.scenes) {
    if (!check_scene(kind, n, options, collide, root, host, out)) ++failed;
  }
  if (own_root) {
    std::error_code ec;
    std::filesystem::remove_all(root, ec);
  }
  out << "timing check: " << (failed == 0 ? "PASS" : "FAIL") << " (" << options.scenes.size() - failed << " of "
      << options.scenes.size() << " scenes agree)\n";
  return failed == 0 ? 0 : 1;
}

}  // namespace collide_bench
