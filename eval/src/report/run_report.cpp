// report/run_report.cpp - the engine of `collide report` (and of
// collide.report() in Python): speed against error for every variant, on the
// pairs, the debris and the pile scene. The shells print and write what it
// returns. This file holds the Runner, which measures the rows, and the
// entry points; the scenes come from report_scenes.cpp, the machine block
// from report_machine.cpp.
//
// Design notes
// ------------
// * Speed: every timed row, the N sweep's points and the hard rows follow
//   the rule of collide/eval/timing.hpp (time_solve): one untimed warm-up
//   solve, then `runs` timed solves of the full scene (--n collisions),
//   each after an untimed restore of the velocities from a saved copy, the
//   restore before the warm-up included; only the solve call is timed
//   (Solver::solve for the kernel). The median run is the row's speed, so
//   one run disturbed by another process does not move it. The schedule is
//   built once per scene, as a user solving every frame would do.
//   measure_kernel_speed() and measure_sweep_report() time one kernel row
//   and the sweep by the same functions as the run, for the check that
//   compares the instruments (collide_bench --timing-check).
// * The bandwidth bound: bandwidth_fraction() (timing.hpp), collisions/s x
//   bytes_per_collision(model, sizeof(T), friction) (traffic.hpp) / triad
//   bandwidth (bandwidth.hpp) measured at the same thread count at the start
//   of the same run.
// * Error: each variant also solves an error sample (its own scene of
//   --sample contacts; for the pairs scene that is exactly the first pairs of
//   the full scene, since pair k depends only on (seed, k); for the pile, the
//   largest pile of at most --sample contacts), and its impulses
//   and final bodies are compared with reference_solve<long double> on
//   exactly the same stored inputs (convert_scene, no renormalising). The
//   error columns are defined in docs/report.md.
// * Models: the generated scenes need the rigid model. The sphere and the
//   particle rows run on scenes derived from them in place (sphere: every
//   inverse moment set to the x one; particle: inverse moments 0 and w = 0),
//   checked with model_misfit(), so every row is the law's result for its
//   scene. Deriving in place, rigid then sphere then particle, needs no copy
//   of a scene of millions of bodies.
// * Budget (the default run is README command 1 and must take a few
//   minutes on a 2-core machine): the pairs scene has --n collisions (1M by
//   default); the debris scene min(--n, 1M) unless --debris-n says otherwise,
//   because its random body accesses make it several times slower per
//   collision (latency-bound gathers), and its kernel rows at 4M debris
//   collisions alone would take minutes
//   (docs/decisions/0014-the-reports-default-run.md). The pile scene likewise has at most
//   min(--n, 1M) contacts unless --pile-n says otherwise (the largest cubic
//   pile within it: 69^3 boxes, 976005 contacts); its contacts reach nearby
//   bodies in cell order, but share them in chains some 9 x side batches
//   deep. The slow rows (the reference in long double and in double, the
//   textbook loop, the Bullet peer; single-threaded by nature) are timed on
//   the first slow_n contacts only (200k by default, report.hpp), which
//   keeps each to a second or so; the row's n and note say so.
// * The N sweep (panel 2 of the plot) runs on prefixes of one pairs scene of
//   the largest N: the first N pairs of the pairs scene are the N-pair scene.
// * The convergence section (convergence_rows.cpp) runs after the three
//   scenes: residual against time for 1 to 32 passes on a resting pile, a
//   stack and debris, in a scene size of its own (--convergence-n).
// * The hard section (--hard, hard_rows.cpp) runs after the convergence section:
//   every hard scene of collide/eval/hard_scenes.hpp in both accuracy modes.
// * A kernel variant whose error exceeds kImpulseErrorBoundEps makes the
//   command exit 3, like `solve --check` (and a hard row of the accurate
//   mode above kAccurateErrorUlps); the table and files are written first.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/eval/timing.hpp"
#include "collide/eval/traffic.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/rules.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "measure.hpp"
#include "report.hpp"
#include "report_run.hpp"

