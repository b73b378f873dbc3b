// report/report_plot.cpp - the PNG of `collide report --plot`
// (write_report_plot): throughput against error, throughput against N, the
// convergence section and, with --hard, the hard scenes, drawn by gnuplot.
//
// Design notes
// ------------
// * Written from the same Report as the table and the JSON, so the three
//   agree.
// * The plot is drawn by gnuplot (gnuplot-nox, a declared dependency) from a
//   generated script and data files in a private temporary directory, run as
//   a subprocess; the PNG is written to a temporary name and renamed, like
//   every other output. gnuplot missing is reported, not hidden.
// * Panel 1 puts every variant of the pairs scene without friction on one
//   plane: throughput against the worst impulse error relative to the
//   contact's impulse scale (max_err_eps x eps: dimensionless, so float and
//   double variants share an axis). Kernel variants at the largest thread
//   count; the reference, the textbook loop and the peer are single-threaded.
//   The long double reference is the yardstick (error 0 by definition) and
//   is drawn at the left edge.
// * Panel 2 is the N sweep: throughput of the SIMD float kernel against the
//   number of pairs, with the bandwidth bound of each model as a horizontal
//   line and the N at which the model's working set (bytes_per_collision x N)
//   fills the L2 caches of the threads and the L3 as vertical lines.
// * Panel 3, the convergence section (unless --no-convergence): residual
//   against the kernel time of the solve, log-log, one line per scene,
//   order and mode over the pass counts, the warm rows a line of their own,
//   and the residual 0.01 as a dotted line: how much time each way to a
//   residual costs.
// * The last panel, only with --hard: every hard row (collide/eval/hard_scenes.hpp) as a
//   point, throughput against its max plain relative error (max_err_ulps x
//   eps), one series per mode and precision, so the cost and the gain of the
//   accurate mode on the hard cases are one picture.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "collide/eval/traffic.hpp"
#include "collide/model.hpp"
#include "report.hpp"
#include "report_format.hpp"

