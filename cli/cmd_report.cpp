// cli/cmd_report.cpp - `collide report`: parses the options, runs the report
// engine (report.hpp, eval/src/report/) and prints its table, JSON
// and plot. Exit codes: see the usage.

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "collide/eval/check.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/solve.hpp"
#include "commands.hpp"
#include "report.hpp"

namespace collide::cli {

const char* const kReportUsage =
    "usage: collide report [--n N] [--debris-n N] [--pile-n N] [--threads LIST]\n"
    "                      [--json FILE] [--plot FILE.png] [--sample N] [--runs R]\n"
    "                      [--seed S] [--quick] [--hard] [--hard-n N]\n"
    "                      [--convergence-n N] [--no-convergence]\n"
    "                      [--bodies B --contacts C] [--all]\n"
    "\n"
    "Measures every variant of the solver on the pairs, debris and pile scenes:\n"
    "speed (collisions per second, median of R timed runs, and the fraction of the\n"
    "memory-bandwidth bound) and error against the long double reference (impulse\n"
    "error in eps times the contact's impulse scale, relative error, momentum and\n"
    "energy drift). Prints a summary on stdout, the speed-against-error frontier of\n"
    "each scene (the rows no other row beats on both), and with --all every row;\n"
    "docs/report.md explains the columns.\n"
    "\n"
    "  --n N           collisions of the pairs scene (default 1000000)\n"
    "  --debris-n N    collisions of the debris scene (default: N, at most 1000000;\n"
    "                  its random body accesses run 3 to 10 times slower per\n"
    "                  collision, so this keeps the default run to a few minutes)\n"
    "  --pile-n N      collisions of the pile scene, boxes on a lattice touching their\n"
    "                  neighbours and the ground (as collide gen --pile): the largest\n"
    "                  cubic pile with at most N contacts (default: N, at most\n"
    "                  1000000, which gives 69^3 boxes and 976005 contacts)\n"
    "  --threads LIST  comma-separated thread counts of the kernel rows (default 1,2)\n"
    "  --json FILE     also write every row as JSON\n"
    "  --plot FILE     also write a PNG with gnuplot: throughput against error, and\n"
    "                  throughput against N (runs an extra sweep up to 4e6 pairs)\n"
    "  --sample N      contacts of the error sample (default 100000)\n"
    "  --runs R        timed runs per row, the median is reported (default 3)\n"
    "  --seed S        scene seed (default 1)\n"
    "  --quick         a smoke run for tests: 3 runs, a sample of at most N, a short\n"
    "                  sweep, a short triad\n"
    "  --hard          also measure the hard scenes (mass ratios, immovable bodies,\n"
    "                  needles, levers, grazing, unit scales, subnormals, resting,\n"
    "                  e = 0 and 1, stick/slip, spin, cradles, stars, a cluster) in\n"
    "                  float and double, fast and accurate mode: speed, error in\n"
    "                  eps x impulse scale and in ulps (takes seconds)\n"
    "  --hard-n N      pairs of each hard pair family (default 1000)\n"
    "  --convergence-n N\n"
    "                  contacts of each scene of the convergence section, a resting\n"
    "                  pile, a stack and debris solved with 1 to 32 passes in both\n"
    "                  orders and iteration modes, and warm-started: the residual\n"
    "                  against the time (default 188800, a pile of 40^3 boxes;\n"
    "                  --quick: 1408)\n"
    "  --no-convergence\n"
    "                  leave the convergence section out\n"
    "  --bodies B      also measure the scene in the files B and C (CSV, or binary\n"
    "  --contacts C    .npz): rows of scene 'file' in float and double, with its own\n"
    "                  friction and the models it fits; the error sample and the\n"
    "                  slow rows use its first contacts\n"
    "  --all           print every row, not only the frontier (the JSON always has\n"
    "                  every row)\n"
    "\n"
    "exit codes: 0 success, 1 I/O error or gnuplot missing with --plot, 2 usage\n"
    "            error, 3 a kernel variant's error exceeds the documented bound\n"
    "            (--hard: also an accurate row above its bound in ulps)\n";

namespace {
std::vector<int> parse_thread_list(const std::string& text) {
  std::vector<int> threads;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const unsigned long long t = parse_integer("threads", item, 1, kMaxThreads);
    if (std::find(threads.begin(), threads.end(), static_cast<int>(t)) == threads.end()) {
      threads.push_back(static_cast<int>(t));
    }
  }
  if (threads.empty()) throw UsageError("--threads needs at least one count");
  return threads;
}

void write_text_file(const std::string& path, const std::string& text) {
  OutputFile out(path);
  out.write(text);
  out.commit();
}

}  // namespace

// ---------------------------------------------------------------------------
// The command.
// ---------------------------------------------------------------------------