namespace collide {

namespace {

using namespace report_detail;

using Clock = std::chrono::steady_clock;
using L = long double;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// ---------------------------------------------------------------------------
// Progress on a terminal.
// ---------------------------------------------------------------------------

/// "collide report: [12/98] pairs float friction: simd rigid, 2 threads" on
/// stderr, rewritten in place; nothing when stderr is not a terminal, so logs
/// and tests see no carriage returns.
class Progress {
 public:
  explicit Progress(std::size_t total) : total_(total), enabled_(::isatty(STDERR_FILENO) != 0) {}
  ~Progress() { clear(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void step(const std::string& what) {
    ++done_;
    show(what);
  }
  void show(const std::string& what) const {
    if (!enabled_) return;
    std::fprintf(stderr, "\r\033[Kcollide report: [%zu/%zu] %s", std::min(done_, total_), total_, what.c_str());
    std::fflush(stderr);
  }
  void clear() const {
    if (enabled_) std::fputs("\r\033[K", stderr);
  }

 private:
  std::size_t total_;
  std::size_t done_ = 0;
  bool enabled_;
};

// ---------------------------------------------------------------------------
// Timed runs.
// ---------------------------------------------------------------------------

/// The velocities of the first `count` bodies, saved so that every timed run
/// starts from the same state.
template <class T>
class SavedVelocities {
 public:
  void save(const BodyView<T>& b, std::size_t count) {
    T* const src[6] = {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
    for (int c = 0; c < 6; ++c) saved_[c].assign(src[c], src[c] + count);
  }
  void restore(const BodyView<T>& b) const {
    T* const dst[6] = {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z};
    for (int c = 0; c < 6; ++c) std::copy(saved_[c].begin(), saved_[c].end(), dst[c]);
  }

 private:
  std::vector<T> saved_[6];
};

/// A row as measure_report starts it: what ran, on which scene; the
/// figures follow.
ReportRow new_row(SceneKind kind, const char* variant, Model model, const char* precision, bool friction, int threads,
                  std::size_t n, std::size_t error_sample) {
  ReportRow row;
  row.scene = scene_name(kind);
  row.variant = variant;
  row.model = to_string(model);
  row.precision = precision;
  row.friction = friction;
  row.threads = threads;
  row.n = n;
  row.error_sample = error_sample;
  return row;
}

/// The speed columns of `row` from its timed runs: the median's rate and its
/// fraction of the bandwidth bound at the row's thread count
/// (`triad_bytes_per_second` 0: unknown, fraction 0).
void finish_speed(ReportRow& row, const RunTimes& times, std::size_t value_bytes, Model model,
                  double triad_bytes_per_second) {
  row.runs = times.runs();
  row.seconds = times.median;
  row.collisions_per_second = row.seconds > 0 ? static_cast<double>(row.n) / row.seconds : 0;
  row.bytes_per_collision = static_cast<double>(bytes_per_collision(model, value_bytes, row.friction));
  row.bandwidth_fraction =
      bandwidth_fraction(row.collisions_per_second, model, value_bytes, row.friction, triad_bytes_per_second);
}

/// A kernel row's timed runs: `s` solving the whole scene by the rule of
/// collide/eval/timing.hpp (an untimed warm-up, the velocities restored
/// untimed before every solve, `runs` timed solves). `stats` is the last
/// solve's.
template <class T>
RunTimes time_kernel(const Solver& s, Model model, Scene<T>& scene, const SavedVelocities<T>& saved,
                     const Schedule& schedule, ImpulseBuffer<T>& impulses, int runs, SolveStats& stats) {
  const BodyView<T> bodies = scene.bodies.view();
  const ContactView<T> contacts = scene.contacts.view();
  return time_solve(
      runs, [&] { saved.restore(bodies); },
      [&] { stats = s.solve(model, bodies, contacts, impulses.view(), schedule); });
}

/// The sweep's timed runs at one N: about 0.2 s of them for small N, at
/// least 5 and at most 200, and 3 for the scenes of millions of pairs, whose
/// runs are long and steady; at most 5 with --quick.
RunPlan sweep_plan(std::size_t n, bool quick) {
  RunPlan plan = n >= 4000000 ? RunPlan::fixed(3) : RunPlan{5, 0.2, 200};
  if (quick) plan.at_most = std::min(plan.at_most, 5);
  return plan;
}

/// The N sweep of one model: `s` on the first N pairs of `scene` (float,
/// frictionless, the model's bodies) for every N of `sizes`, each N timed
/// by the rule of collide/eval/timing.hpp with sweep_plan(); `step` is told
/// each point before it runs.
void sweep_points(const Solver& s, Model model, Scene<float>& scene, const std::vector<std::size_t>& sizes, int threads,
                  bool quick, double triad_bytes_per_second, std::vector<SweepPoint>& out,
                  const std::function<void(const std::string&)>& step) {
  ImpulseBuffer<float> impulses(scene.contacts.size());
  SavedVelocities<float> saved;
  Schedule schedule;
  for (const std::size_t n : sizes) {
    step("sweep: simd float " + std::string(to_string(model)) + ", " + std::to_string(n) + " pairs, " +
         std::to_string(threads) + " thread(s)");
    BodyView<float> bodies = scene.bodies.view();
    bodies.count = 2 * n;
    ContactView<float> contacts = scene.contacts.view();
    contacts.count = n;
    ImpulseView<float> j = impulses.view();
    j.count = n;
    schedule.build(contacts, bodies);
    saved.save(bodies, bodies.count);
    const RunTimes times = time_solve(
        sweep_plan(n, quick), [&] { saved.restore(bodies); }, [&] { s.solve(model, bodies, contacts, j, schedule); });
    saved.restore(bodies);  // the next N saves the first pairs as generated, not as solved
    SweepPoint p;
    p.model = to_string(model);
    p.n = n;
    p.threads = threads;
    p.runs = times.runs();
    p.collisions_per_second = times.median > 0 ? static_cast<double>(n) / times.median : 0;
    p.bandwidth_fraction =
        bandwidth_fraction(p.collisions_per_second, model, sizeof(float), false, triad_bytes_per_second);
    out.push_back(p);
  }
}

/// The options of a kernel row's Solver.
SolverOptions kernel_options(Path path, int threads, Isa isa, Accuracy accuracy) {
  SolverOptions options;
  options.path = path;
  options.threads = threads;
  options.isa = isa;
  options.accuracy = accuracy;
  return options;
}

// ---------------------------------------------------------------------------
// The run.
// ---------------------------------------------------------------------------

using Config = ReportOptions;

constexpr Model kModels[] = {Model::rigid, Model::sphere, Model::particle};
constexpr std::pair<Path, Accuracy> kKernelVariants[] = {
    {Path::scalar, Accuracy::fast}, {Path::simd, Accuracy::fast}, {Path::simd, Accuracy::accurate}};

class Runner {
 public:
  Runner(const Config& config, Report& report) : config_(config), report_(report) {}

  void run() {
    progress_ = std::make_unique<Progress>(expected_rows() + config_.sweep_n.size() * 2);
    auto phase = Clock::now();
    auto end_phase = [&](const char* name) {
      report_.phase_seconds.emplace_back(name, seconds_since(phase));
      phase = Clock::now();
    };
    // The caller's files first: a file that cannot be read stops the report
    // before any measurement, not minutes into it.
    if (!config_.scene_bodies.empty()) {
      file_double_ = read_file_scene<double>();
      file_float_ = read_file_scene<float>();
      end_phase("read");
    }
    triad_ = measure_machine(config_, report_.machine, [&](const std::string& what) { progress_->show(what); });
    end_phase("triad");
    for (const SceneKind kind : {SceneKind::pairs, SceneKind::debris, SceneKind::pile}) {
      for (const bool friction : {false, true}) {
        run_scene<double>(kind, friction);
        run_scene<float>(kind, friction);
      }
      end_phase(scene_name(kind));
    }
    if (!config_.scene_bodies.empty()) {
      run_file_scene(*file_double_);
      file_double_.reset();
      run_file_scene(*file_float_);
      file_float_.reset();
      end_phase("file");
    }
    if (config_.convergence) {
      report_.convergence = measure_convergence_rows(config_, [&](const std::string& what) { progress_->show(what); });
      end_phase("convergence");
    }
    if (config_.hard) {
      report_.hard = measure_hard_rows(config_, [&](const std::string& what) { progress_->show(what); });
      end_phase("hard");
    }
    if (!config_.sweep_n.empty()) {
      run_sweep();
      end_phase("sweep");
    }
    progress_->clear();
  }

 private:
  // -- variants --------------------------------------------------------------

  [[nodiscard]] std::size_t expected_rows() const {
    const std::size_t kernel = std::size_t{2} /*precisions*/ * 3 /*models*/ * kernel_variants().size();
    const std::size_t slow = 2 /*reference ld, double*/ + 2 /*textbook float, double*/;
    std::size_t rows = std::size_t{3} /*scenes*/ * 2 /*friction*/ * (kernel + slow);
    rows += std::size_t{2} /*friction*/ * 2 /*precisions*/ * 3 /*models*/ *
            config_.threads.size();  // the pile's colour order
    if (!bullet_version().empty()) ++rows;
    return rows;
  }

  const Solver& solver(Path path, int threads, Isa isa, Accuracy accuracy) {
    auto& slot = solvers_[{
        (path == Path::simd ? 1 : 0) + 2 * static_cast<int>(isa) + (accuracy == Accuracy::accurate ? 16 : 0), threads}];
    if (!slot) slot = std::make_unique<Solver>(kernel_options(path, threads, isa, accuracy));
    return *slot;
  }

  /// The kernel rows of one scene: the SIMD path (the default ISA) and the
  /// SIMD path in the accurate mode (variant "accurate") at every thread
  /// count; the scalar path, and SIMD on every other ISA the CPU has, at the
  /// first. The scalar path gives the SIMD path's bits, so its rows are the
  /// baseline of the lanes' gain, which one thread count shows (at every
  /// count they would be a tenth of the default run). The default ISA is
  /// default_isa() (COLLIDE_ISA, else the widest), named, so that every row
  /// says which ISA it timed whatever Isa::automatic would measure; the
  /// machine block shows those picks.
  [[nodiscard]] std::vector<std::tuple<Path, int, Isa, Accuracy>> kernel_variants() const {
    std::vector<std::tuple<Path, int, Isa, Accuracy>> v;
    for (const auto& [path, accuracy] : kKernelVariants) {
      if (path == Path::scalar) {
        v.emplace_back(path, config_.threads.front(), default_isa(), accuracy);
        continue;
      }
      for (const int threads : config_.threads) v.emplace_back(path, threads, default_isa(), accuracy);
    }
    for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
      if (isa_supported(isa) && isa != default_isa()) {
        v.emplace_back(Path::simd, config_.threads.front(), isa, Accuracy::fast);
      }
    }
    return v;
  }

  // -- rows ------------------------------------------------------------------

  [[nodiscard]] std::size_t sample_size() const { return report_sample_size(config_); }

  void add(ReportRow row) {
    progress_->step(row.scene + " " + row.precision + (row.friction ? " friction" : "") + ": " + row.variant + " " +
                    row.model + ", " + std::to_string(row.threads) + " thread(s)");
    report_.rows.push_back(std::move(row));
  }

  template <class T>
  void run_scene(SceneKind kind, bool friction) {
    const std::string what = std::string(scene_name(kind)) + " " + precision_name<T>() + (friction ? " friction" : "");
    const std::size_t n = kind == SceneKind::pairs    ? config_.n
                          : kind == SceneKind::debris ? config_.debris_n
                                                      : config_.pile_n;
    progress_->show(what + ": generating " + std::to_string(n) + " collisions");
    Scene<T> scene = make_scene<T>(kind, n, friction, config_.seed);
    Scene<T> sample = make_scene<T>(kind, sample_size(), friction, config_.seed);
    measure_scene(kind, friction, scene, std::move(sample));
  }

  /// The caller's scene files: its own friction, and only the models it fits
  /// (its bodies are the caller's, not reshaped for a model).
  template <class T>
  [[nodiscard]] Scene<T> read_file_scene() {
    progress_->show(std::string("file ") + precision_name<T>() + ": reading " + config_.scene_bodies + " and " +
                    config_.scene_contacts);
    return read_scene_files<T>(config_.scene_bodies, config_.scene_contacts);
  }

  template <class T>
  void run_file_scene(Scene<T>& scene) {
    const Scene<T> sample = contact_prefix(scene, sample_size());
    measure_scene(SceneKind::file, scene.contacts.view().mu != nullptr, scene, sample);
  }

  template <class T>
  void measure_scene(SceneKind kind, bool friction, Scene<T>& scene, Scene<T> sample) {
    const std::string what = std::string(scene_name(kind)) + " " + precision_name<T>() + (friction ? " friction" : "");
    const std::size_t n = scene.contacts.size();
    Schedule schedule, sample_schedule;
    schedule.build(scene.contacts.view(), scene.bodies.view());
    sample_schedule.build(sample.contacts.view(), sample.bodies.view());
    // The pile also in the colour order collide chooses (collide/schedule.hpp).
    const bool colour_rows = kind == SceneKind::pile;
    Schedule colour_schedule(Order::colour), colour_sample_schedule(Order::colour);
    if (colour_rows) {
      colour_schedule.build(scene.contacts.view(), scene.bodies.view());
      colour_sample_schedule.build(sample.contacts.view(), sample.bodies.view());
    }
    ImpulseBuffer<T> impulses(scene.contacts.size());
    SavedVelocities<T> saved;

    for (const Model model : kModels) {
      if (kind == SceneKind::file) {
        if (!model_misfit(model, scene.bodies.view(), scene.contacts.view()).empty()) continue;
      } else if (model != Model::rigid) {
        derive_model(scene, model);
        derive_model(sample, model);
      }
      progress_->show(what + ": long double reference of the " + to_string(model) + " sample");
      const ReferenceResult reference = reference_of(sample);
      saved.save(scene.bodies.view(), scene.bodies.size());

      if (model == Model::rigid) {
        if constexpr (std::is_same_v<T, double>) {
          slow_reference_rows(kind, friction, scene, sample, reference);
        }
        textbook_row(kind, friction, scene, saved, sample, reference);
        if constexpr (std::is_same_v<T, float>) {
          if (kind == SceneKind::pairs && !friction && !bullet_version().empty()) {
            progress_->show(what + ": bullet");
            ReportRow row = bullet_row(scene, config_.slow_n, sample, reference, config_.runs, triad_bw(1));
            row.error_sample = sample.contacts.size();
            add(std::move(row));
            // Bullet wrote only its own copies; the scene is untouched.
          }
        }
      }

      for (const auto& [path, threads, isa, accuracy] : kernel_variants()) {
        {
          const Solver& s = solver(path, threads, isa, accuracy);
          ReportRow row = new_row(kind, accuracy == Accuracy::accurate ? "accurate" : to_string(path), model,
                                  precision_name<T>(), friction, threads, n, sample.contacts.size());
          row.simd = path == Path::simd;
          progress_->show(what + ": " + row.variant + " " + row.model + ", " + std::to_string(threads) + " thread(s)");
          measure_solver(row, s, model, scene, sample, saved, schedule, sample_schedule, impulses, reference);
          add(std::move(row));
        }
      }
      if (colour_rows) {
        colour_order_rows(kind, friction, model, scene, sample, saved, colour_schedule, colour_sample_schedule,
                          impulses);
      }
      // The velocities as generated, not as the last row's solve left them:
      // the next model's scene is derived from them and saved.
      saved.restore(scene.bodies.view());
    }
  }

  /// The SIMD path in the colour order at every thread count, its error
  /// against the reference replaying that order on the sample.
  template <class T>
  void colour_order_rows(SceneKind kind, bool friction, Model model, Scene<T>& scene, const Scene<T>& sample,
                         SavedVelocities<T>& saved, const Schedule& schedule, const Schedule& sample_schedule,
                         ImpulseBuffer<T>& impulses) {
    const std::string what = std::string(scene_name(kind)) + " " + precision_name<T>() + (friction ? " friction" : "");
    progress_->show(what + ": long double reference of the " + to_string(model) + " sample in the colour order");
    const ReferenceResult reference = reference_of(sample, sample_schedule.solve_order());
    for (const int threads : config_.threads) {
      const Solver& s = solver(Path::simd, threads, default_isa(), Accuracy::fast);
      ReportRow row = new_row(kind, "simd", model, precision_name<T>(), friction, threads, scene.contacts.size(),
                              sample.contacts.size());
      row.simd = true;
      row.order = "colour";
      row.note = "colour order";
      measure_solver(row, s, model, scene, sample, saved, schedule, sample_schedule, impulses, reference);
      add(std::move(row));
    }
  }

  /// A kernel row's figures: `s` timed on the scene (its velocities restored
  /// before each run), then its error on the sample, solved by the same
  /// solver, against `reference`.
  template <class T>
  void measure_solver(ReportRow& row, const Solver& s, Model model, Scene<T>& scene, const Scene<T>& sample,
                      SavedVelocities<T>& saved, const Schedule& schedule, const Schedule& sample_schedule,
                      ImpulseBuffer<T>& impulses, const ReferenceResult& reference) {
    SolveStats stats;
    const RunTimes times = time_kernel(s, model, scene, saved, schedule, impulses, config_.runs, stats);
    row.lanes = stats.lanes;
    row.isa = to_string(stats.isa);
    row.layout = to_string(stats.layout);
    finish_speed(row, times, sizeof(T), model, triad_bw(row.threads));
    BodyBuffer<T> after = sample.bodies;
    ImpulseBuffer<T> j(sample.contacts.size());
    s.solve(model, after.view(), sample.contacts.view(), j.view(), sample_schedule);
    fill_error<T>(row, std::as_const(j).view(), std::as_const(after).view(), reference,
                  std::numeric_limits<T>::epsilon());
  }
  double triad_bw(int threads) const {
    const auto it = triad_.find(threads);
    return it != triad_.end() ? it->second : 0;
  }

  /// The first slow_n contacts of a scene, with every body.
  template <class T>
  ContactView<T> slow_contacts(const Scene<T>& scene) const {
    ContactView<T> c = scene.contacts.view();
    c.count = std::min(c.count, config_.slow_n);
    return c;
  }

  /// reference_solve<long double> and <double> on the rigid double scene.
  void slow_reference_rows(SceneKind kind, bool friction, const Scene<double>& scene, const Scene<double>& sample,
                           const ReferenceResult& reference) {
    ContactView<double> contacts = slow_contacts(scene);
    // Pairs touch only their own two bodies, so the slow prefix needs only
    // the first 2 slow_n of them; debris contacts reach every body, and a
    // pile's bottom layer the ground, its last.
    BodyView<const double> body_src = scene.bodies.view();
    if (kind == SceneKind::pairs) body_src.count = std::min(body_src.count, 2 * contacts.count);
    // A file's prefix may touch any of its bodies: only those it touches.
    Scene<double> prefix;
    if (kind == SceneKind::file) {
      prefix = contact_prefix(scene, contacts.count);
      body_src = std::as_const(prefix.bodies).view();
      contacts = prefix.contacts.view();
    }
    {
      // long double: the yardstick itself (its error is 0 by definition; the
      // comparison still runs, as a check that it is deterministic).
      BodyBuffer<L> bodies = convert_bodies<L>(body_src);
      const ContactBuffer<L> ld_contacts = convert_contacts<L>(contacts);
      ImpulseBuffer<L> j(ld_contacts.size());
      SavedVelocities<L> saved;
      saved.save(bodies.view(), bodies.size());
      ReportRow row =
          new_row(kind, "reference", Model::rigid, "long double", friction, 1, contacts.count, sample.contacts.size());
      progress_->show(row.scene + ": reference long double");
      const RunTimes times = time_solve(
          config_.runs, [&] { saved.restore(bodies.view()); },
          [&] { reference_solve<L>(bodies.view(), ld_contacts.view(), j.view()); });
      finish_speed(row, times, sizeof(L), Model::rigid, triad_bw(1));
      if (contacts.count != scene.contacts.size()) row.note = "first " + std::to_string(contacts.count) + " contacts";

      Scene<L> s = convert_scene<L>(sample);
      ImpulseBuffer<L> sj(s.contacts.size());
      reference_solve<L>(s.bodies.view(), s.contacts.view(), sj.view());
      fill_error<L>(row, std::as_const(sj).view(), std::as_const(s.bodies).view(), reference,
                    static_cast<double>(std::numeric_limits<L>::epsilon()));
      add(std::move(row));
    }
    {
      BodyBuffer<double> bodies = convert_bodies<double>(body_src);
      ImpulseBuffer<double> j(contacts.count);
      SavedVelocities<double> saved;
      saved.save(bodies.view(), bodies.size());
      ReportRow row =
          new_row(kind, "reference", Model::rigid, "double", friction, 1, contacts.count, sample.contacts.size());
      progress_->show(row.scene + ": reference double");
      const RunTimes times = time_solve(
          config_.runs, [&] { saved.restore(bodies.view()); },
          [&] { reference_solve<double>(bodies.view(), contacts, j.view()); });
      finish_speed(row, times, sizeof(double), Model::rigid, triad_bw(1));
      if (contacts.count != scene.contacts.size()) row.note = "first " + std::to_string(contacts.count) + " contacts";

      BodyBuffer<double> after = sample.bodies;
      ImpulseBuffer<double> sj(sample.contacts.size());
      reference_solve<double>(after.view(), sample.contacts.view(), sj.view());
      fill_error<double>(row, std::as_const(sj).view(), std::as_const(after).view(), reference,
                         static_cast<double>(std::numeric_limits<double>::epsilon()));
      add(std::move(row));
    }
  }

  /// The plain textbook loop (textbook_solve, collide/eval/reference.hpp) on the rigid scene.
  template <class T>
  void textbook_row(SceneKind kind, bool friction, Scene<T>& scene, const SavedVelocities<T>& saved,
                    const Scene<T>& sample, const ReferenceResult& reference) {
    const ContactView<T> contacts = slow_contacts(scene);
    const BodyView<T> bodies = scene.bodies.view();
    ImpulseBuffer<T> j(contacts.count);
    ReportRow row = new_row(kind, "textbook", Model::rigid, precision_name<T>(), friction, 1, contacts.count,
                            sample.contacts.size());
    progress_->show(row.scene + ": textbook " + row.precision);
    const RunTimes times = time_solve(
        config_.runs, [&] { saved.restore(bodies); }, [&] { textbook_solve<T>(bodies, contacts, j.view()); });
    saved.restore(bodies);  // the kernel rows start from the generated state
    finish_speed(row, times, sizeof(T), Model::rigid, triad_bw(1));
    if (contacts.count != scene.contacts.size()) row.note = "first " + std::to_string(contacts.count) + " contacts";

    BodyBuffer<T> after = sample.bodies;
    ImpulseBuffer<T> sj(sample.contacts.size());
    textbook_solve<T>(after.view(), sample.contacts.view(), sj.view());
    fill_error<T>(row, std::as_const(sj).view(), std::as_const(after).view(), reference,
                  static_cast<double>(std::numeric_limits<T>::epsilon()));
    add(std::move(row));
  }

  // -- the N sweep -------------------------------------------------------------

  void run_sweep() {
    const int threads = *std::max_element(config_.threads.begin(), config_.threads.end());
    const std::size_t largest = *std::max_element(config_.sweep_n.begin(), config_.sweep_n.end());
    progress_->show("sweep: generating " + std::to_string(largest) + " pairs");
    Scene<float> scene = make_scene<float>(SceneKind::pairs, largest, false, config_.seed);
    const Solver& s = solver(Path::simd, threads, default_isa(), Accuracy::fast);
    for (const Model model : {Model::rigid, Model::particle}) {
      if (model != Model::rigid) derive_model(scene, model);
      sweep_points(s, model, scene, config_.sweep_n, threads, config_.quick, triad_bw(threads), report_.sweep,
                   [&](const std::string& what) { progress_->step(what); });
    }
  }

  const Config& config_;
  Report& report_;
  std::unique_ptr<Progress> progress_;
  std::map<int, double> triad_;
  /// The caller's scene in each precision, read before anything is measured.
  std::optional<Scene<double>> file_double_;
  std::optional<Scene<float>> file_float_;
  std::map<std::pair<int, int>, std::unique_ptr<Solver>> solvers_;
};

}  // namespace

// ---------------------------------------------------------------------------
// The run.
// ---------------------------------------------------------------------------

std::vector<HardRow> measure_hard_report(const ReportOptions& options) {
  if (options.runs < 1 || options.runs > 1000) throw std::invalid_argument("report: runs must be from 1 to 1000");
  if (options.hard_n < 1 || options.hard_n > 0x7FFFFFFFULL) {
    throw std::invalid_argument("report: hard_n must be from 1 to 2^31 - 1");
  }
  return measure_hard_rows(options, [](const std::string&) {});
}

namespace {

/// Throws std::invalid_argument for options out of the ranges of the usage
/// of `collide report`: pairs use 2n body ids, which are 32-bit.
void require_valid(const ReportOptions& options) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("report: ") + what);
  };
  require(options.n >= 1 && options.n <= 0x7FFFFFFFULL, "n must be from 1 to 2^31 - 1");
  require(options.debris_n >= 1 && options.debris_n <= 0xFFFFFFFFULL, "debris_n must be from 1 to 2^32 - 1");
  require(options.pile_n >= 1 && options.pile_n <= 0xFFFFFFFFULL, "pile_n must be from 1 to 2^32 - 1");
  require(options.sample >= 1 && options.sample <= 0x7FFFFFFFULL, "sample must be from 1 to 2^31 - 1");
  require(options.runs >= 1 && options.runs <= 1000, "runs must be from 1 to 1000");
  require(!options.threads.empty(), "threads needs at least one count");
  for (const int t : options.threads) require(t >= 1 && t <= 4096, "thread counts must be from 1 to 4096");
  for (const std::size_t n : options.sweep_n) {
    require(n >= 1 && n <= 0x7FFFFFFFULL, "sweep sizes must be from 1 to 2^31 - 1");
  }
  require(options.hard_n >= 1 && options.hard_n <= 0x7FFFFFFFULL, "hard_n must be from 1 to 2^31 - 1");
  require(options.convergence_n >= 1 && options.convergence_n <= 100000000,
          "convergence_n must be from 1 to 100000000");
  require(options.scene_bodies.empty() == options.scene_contacts.empty(),
          "a scene of files needs both its bodies and its contacts file");
}

}  // namespace

