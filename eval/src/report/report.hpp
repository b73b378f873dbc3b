// report.hpp - the report engine: speed against error of every
// variant of the solver (and the reference, the textbook loop, the Bullet
// peer) on the pairs, the debris and the pile scene, as rows, the
// convergence section (residual against time over passes), optionally the
// hard scenes of collide/eval/hard_scenes.hpp in both accuracy modes, and
// the writers of the table, the JSON and the plot. `collide report` and collide.report() in
// Python are thin shells over it.
//
// Design notes
// ------------
// * One Row is one variant measured on one scene: speed (median of timed
//   runs of the solve alone after an untimed warm-up, the rule of
//   collide/eval/timing.hpp) and error (against reference_solve<long double>
//   on an error sample). The same struct feeds the table, the JSON and the
//   plot, so the three can never disagree.
// * The peer (Bullet) lives in its own translation unit behind
//   COLLIDE_WITH_BULLET (src/report/bullet_row.cpp), so the report builds
//   and runs without it. The engine is its own library (collide_report), so
//   the core library never links Bullet.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace collide {

/// One measured variant.
struct ReportRow {
  std::string scene;      ///< "pairs", "debris", "pile", or "file" (ReportOptions::scene_bodies)
  std::string variant;    ///< "reference", "textbook", "scalar", "simd", "accurate" or "bullet"
  std::string model;      ///< "particle", "sphere" or "rigid"
  std::string precision;  ///< "float", "double" or "long double"
  bool simd = false;      ///< the SIMD path (lanes > 1)
  bool friction = false;  ///< the scene has mu > 0 (the Coulomb step runs)
  int threads = 1;
  std::size_t n = 0;      ///< collisions per timed solve
  std::size_t lanes = 1;  ///< SIMD width of the path
  /// Instruction set the row's code ran with: the SIMD kernel's ISA for simd
  /// rows; "sse2", the x86-64 baseline everything else is compiled for, for
  /// the scalar path, the references, the textbook loop and Bullet.
  std::string isa = "sse2";
  std::string layout = "soa";  ///< body layout the kernel ran on ("soa" or "packed"; SolveStats::layout)
  /// The solve order (collide/schedule.hpp): "input", or "colour" for the
  /// pile's rows in the colour order, whose error is against the reference
  /// replaying that order.
  std::string order = "input";
  int runs = 0;        ///< timed runs (after one untimed warm-up); the speed is their median
  double seconds = 0;  ///< median time of one solve
  double collisions_per_second = 0;
  double bytes_per_collision = 0;     ///< traffic.hpp, in the row's precision
  double bandwidth_fraction = 0;      ///< collisions/s x bytes / triad bandwidth (same thread count)
  std::size_t error_sample = 0;       ///< contacts compared with the reference
  double eps = 0;                     ///< machine epsilon of the row's precision
  double max_err_eps = 0;             ///< max |J - Jref| / (eps impulse_scale)
  double p99_err_eps = 0;             ///< 99th percentile of the same
  double max_rel_err = 0;             ///< max |J - Jref| / |Jref| over |Jref| > 0
  double momentum_drift = 0;          ///< |P - Pref| / sum m|v| (initial)
  double angular_momentum_drift = 0;  ///< |L - Lref| / sum (|p x m v| + |I w|) (initial)
  double energy_drift = 0;            ///< |E - Eref| / E (initial)
  std::string note;                   ///< how the row differs from the others, if it does
};

/// True for the rows of collide's own kernel: "scalar", "simd" and
/// "accurate" (the SIMD path with SolverOptions::accuracy = accurate).
/// Defined in report_order.cpp.
bool is_kernel_variant(const std::string& variant);