int run_report(int argc, char** argv) {
  const Options opt = parse_options(argc, argv, 2,
                                    {{"n", true},
                                     {"debris-n", true},
                                     {"pile-n", true},
                                     {"threads", true},
                                     {"json", true},
                                     {"plot", true},
                                     {"sample", true},
                                     {"runs", true},
                                     {"seed", true},
                                     {"quick", false},
                                     {"hard", false},
                                     {"hard-n", true},
                                     {"convergence-n", true},
                                     {"no-convergence", false},
                                     {"bodies", true},
                                     {"contacts", true},
                                     {"all", false}});
  if (opt.count("help") != 0) {
    std::fputs(kReportUsage, stdout);
    return kExitOk;
  }
  ReportOptions config;
  std::string json_path, plot_path;
  config.quick = opt.count("quick") != 0;
  if (config.quick) config.runs = 3;
  // Pairs use 2n body ids, which are 32-bit.
  if (const auto it = opt.find("n"); it != opt.end()) config.n = parse_integer("n", it->second, 1, kMaxPairs);
  if (const auto it = opt.find("threads"); it != opt.end()) config.threads = parse_thread_list(it->second);
  if (const auto it = opt.find("json"); it != opt.end()) json_path = it->second;
  if (const auto it = opt.find("plot"); it != opt.end()) plot_path = it->second;
  if (const auto it = opt.find("sample"); it != opt.end()) {
    config.sample = parse_integer("sample", it->second, 1, 0x7FFFFFFF);
  }
  if (const auto it = opt.find("runs"); it != opt.end()) {
    config.runs = static_cast<int>(parse_integer("runs", it->second, 1, 1000));
  }
  if (const auto it = opt.find("seed"); it != opt.end()) config.seed = parse_count("seed", it->second);
  if (const auto it = opt.find("debris-n"); it != opt.end()) {
    config.debris_n = parse_integer("debris-n", it->second, 1, kMaxDebrisContacts);
  } else {
    config.debris_n = std::min(config.n, config.debris_n);
  }
  if (const auto it = opt.find("pile-n"); it != opt.end()) {
    config.pile_n = parse_integer("pile-n", it->second, 1, 0xFFFFFFFF);
  } else {
    config.pile_n = std::min(config.n, config.pile_n);
  }
  config.hard = opt.count("hard") != 0 || opt.count("hard-n") != 0;
  if (const auto it = opt.find("hard-n"); it != opt.end()) {
    config.hard_n = parse_integer("hard-n", it->second, 1, kMaxPairs);
  }
  config.convergence = opt.count("no-convergence") == 0;
  if (const auto it = opt.find("convergence-n"); it != opt.end()) {
    config.convergence_n = parse_integer("convergence-n", it->second, 1, 100000000);
  } else if (config.quick) {
    config.convergence_n = kQuickConvergenceN;
  }
  if (opt.count("bodies") != opt.count("contacts")) throw UsageError("--bodies and --contacts go together");
  if (opt.count("bodies") != 0) {
    config.scene_bodies = opt.at("bodies");
    config.scene_contacts = opt.at("contacts");
  }
  if (!plot_path.empty()) {
    // Few points, so the sweep fits the budget: the two scenes of millions of
    // pairs dominate its time (3 runs each).
    config.sweep_n =
        config.quick ? std::vector<std::size_t>{10000, 100000, 1000000}
                     : std::vector<std::size_t>{10000, 20000, 50000, 100000, 200000, 500000, 1000000, 2000000, 4000000};
  }

  const Report report = measure_report(config);

  const std::string text =
      opt.count("all") != 0 ? format_report_table(report) : format_report_summary(report, json_path, plot_path);
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
  if (!json_path.empty()) write_text_file(json_path, format_report_json(report));
  int status = kExitOk;
  if (!plot_path.empty()) {
    if (const std::string why = write_report_plot(report, plot_path); !why.empty()) {
      std::fprintf(stderr, "collide report: no plot: %s\n", why.c_str());
      status = kExitBadInput;
    }
  }
  for (const ReportRow& row : report.rows) {
    const bool kernel = is_kernel_variant(row.variant);
    if (kernel && !(row.max_err_eps <= kImpulseErrorBoundEps)) {
      std::fprintf(stderr,
                   "collide report: %s %s %s %s: impulse error %.6g eps * impulse_scale exceeds the documented "
                   "bound of %g\n",
                   row.scene.c_str(), row.variant.c_str(), row.precision.c_str(), row.model.c_str(), row.max_err_eps,
                   kImpulseErrorBoundEps);
      status = kExitCheckFailed;
    }
  }
  for (const HardRow& row : report.hard) {
    if (row.judge == "none") continue;  // no reference that can judge it in this build
    const bool accurate = row.mode == "accurate";
    const double figure = accurate ? row.max_err_ulps : row.max_err_eps;
    const double bound = accurate ? kAccurateErrorUlps : kImpulseErrorBoundEps;
    if (!(figure <= bound)) {
      std::fprintf(stderr, "collide report: hard %s %s %s %s: error %.6g %s exceeds the documented bound of %g\n",
                   row.family.c_str(), row.model.c_str(), row.precision.c_str(), row.mode.c_str(), figure,
                   accurate ? "ulps" : "eps * impulse_scale", bound);
      status = kExitCheckFailed;
    }
  }
  return status;
}

}  // namespace collide::cli