std::vector<ConvergenceRow> measure_convergence_report(const ReportOptions& options) {
  require_valid(options);
  return measure_convergence_rows(options, [](const std::string&) {});
}

ReportRow measure_kernel_speed(const ReportOptions& options, const std::string& scene) {
  require_valid(options);
  SceneKind kind = SceneKind::pairs;
  std::size_t n = options.n;
  if (scene == "debris") {
    kind = SceneKind::debris;
    n = options.debris_n;
  } else if (scene == "pile") {
    kind = SceneKind::pile;
    n = options.pile_n;
  } else if (scene != "pairs") {
    throw std::invalid_argument("report: the kernel speed's scene must be pairs, debris or pile, got '" + scene + "'");
  }
  Scene<float> s = make_scene<float>(kind, n, false, options.seed);
  Schedule schedule;
  schedule.build(s.contacts.view(), s.bodies.view());
  ImpulseBuffer<float> impulses(s.contacts.size());
  SavedVelocities<float> saved;
  saved.save(s.bodies.view(), s.bodies.size());
  const int threads = options.threads.front();
  const Solver solver(kernel_options(Path::simd, threads, default_isa(), Accuracy::fast));
  ReportRow row = new_row(kind, "simd", Model::rigid, "float", false, threads, s.contacts.size(), 0);
  row.simd = true;
  SolveStats stats;
  const RunTimes times = time_kernel(solver, Model::rigid, s, saved, schedule, impulses, options.runs, stats);
  row.lanes = stats.lanes;
  row.isa = to_string(stats.isa);
  row.layout = to_string(stats.layout);
  finish_speed(row, times, sizeof(float), Model::rigid, 0);
  row.note = "speed only";
  return row;
}