/// One hard scene (collide/eval/hard_scenes.hpp, the catalogue) measured in one
/// precision and one accuracy mode (`collide report --hard`): speed and
/// error, in the fast mode's unit and in the accurate mode's.
struct HardRow {
  std::string family;      ///< hard::hard_scene_catalogue() name ("mass-ratio", "cradle-mixed", ...)
  std::string model;       ///< the model the scene is shaped for and solved with (the cheapest that fits)
  std::string precision;   ///< "float" or "double"
  std::string mode;        ///< "fast" or "accurate" (SolverOptions::accuracy)
  bool shared = false;     ///< contacts share bodies (a chain: cradles, stars, the cluster)
  std::size_t n = 0;       ///< contacts of the scene
  std::size_t acting = 0;  ///< contacts with an impulse in the reference
  int threads = 1;
  std::string isa;  ///< the SIMD kernel's ISA
  int runs = 0;     ///< timed runs (after one untimed warm-up); the speed is their median
  double seconds = 0;
  double collisions_per_second = 0;
  double max_err_eps = 0;  ///< max |J - Jref| / (eps impulse_scale), the fast mode's unit (error_bound.hpp)
  double p99_err_eps = 0;  ///< 99th percentile of the same
  /// Max plain relative error of J in ulps of the precision, |J - Jref| /
  /// (eps |Jref| + denorm_min), the accurate mode's unit (kAccurateErrorUlps).
  /// Shared scenes: each contact against the law applied to the velocities
  /// as stored before it, which the mode's own solve leaves.
  double max_err_ulps = 0;
  /// Precision of the reference for max_err_ulps: "long double" (float),
  /// "__float128" (double), or "none" for double in a build without
  /// __float128, where max_err_ulps is NaN (not measured).
  std::string judge;
};

/// One solve of the convergence section (convergence_rows.cpp): a pile, a
/// stack or debris solved by the SIMD path (float, frictionless, fast mode)
/// with some passes in one order and one iteration mode, cold or warm-started.
struct ConvergenceRow {
  std::string scene;      ///< "pile", "stack" or "debris"
  std::string order;      ///< "input" or "colour" (SolverOptions::order)
  std::string iteration;  ///< "repeat" or "accumulate" (SolverOptions::iteration)
  int passes = 1;         ///< SolverOptions::passes
  /// Started from the converged J of the same scene (SolverOptions::warm_start;
  /// accumulate only), else from zero.
  bool warm = false;
  std::size_t n = 0;  ///< contacts of the scene
  int threads = 1;
  std::string isa;
  int runs = 0;        ///< timed runs (after one untimed warm-up); the speed is their median
  double seconds = 0;  ///< median time of one solve (all its passes)
  /// Contact visits per second: n x passes / seconds (the warm start's own
  /// two visits before the first pass are not counted).
  double collisions_per_second = 0;
  double residual = 1;  ///< SolveStats::residual of the solve
  /// Warm rows: the residual of the converged solve whose J they start from
  /// (how converged that J is); 1 for the cold rows, which start from 0.
  double start_residual = 1;
  /// One more pass (repeat, passes 1) on the solved bodies: its largest |J|
  /// over the solve's largest |J| (0 when the solve's J are all 0).
  double next_pass = 0;
};

/// One point of the throughput-against-N sweep (pairs scene, SIMD, float).
struct SweepPoint {
  std::string model;
  std::size_t n = 0;
  int threads = 1;
  int runs = 0;  ///< timed runs (after one untimed warm-up); the rate is n over their median
  double collisions_per_second = 0;
  double bandwidth_fraction = 0;
};

/// What Isa::automatic picks on the machine of the run for one kind of solve
/// (collide::fastest_isa, measured in the report's own process).
struct IsaAutoPick {
  std::string precision;           ///< "float" or "double"
  std::string model;               ///< "particle", "sphere" or "rigid"
  std::string accuracy;            ///< "fast" or "accurate"
  bool scattered = false;          ///< a scattered scene (debris-like), else streaming (pairs-like)
  std::string isa;                 ///< the pick
  double calibration_seconds = 0;  ///< time the measurement took
  /// Best pass of each ISA measured, in ns per contact, named by the ISA ("sse2", ...).
  std::vector<std::pair<std::string, double>> ns_per_contact;
};