namespace collide {

namespace {

using report_detail::format;

/// Short label of a row for the plot: "simd float rigid".
std::string label(const ReportRow& r) {
  std::string s = r.variant;
  if (r.variant == "reference" || r.variant == "textbook" || r.variant == "bullet") return s + " " + r.precision;
  return s + " " + r.precision + " " + r.model;
}

/// A private temporary directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "collide-report-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("cannot create a temporary directory");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Runs argv without a shell; returns the exit status, 127 when it could not
/// be started. stdout and stderr go to `log`. posix_spawn rather than fork:
/// the process has worker threads, and nothing may allocate between a fork
/// and the exec.
int run_program(const std::vector<std::string>& argv, const std::string& log) {
  std::vector<char*> args;
  args.reserve(argv.size() + 1);
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  if (::posix_spawn_file_actions_init(&actions) != 0) return 127;
  ::posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  ::posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return 127;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return 127;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

/// True when `name` is an executable file on PATH.
bool on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + name;
    if (::access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

/// gnuplot's string syntax: single quotes, a quote doubled.
std::string gp_string(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

/// The convergence panel (residual against kernel time), or "" without
/// the section: one data file and one line per scene, order and mode (the
/// warm rows a mode of their own), written into `tmp`. Colour says the
/// scene, the dash the order, the point the mode.
std::string convergence_panel(const Report& report, const std::filesystem::path& tmp) {
  if (report.convergence.empty()) return {};
  std::map<std::string, std::string> data;  // by "scene order mode"
  std::vector<std::string> series;          // in the rows' order
  for (const ConvergenceRow& c : report.convergence) {
    const std::string key = c.scene + " " + c.order + " " + (c.warm ? "warm" : c.iteration);
    if (data.count(key) == 0) series.push_back(key);
    data[key] += format("%.6e", c.seconds) + " " + format("%.6e", c.residual) + "\n";
  }
  const std::map<std::string, std::string> scene_colour = {
      {"pile", "#d62728"}, {"stack", "#1f77b4"}, {"debris", "#2ca02c"}};
  const std::map<std::string, std::string> mode_point = {{"repeat", "pt 7"}, {"accumulate", "pt 5"}, {"warm", "pt 9"}};
  std::string plot;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const std::string& key = series[i];
    const std::string file = gp_string((tmp / ("convergence-" + std::to_string(i) + ".dat")).string());
    std::ofstream(tmp / ("convergence-" + std::to_string(i) + ".dat")) << data.at(key);
    std::istringstream words(key);
    std::string scene, order, mode;
    words >> scene >> order >> mode;
    if (!plot.empty()) plot += ", \\\n  ";
    plot += file + " using 1:2 with linespoints lw 1.5 " + (order == "colour" ? "dt 2 " : "dt 1 ") +
            (mode_point.count(mode) ? mode_point.at(mode) : std::string("pt 7")) + " lc rgb '" +
            (scene_colour.count(scene) ? scene_colour.at(scene) : std::string("#000000")) + "' title " + gp_string(key);
  }
  const ConvergenceRow& first = report.convergence.front();
  std::string gp = "unset arrow\nunset label\nunset ytics\nset ytics\nset autoscale xy\n";
  gp += "set title " +
        gp_string("Convergence: residual against kernel time, 1 to 32 passes (" + std::to_string(first.n) +
                  " contacts, simd float, " + std::to_string(first.threads) + " threads)") +
        "\n";
  gp +=
      "set xlabel 'seconds per solve (median)'\nset ylabel 'residual (largest change of a J in the last pass / "
      "largest J)'\n";
  gp += "set format x '%.0e'\nset format y '%.0e'\nset key bottom left box opaque font ',8'\n";
  gp += "plot " + plot + ", \\\n  0.01 with lines dt 3 lc rgb '#7f7f7f' title 'residual 0.01'\n";
  return gp;
}

}  // namespace

std::string write_report_plot(const Report& report, const std::string& png_path) {
  if (!on_path("gnuplot")) {
    return "gnuplot is not installed (Debian package gnuplot-nox; scripts/install-deps.sh installs it)";
  }
  TempDir dir;
  const std::filesystem::path& tmp = dir.path();

  // Panel 1 data: one file per family, so each gets its own colour.
  const int max_threads = report.machine.triad_threads.empty() ? 1
                                                               : *std::max_element(report.machine.triad_threads.begin(),
                                                                                   report.machine.triad_threads.end());
  constexpr double kZeroErrorAt = 1e-20;  // where the yardstick (error 0) is drawn on a log axis
  const char* const families[] = {"reference", "textbook", "bullet", "scalar", "simd", "accurate"};
  std::map<std::string, std::string> data;
  double min_error = 1;
  for (const ReportRow& r : report.rows) {
    if (r.scene != "pairs" || r.friction) continue;
    const bool kernel = is_kernel_variant(r.variant);
    if (kernel ? r.threads != max_threads : r.threads != 1) continue;
    double error = r.max_err_eps * r.eps;
    std::string text = label(r);
    if (error <= 0) {
      error = kZeroErrorAt;
      text += " (error 0: the yardstick)";
    } else {
      min_error = std::min(min_error, error);
    }
    // Data files quote strings with double quotes (single quotes are script syntax).
    std::replace(text.begin(), text.end(), '"', '\'');
    data[r.variant] += format("%.6e", error) + " " + format("%.6e", r.collisions_per_second) + " \"" + text + "\"\n";
  }
  for (const auto& [family, text] : data) {
    std::ofstream(tmp / (family + ".dat")) << text;
  }

  // Panel 2 data: one file per model.
  std::map<std::string, std::string> sweep;
  for (const SweepPoint& p : report.sweep) {
    sweep[p.model] += std::to_string(p.n) + " " + format("%.6e", p.collisions_per_second) + "\n";
  }
  for (const auto& [model, text] : sweep) {
    std::ofstream(tmp / ("sweep-" + model + ".dat")) << text;
  }

  // Panel 3 data: one file per mode and precision.
  std::map<std::string, std::string> hard;
  for (const HardRow& h : report.hard) {
    const double error =
        h.max_err_ulps > 0 ? h.max_err_ulps * (h.precision == "float" ? 0x1p-23 : 0x1p-52) : kZeroErrorAt;
    hard[h.mode + " " + h.precision] += format("%.6e", error) + " " + format("%.6e", h.collisions_per_second) + "\n";
  }
  for (const auto& [series, text] : hard) {
    std::string file = series;
    std::replace(file.begin(), file.end(), ' ', '-');
    std::ofstream(tmp / ("hard-" + file + ".dat")) << text;
  }
  const bool hard_panel = !hard.empty();
  const std::string convergence = convergence_panel(report, tmp);
  const int panels = 2 + (convergence.empty() ? 0 : 1) + (hard_panel ? 1 : 0);

  const std::filesystem::path out_png = std::filesystem::absolute(png_path);
  const std::filesystem::path temp_png = out_png.string() + ".tmp-" + std::to_string(::getpid()) + ".png";
  std::ostringstream gp;
  gp << "set terminal pngcairo size " << 800 * panels << ",760 font 'DejaVu Sans,10' noenhanced\n";
  gp << "set output " << gp_string(temp_png.string()) << "\n";
  gp << "set multiplot layout 1," << panels << " title "
     << gp_string("collide report: " + report.machine.cpu + ", " + std::to_string(report.machine.hardware_threads) +
                  " hardware threads, " + std::to_string(report.n) + " pairs per speed run")
     << " font ',12'\n";
  gp << "set logscale xy\nset grid xtics ytics mxtics mytics lc rgb '#dddddd'\nset key top left box opaque\n";
  gp << "set format x '%.0e'\nset format y '%.0s%c'\n";

  // Panel 1.
  gp << "set title 'Throughput against error (pairs, frictionless; kernel at " << max_threads
     << " threads, others at 1)'\n";
  gp << "set xlabel 'max |J - Jref| / impulse scale   (long double reference; eps float 1.2e-7, double 2.2e-16)'\n";
  gp << "set ylabel 'collisions per second'\n";
  gp << "set xrange [" << format("%.1e", kZeroErrorAt / 10) << ":1e-3]\n";
  gp << "set autoscale y\n";
  const std::map<std::string, std::string> colour = {{"reference", "#000000"}, {"textbook", "#7f7f7f"},
                                                     {"bullet", "#2ca02c"},    {"scalar", "#1f77b4"},
                                                     {"simd", "#d62728"},      {"accurate", "#9467bd"}};
  std::string plot1;
  for (const char* family : families) {
    if (data.count(family) == 0) continue;
    const std::string file = gp_string((tmp / (std::string(family) + ".dat")).string());
    const std::string c = colour.at(family);
    if (!plot1.empty()) plot1 += ", \\\n  ";
    plot1.append(file)
        .append(" using 1:2 with points pt 7 ps 1.4 lc rgb '")
        .append(c)
        .append("' title '")
        .append(family)
        .append("', \\\n  ")
        .append(file)
        .append(" using 1:2:3 with labels left offset 0.8,0 font ',8' tc rgb '")
        .append(c)
        .append("' notitle");
  }
  gp << "plot " << plot1 << "\n";

  // Panel 2.
  gp << "unset arrow\nunset label\n";
  gp << "set title 'Throughput against N (pairs, simd float, frictionless, " << max_threads << " threads)'\n";
  gp << "set xlabel 'pairs N'\nset ylabel 'collisions per second'\nset format x '%.0s%c'\n";
  gp << "set xrange [5e3:3e7]\nset key bottom right box opaque\n";
  double triad = 0;
  for (std::size_t i = 0; i < report.machine.triad_threads.size(); ++i) {
    if (report.machine.triad_threads[i] == max_threads) triad = report.machine.triad_bytes_per_second[i];
  }
  std::string plot2;
  double y_max = 0, y_min = std::numeric_limits<double>::infinity();
  for (const SweepPoint& p : report.sweep) {
    y_max = std::max(y_max, p.collisions_per_second);
    y_min = std::min(y_min, p.collisions_per_second);
  }
  const std::map<std::string, std::string> model_colour = {{"rigid", "#d62728"}, {"particle", "#1f77b4"}};
  int arrow = 1;
  for (const auto& [name, text] : sweep) {
    const Model model = name == "particle" ? Model::particle : name == "sphere" ? Model::sphere : Model::rigid;
    const double bytes = static_cast<double>(bytes_per_collision(model, sizeof(float), false));
    const double bound = triad > 0 ? triad / bytes : 0;
    y_max = std::max(y_max, bound);
    const std::string c = model_colour.count(name) ? model_colour.at(name) : "#000000";
    const std::string file = gp_string((tmp / ("sweep-" + name + ".dat")).string());
    if (!plot2.empty()) plot2 += ", \\\n  ";
    plot2.append(file)
        .append(" using 1:2 with linespoints pt 7 lw 2 lc rgb '")
        .append(c)
        .append("' title '")
        .append(name)
        .append(" (")
        .append(format("%.0f", bytes))
        .append(" B/collision)'");
    if (bound > 0) {
      plot2.append(", ")
          .append(format("%.6e", bound))
          .append(" with lines dt 2 lw 2 lc rgb '")
          .append(c)
          .append("' title '")
          .append(name)
          .append(" bandwidth bound (triad ")
          .append(format("%.1f", triad / 1e9))
          .append(" GB/s / ")
          .append(format("%.0f", bytes))
          .append(" B)'");
    }
    // Where the working set fills the L2 of the threads and the shared L3.
    const double l2 = static_cast<double>(report.machine.l2_bytes.value_or(0)) * max_threads / bytes;
    const double l3 = static_cast<double>(report.machine.l3_bytes.value_or(0)) / bytes;
    for (const auto& [n, what] : {std::pair<double, std::string>{l2, "L2"}, {l3, "L3"}}) {
      if (n <= 0) continue;
      gp << "set arrow " << arrow++ << " from " << format("%.4e", n) << ", graph 0 to " << format("%.4e", n)
         << ", graph 1 nohead dt 3 lw 1.5 lc rgb '" << c << "'\n";
      gp << "set label " << arrow << " " << gp_string(std::string(what).append(" full (").append(name).append(")"))
         << " at " << format("%.4e", n) << ", graph 0.98 rotate by 90 right offset -0.7,0 font ',8' tc rgb '" << c
         << "'\n";
    }
  }
  if (y_max > 0 && std::isfinite(y_min)) {
    const double lo = y_min / 3, hi = y_max * 2.5;
    gp << "set yrange [" << format("%.3e", lo) << ":" << format("%.3e", hi) << "]\n";
    // The range spans about a decade: label 1, 2, 5 x 10^k, not only decades.
    std::string tics;
    for (double decade = std::pow(10.0, std::floor(std::log10(lo))); decade <= hi; decade *= 10) {
      for (const double m : {1.0, 2.0, 5.0}) {
        const double y = m * decade;
        if (y < lo || y > hi) continue;
        const std::string text = y >= 1e9   ? format("%.0fG", y / 1e9)
                                 : y >= 1e6 ? format("%.0fM", y / 1e6)
                                            : format("%.0fk", y / 1e3);
        tics += (tics.empty() ? "" : ", ") + std::string("'") + text + "' " + format("%.6e", y);
      }
    }
    if (!tics.empty()) gp << "set ytics (" << tics << ")\n";
  }
  if (plot2.empty()) {
    gp << "set label 1 'no sweep' at graph 0.5, graph 0.5 center\nplot 1/0 notitle\n";
  } else {
    gp << "plot " << plot2 << "\n";
  }
  gp << convergence;  // panel 3, when the section ran
  if (hard_panel) {
    // The last panel: the hard scenes.
    gp << "unset arrow\nunset label\nunset ytics\nset ytics\nset autoscale y\n";
    gp << "set title "
       << gp_string("Hard scenes (--hard): throughput against error, fast and accurate (simd, 1 thread)") << "\n";
    gp << "set xlabel 'max |J - Jref| / |Jref| per scene (exact-law reference; 0 drawn at 1e-20)'\n";
    gp << "set ylabel 'collisions per second'\nset format x '%.0e'\nset format y '%.0s%c'\n";
    gp << "set xrange [" << format("%.1e", kZeroErrorAt / 10) << ":1e3]\nset key top left box opaque\n";
    const std::map<std::string, std::string> style = {{"fast float", "pt 7 lc rgb '#d62728'"},
                                                      {"fast double", "pt 9 lc rgb '#d62728'"},
                                                      {"accurate float", "pt 7 lc rgb '#9467bd'"},
                                                      {"accurate double", "pt 9 lc rgb '#9467bd'"}};
    std::string plot3;
    for (const auto& [series, text] : hard) {
      std::string file = series;
      std::replace(file.begin(), file.end(), ' ', '-');
      if (!plot3.empty()) plot3 += ", \\\n  ";
      plot3 += gp_string((tmp / ("hard-" + file + ".dat")).string()) + " using 1:2 with points ps 1.1 " +
               (style.count(series) ? style.at(series) : std::string("pt 7")) + " title " + gp_string(series);
    }
    gp << "plot " << plot3 << "\n";
  }
  gp << "unset multiplot\nset output\n";
  std::ofstream(tmp / "report.gp") << gp.str();

  const std::string log = (tmp / "gnuplot.log").string();
  const int status = run_program({"gnuplot", (tmp / "report.gp").string()}, log);
  std::error_code ec;
  if (status != 0 || !std::filesystem::exists(temp_png)) {
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    std::filesystem::remove(temp_png, ec);
    return "gnuplot failed (status " + std::to_string(status) + "): " + text.str();
  }
  std::filesystem::rename(temp_png, out_png, ec);
  if (ec) {
    std::filesystem::remove(temp_png, ec);
    return "cannot write " + png_path + ": " + ec.message();
  }
  return "";
}

}  // namespace collide