std::vector<SweepPoint> measure_sweep_report(const ReportOptions& options, const std::string& model) {
  require_valid(options);
  if (model != "rigid" && model != "particle") {
    throw std::invalid_argument("report: the sweep's model must be rigid or particle, got '" + model + "'");
  }
  std::vector<SweepPoint> points;
  if (options.sweep_n.empty()) return points;
  const int threads = *std::max_element(options.threads.begin(), options.threads.end());
  const std::size_t largest = *std::max_element(options.sweep_n.begin(), options.sweep_n.end());
  Scene<float> scene = make_scene<float>(SceneKind::pairs, largest, false, options.seed);
  const Model m = model == "rigid" ? Model::rigid : Model::particle;
  if (m != Model::rigid) derive_model(scene, m);
  const Solver solver(kernel_options(Path::simd, threads, default_isa(), Accuracy::fast));
  sweep_points(solver, m, scene, options.sweep_n, threads, options.quick, 0, points, [](const std::string&) {});
  return points;
}

Report measure_report(const ReportOptions& options) {
  require_valid(options);
  const auto t0 = Clock::now();
  Report report;
  report.n = options.n;
  report.debris_n = options.debris_n;
  report.pile_side = pile_side_for_contacts(options.pile_n);
  report.pile_n = pile_contact_count(report.pile_side);
  report.error_sample = report_sample_size(options);
  report.quick = options.quick;
  report.hard_n = options.hard ? options.hard_n : 0;
  report.convergence_pile_side = options.convergence ? convergence_pile_side(options) : 0;
  const std::string bullet = bullet_version();
  report.peer_status = bullet.empty() ? "not built (libbullet-dev was not found by pkg-config at configure time)"
                                      : bullet + ", btSequentialImpulseConstraintSolver";
  Runner(options, report).run();
  sort_report_rows(report);
  report.wall_seconds = seconds_since(t0);
  return report;
}

}  // namespace collide