/// Facts about the machine the numbers came from.
struct MachineInfo {
  std::string cpu;
  unsigned hardware_threads = 0;
  std::optional<std::size_t> l1d_bytes, l2_bytes, l3_bytes;  ///< one instance each; nullopt = unknown
  std::vector<int> triad_threads;                            ///< thread counts measured
  std::vector<double> triad_bytes_per_second;                ///< best pass (the bound), same order
  std::vector<double> triad_median_bytes_per_second;         ///< median pass, same order
  std::size_t triad_array_bytes = 0;
  std::string simd_build;             ///< e.g. "avx512 (of sse2, avx2, avx512): 16 float / 8 double lanes"
  std::vector<IsaAutoPick> isa_auto;  ///< every precision x accuracy x model x scene kind
  double load_average = -1;
};

/// The whole run, as the writers see it.
struct Report {
  MachineInfo machine;
  std::size_t n = 0;          ///< collisions of the pairs scene
  std::size_t debris_n = 0;   ///< collisions of the debris scene
  std::size_t pile_n = 0;     ///< collisions of the pile scene (pile_contact_count(pile_side))
  std::size_t pile_side = 0;  ///< boxes per side of the pile scene
  std::size_t error_sample = 0;
  bool quick = false;
  double wall_seconds = 0;
  /// Wall time of each phase ("triad", "pairs", "debris", "pile", "convergence", "hard", "sweep"), for budgeting.
  std::vector<std::pair<std::string, double>> phase_seconds;
  std::vector<ReportRow> rows;
  std::vector<SweepPoint> sweep;
  std::size_t hard_n = 0;     ///< pairs of each hard pair family (0: no hard section)
  std::vector<HardRow> hard;  ///< the hard section (--hard), in catalogue order
  std::string peer_status;    ///< "bullet 3.24" or why there is no peer row
  /// Boxes per side of the convergence section's pile (0: no section); its
  /// stack and debris have about as many contacts.
  std::size_t convergence_pile_side = 0;
  std::vector<ConvergenceRow> convergence;  ///< the convergence section, in its order (convergence_rows.cpp)
};

// ---------------------------------------------------------------------------
// The run (src/report/run_report.cpp; its scenes in report_scenes.cpp, the
// machine block in report_machine.cpp).
// ---------------------------------------------------------------------------

/// What to measure; the defaults are `collide report` without options.
struct ReportOptions {
  std::size_t n = 1000000;            ///< collisions of the pairs scene
  std::vector<int> threads = {1, 2};  ///< thread counts of the kernel rows
  std::size_t sample = 100000;        ///< contacts of the error sample
  int runs = 3;                       ///< timed runs per row (the median is reported)
  std::uint64_t seed = 1;             ///< scene seed
  bool quick = false;                 ///< a smoke run: short triad, sample of at most n
  std::size_t debris_n = 1000000;     ///< collisions of the debris scene
  /// Collisions of the pile scene (generate_pile): the largest cubic pile
  /// with at most this many contacts (1000000: 69^3 boxes, 976005 contacts).
  std::size_t pile_n = 1000000;
  std::size_t slow_n = 200000;       ///< contacts of the slow (single-threaded, unvectorised) rows
  std::vector<std::size_t> sweep_n;  ///< N of the throughput sweep; empty: no sweep
  /// The hard section: every scene of hard::hard_scene_catalogue() in float
  /// and double, fast and accurate, SIMD at one thread (`--hard`).
  bool hard = false;
  std::size_t hard_n = 1000;  ///< pairs of each hard pair family (the shared scenes have fixed sizes)
  /// The convergence section: a pile, a stack and debris solved with 1 to
  /// 32 passes in both orders and both iteration modes, and warm-started;
  /// the residual against the kernel time (`--no-convergence` turns it off).
  bool convergence = true;
  /// Contacts of each scene of the convergence section: the pile is the
  /// largest with at most this many (188800: 40^3 boxes), the stack and the
  /// debris have the pile's count (`collide report --quick` asks for
  /// kQuickConvergenceN unless told otherwise).
  std::size_t convergence_n = 188800;
  /// A scene of the caller's, measured beside the generated scenes as the rows of
  /// scene "file" (both empty: none): its bodies and contacts files, CSV or
  /// binary (.npz) by name, in float and double, its own friction, the
  /// models it fits; the error sample and the slow rows on its first
  /// contacts.
  std::string scene_bodies, scene_contacts;
};

