// report/report_table.cpp - what `collide report` prints on stdout: by
// default the summary (format_report_summary: the run and the machine, the
// speed-against-error frontier of each scene, the convergence section,
// where the rest is), with --all the whole table (format_report_table: one
// line per row grouped by scene and friction, then the convergence and the
// hard section, the sweep and the wall time).
//
// Design notes
// ------------
// * Written from the same Report as the JSON and the plot, rows already in
//   the canonical order (report_order.cpp), so the three agree; the summary's
//   lines are the table's lines of the frontier rows.
// * A cache size that could not be read prints "unknown", not 0.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "collide/accuracy.hpp"
#include "collide/eval/check.hpp"
#include "report.hpp"
#include "report_format.hpp"

namespace collide {

namespace {

using report_detail::format;

std::string mib(std::size_t bytes) {
  if (bytes >= (std::size_t{1} << 20)) return format("%.0f MiB", static_cast<double>(bytes) / (1 << 20));
  return format("%.0f KiB", static_cast<double>(bytes) / 1024);
}

/// A cache size that may be unknown: "unknown" in text, null in JSON.
std::string mib(const std::optional<std::size_t>& bytes) { return bytes ? mib(*bytes) : "unknown"; }

/// The run, the machine and the legend, up to the rows' header.
std::string preamble(const Report& report) {
  const MachineInfo& m = report.machine;
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "collide report: pairs scene %zu collisions, debris scene %zu, pile scene %zu (%zu^3 boxes), error "
                "sample %zu contacts%s\n",
                report.n, report.debris_n, report.pile_n, report.pile_side, report.error_sample,
                report.quick ? " (--quick)" : "");
  out += line;
  std::snprintf(line, sizeof line, "machine: %s, %u hardware threads, L1d %s, L2 %s, L3 %s per instance; %s\n",
                m.cpu.empty() ? "unknown CPU" : m.cpu.c_str(), m.hardware_threads, mib(m.l1d_bytes).c_str(),
                mib(m.l2_bytes).c_str(), mib(m.l3_bytes).c_str(), m.simd_build.c_str());
  out += line;
  out += "triad bandwidth:";
  for (std::size_t i = 0; i < m.triad_threads.size(); ++i) {
    std::snprintf(line, sizeof line, "%s %d thread%s %.1f GB/s (median %.1f)", i ? "," : "", m.triad_threads[i],
                  m.triad_threads[i] == 1 ? "" : "s", m.triad_bytes_per_second[i] / 1e9,
                  m.triad_median_bytes_per_second[i] / 1e9);
    out += line;
  }
  std::snprintf(line, sizeof line, "\n  (best pass is the bound; 3 float arrays of %s); load average %.2f at start\n",
                mib(m.triad_array_bytes).c_str(), m.load_average);
  out += line;
  if (!m.isa_auto.empty()) {
    // Four lines: one per precision and accuracy, "streaming/scattered" per model.
    double seconds = 0;
    for (const IsaAutoPick& p : m.isa_auto) seconds += p.calibration_seconds;
    std::snprintf(line, sizeof line,
                  "isa auto (the fastest ISA per kind of solve, measured once per process: %.1f ms for %zu kinds), "
                  "streaming/scattered:\n",
                  1e3 * seconds, m.isa_auto.size());
    out += line;
    std::string last;
    for (const IsaAutoPick& p : m.isa_auto) {
      const std::string group = p.precision + " " + p.accuracy;
      if (group != last) {
        if (!last.empty()) out += "\n";
        std::snprintf(line, sizeof line, "  %-6s %-8s ", p.precision.c_str(), p.accuracy.c_str());
        out += line;
        last = group;
      }
      if (!p.scattered) {
        std::snprintf(line, sizeof line, " %s %s", p.model.c_str(), p.isa.c_str());
      } else {
        std::snprintf(line, sizeof line, "/%s", p.isa.c_str());
      }
      out += line;
    }
    out += "\n";
  }
  out += "peer: " + report.peer_status + "\n";
  std::snprintf(line, sizeof line,
                "speed: median of timed runs of the solve alone, after an untimed warm-up; bw = share of the bandwidth "
                "bound.\n"
                "error: vs reference_solve<long double> on the sample; err in eps x impulse scale (kernel bound "
                "%.0f),\n"
                "       rel = max |J-Jref|/|Jref|; dP, dL, dE = momentum, angular momentum, energy drift "
                "(docs/report.md).\n\n",
                kImpulseErrorBoundEps);
  out += line;
  return out;
}

const char* const kRowHeader =
    "scene   fric variant   precision   model    isa    layout thr         n  Mcoll/s     bw   max err   p99 err"
    "   max rel       dP       dL       dE  note\n";

/// The rows `which` (indices into report.rows), a blank line between scene
/// and friction groups.
std::string row_lines(const Report& report, const std::vector<std::size_t>& which) {
  std::string out;
  char line[512];
  std::string previous_group;
  for (const std::size_t i : which) {
    const ReportRow& r = report.rows[i];
    const std::string group = r.scene + (r.friction ? "1" : "0");
    if (!previous_group.empty() && group != previous_group) out += "\n";
    previous_group = group;
    std::snprintf(
        line, sizeof line,
        "%-7s %-4s %-9s %-11s %-8s %-6s %-6s %3d %9zu %8.2f %5.1f%% %9.3g %9.3g %9.2e %8.1e %8.1e %8.1e  %s\n",
        r.scene.c_str(), r.friction ? "mu" : "-", r.variant.c_str(), r.precision.c_str(), r.model.c_str(),
        r.isa.c_str(), r.layout.c_str(), r.threads, r.n, r.collisions_per_second / 1e6, 100.0 * r.bandwidth_fraction,
        r.max_err_eps, r.p99_err_eps, r.max_rel_err, r.momentum_drift, r.angular_momentum_drift, r.energy_drift,
        r.note.c_str());
    out += line;
  }
  return out;
}

/// The hard section (--hard), or nothing.
std::string hard_lines(const Report& report) {
  if (report.hard.empty()) return {};
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "\nhard scenes (--hard; collide/eval/hard_scenes.hpp): %zu pairs per pair family, the shared scenes at "
                "their sizes;\n"
                "  simd, 1 thread, solved by the model each scene is shaped for; err in eps x impulse scale vs long "
                "double\n"
                "  (fast mode's target %.0f), ulps = max |J-Jref| / (eps |Jref|) vs the exact law (accurate mode's "
                "bound %.0f;\n"
                "  shared scenes: each contact on the state stored before it).\n",
                report.hard_n, kImpulseErrorTargetEps, kAccurateErrorUlps);
  out += line;
  out +=
      "family             model    precision mode      isa      n    act  Mcoll/s   max err   p99 err     max ulps\n";
  std::string previous;
  for (const HardRow& h : report.hard) {
    if (!previous.empty() && h.family != previous) out += "\n";
    previous = h.family;
    const std::string ulps = std::isnan(h.max_err_ulps) ? "n/a" : format("%.4g", h.max_err_ulps);
    std::snprintf(line, sizeof line, "%-18s %-8s %-9s %-8s %-6s %6zu %6zu %8.2f %9.3g %9.3g %12s\n", h.family.c_str(),
                  h.model.c_str(), h.precision.c_str(), h.mode.c_str(), h.isa.c_str(), h.n, h.acting,
                  h.collisions_per_second / 1e6, h.max_err_eps, h.p99_err_eps, ulps.c_str());
    out += line;
  }
  return out;
}

/// The residual the convergence section's summary line asks for.
constexpr double kConvergedResidual = 0.01;

/// The fewest passes of the convergence rows of `scene`, `order`,
/// `iteration` and `warm` that reach kConvergedResidual: "4", or "more than
/// 32" when none of them does.
std::string passes_to_converge(const Report& report, const std::string& scene, const std::string& order,
                               const std::string& iteration, bool warm) {
  int most = 0;
  for (const ConvergenceRow& c : report.convergence) {
    if (c.scene != scene || c.order != order || c.iteration != iteration || c.warm != warm) continue;
    if (c.residual <= kConvergedResidual) return std::to_string(c.passes);
    most = std::max(most, c.passes);
  }
  return "more than " + std::to_string(most);
}

/// The convergence section, or nothing: per scene and order a line of
/// residuals per mode, over the pass counts of the cold rows.
std::string convergence_lines(const Report& report) {
  if (report.convergence.empty()) return {};
  const ConvergenceRow& first = report.convergence.front();
  std::vector<int> passes;
  for (const ConvergenceRow& c : report.convergence) {
    if (!c.warm && std::find(passes.begin(), passes.end(), c.passes) == passes.end()) passes.push_back(c.passes);
  }
  std::sort(passes.begin(), passes.end());
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "\nconvergence (simd %s float, frictionless, %d thread%s; %zu contacts per scene: a pile of %zu^3 "
                "boxes and a stack\n"
                "  of 16-box columns, contacts top first, at rest after one step of gravity, and debris as "
                "generated): the residual,\n"
                "  the last pass's largest change of a J over the largest J, after each number of passes; warm: "
                "accumulate from\n"
                "  the converged J; ms: the median time of the first column's solve.\n",
                first.isa.c_str(), first.threads, first.threads == 1 ? "" : "s", first.n, report.convergence_pile_side);
  out += line;
  // Indented, so that no line starts with a scene's name as the rows' lines do.
  out += "  scene  order  mode          ms";
  for (const int p : passes) out += format("%9.0f", p);
  out += "\n";
  const std::vector<ConvergenceRow>& rows = report.convergence;
  const auto same_line = [](const ConvergenceRow& x, const ConvergenceRow& y) {
    return x.scene == y.scene && x.order == y.order && x.iteration == y.iteration && x.warm == y.warm;
  };
  for (std::size_t i = 0; i < rows.size();) {
    const ConvergenceRow& head = rows[i];
    if (i > 0 && head.scene != rows[i - 1].scene) out += "\n";
    std::size_t end = i;
    while (end < rows.size() && same_line(rows[end], head)) ++end;
    std::snprintf(line, sizeof line, "  %-6s %-6s %-10s %7.2f", head.scene.c_str(), head.order.c_str(),
                  head.warm ? "warm" : head.iteration.c_str(), 1e3 * head.seconds);
    out += line;
    for (const int p : passes) {
      const auto it =
          std::find_if(rows.begin() + static_cast<std::ptrdiff_t>(i), rows.begin() + static_cast<std::ptrdiff_t>(end),
                       [p](const ConvergenceRow& c) { return c.passes == p; });
      if (it != rows.begin() + static_cast<std::ptrdiff_t>(end)) out += format("%9.2g", it->residual);
    }
    out += "\n";
    i = end;
  }
  out += "pile: " + passes_to_converge(report, "pile", "colour", "accumulate", false) +
         " passes (accumulate, colour) reach residual <= 0.01; warm-started: " +
         passes_to_converge(report, "pile", "colour", "accumulate", true) + "\n";
  out += "pile: " + passes_to_converge(report, "pile", "colour", "repeat", false) +
         " passes (repeat, colour) reach residual <= 0.01\n";
  return out;
}