/// The convergence section's size in `collide report --quick`: a pile of
/// 8^3 boxes, small enough to add well under a second.
inline constexpr std::size_t kQuickConvergenceN = 1408;

/// Measures every row (and the sweep) and returns them in canonical order
/// (sort_report_rows). Progress goes to stderr only when it is a terminal.
/// Throws std::invalid_argument for options out of range.
Report measure_report(const ReportOptions& options);

/// One kernel row's speed alone, timed as measure_report times it (the same
/// functions): the SIMD path on default_isa(), fast mode, rigid model, float,
/// without friction, at options.threads.front() threads, options.runs timed
/// runs, on the generated `scene` ("pairs", "debris" or "pile") of options.n,
/// debris_n or pile_n collisions and options.seed. No error sample (the error
/// columns are 0) and no triad (bandwidth_fraction 0); note "speed only".
/// For the check that compares the instruments (collide_bench
/// --timing-check). Throws std::invalid_argument as measure_report does, and
/// for another scene.
ReportRow measure_kernel_speed(const ReportOptions& options, const std::string& scene);

/// Only the N sweep's points of one model ("rigid" or "particle"), timed as
/// measure_report times them: options.sweep_n on the largest thread count of
/// options.threads, runs chosen as the sweep chooses them (options.quick
/// included). No triad (bandwidth_fraction 0). Empty for an empty sweep_n.
std::vector<SweepPoint> measure_sweep_report(const ReportOptions& options, const std::string& model);

/// Only the hard section (the rows `collide report --hard` adds), for
/// callers that want it alone (the Python module's report_hard()). Reads
/// hard_n and runs, checked as measure_report checks them.
std::vector<HardRow> measure_hard_report(const ReportOptions& options);

/// Only the convergence section, for callers that want it alone (the
/// Python module's report_convergence()). Reads convergence_n, seed, runs
/// and threads (the largest count), checked as measure_report checks them.
std::vector<ConvergenceRow> measure_convergence_report(const ReportOptions& options);

// ---------------------------------------------------------------------------
// Output: the order (report_order.cpp), the table (report_table.cpp), the
// JSON (report_json.cpp) and the plot (report_plot.cpp).
// ---------------------------------------------------------------------------

/// Puts the rows into the canonical order of the table and the JSON.
void sort_report_rows(Report& report);
/// The speed-against-error frontier of each scene and friction setting: the
/// indices of the rows (in canonical order, see sort_report_rows) that no
/// other row of the group beats, being faster at no more error or less
/// erroneous at no less speed; error is max_err_eps x eps, kernel rows count
/// at the largest thread count of the run. Group by group, fastest first.
std::vector<std::size_t> report_frontier(const Report& report);
/// The fixed-width table printed on stdout by `collide report --all`: every row.
std::string format_report_table(const Report& report);
/// What `collide report` prints by default: the run and the machine, the
/// frontier rows (report_frontier), the hard section when measured, where
/// every row is (`json_path`, `plot_path`: empty when not written) and the
/// wall time.
std::string format_report_summary(const Report& report, const std::string& json_path, const std::string& plot_path);
/// The JSON document: {"machine": ..., "rows": [one object per row], "hard": [one object per
/// hard row; empty without --hard], "convergence": [one object per convergence row; empty
/// without the section], "sweep": [...]}.
std::string format_report_json(const Report& report);
/// Writes the PNG with gnuplot. Returns "" on success, or why it failed.
std::string write_report_plot(const Report& report, const std::string& png_path);

}  // namespace collide