/// "wall time 12.3 s (triad 1.0 s, ...)".
std::string wall_line(const Report& report) {
  char line[512];
  std::snprintf(line, sizeof line, "\nwall time %.1f s (", report.wall_seconds);
  std::string out = line;
  for (std::size_t i = 0; i < report.phase_seconds.size(); ++i) {
    std::snprintf(line, sizeof line, "%s%s %.1f s", i ? ", " : "", report.phase_seconds[i].first.c_str(),
                  report.phase_seconds[i].second);
    out += line;
  }
  return out + ")\n";
}

}  // namespace

std::string format_report_table(const Report& report) {
  std::string out = preamble(report) + kRowHeader;
  std::vector<std::size_t> all(report.rows.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  out += row_lines(report, all);
  out += convergence_lines(report);
  out += hard_lines(report);
  if (!report.sweep.empty()) {
    char line[512];
    out += "\nthroughput against N (pairs, simd float, frictionless):\n";
    out += "model         N  thr  runs  Mcoll/s     bw\n";
    for (const SweepPoint& p : report.sweep) {
      std::snprintf(line, sizeof line, "%-8s %9zu %4d %5d %8.2f %5.1f%%\n", p.model.c_str(), p.n, p.threads, p.runs,
                    p.collisions_per_second / 1e6, 100.0 * p.bandwidth_fraction);
      out += line;
    }
  }
  return out + wall_line(report);
}

std::string format_report_summary(const Report& report, const std::string& json_path, const std::string& plot_path) {
  const std::vector<std::size_t> frontier = report_frontier(report);
  std::string out = preamble(report);
  char line[512];
  std::snprintf(line, sizeof line,
                "speed against error: of each scene, the %zu of %zu rows that no other row beats on both (faster at "
                "no more\nerror, or less error at no less speed; kernel rows at the largest thread count), fastest "
                "first:\n\n",
                frontier.size(), report.rows.size());
  out += line;
  out += kRowHeader;
  out += row_lines(report, frontier);
  out += convergence_lines(report);
  out += hard_lines(report);
  out += "\nevery row: collide report --all";
  out += json_path.empty() ? ", or --json FILE" : "; as JSON: " + json_path;
  out += plot_path.empty() ? "; the plot: --plot FILE.png" : "; the plot: " + plot_path;
  if (!report.sweep.empty()) out += " (with the throughput against N)";
  out += "\n";
  return out + wall_line(report);
}

}  // namespace collide
