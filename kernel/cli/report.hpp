// cli/report.hpp - what the parts of `collide report` share: the rows it
// measures, the machine facts it states, and the writers of the table, the
// JSON and the plot.
//
// Design notes
// ------------
// * One Row is one variant measured on one scene: speed (median of timed
//   runs of the solve alone) and error (against reference_solve<long double>
//   on an error sample). The same struct feeds the table, the JSON and the
//   plot, so the three can never disagree.
// * The peer (Bullet) lives in its own translation unit behind
//   COLLIDE_WITH_BULLET, so the report builds and runs without it; the
//   measuring helpers it shares with the kernel rows (error statistics,
//   momentum and energy) are declared here.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/reference.hpp"
#include "collide/scene.hpp"

namespace collide::cli {

/// One measured variant.
struct ReportRow {
  std::string scene;      ///< "pairs" or "debris"
  std::string variant;    ///< "reference", "textbook", "scalar", "simd" or "bullet"
  std::string model;      ///< "particle", "sphere" or "rigid"
  std::string precision;  ///< "float", "double" or "long double"
  bool simd = false;      ///< the SIMD path (lanes > 1)
  bool friction = false;  ///< the scene has mu > 0 (the Coulomb step runs)
  int threads = 1;
  std::size_t n = 0;      ///< collisions per timed solve
  std::size_t lanes = 1;  ///< SIMD width of the path
  int runs = 0;           ///< timed runs; the speed is their median
  double seconds = 0;     ///< median time of one solve
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

/// One point of the throughput-against-N sweep (pairs scene, SIMD, float).
struct SweepPoint {
  std::string model;
  std::size_t n = 0;
  int threads = 1;
  int runs = 0;
  double collisions_per_second = 0;
  double bandwidth_fraction = 0;
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
  std::string simd_build;  ///< e.g. "AVX2: 8 float / 4 double lanes"
  double load_average = -1;
};

/// The whole run, as the writers see it.
struct Report {
  MachineInfo machine;
  std::size_t n = 0;         ///< collisions of the pairs scene
  std::size_t debris_n = 0;  ///< collisions of the debris scene
  std::size_t error_sample = 0;
  bool quick = false;
  double wall_seconds = 0;
  /// Wall time of each phase ("triad", "pairs", "debris", "sweep"), for budgeting.
  std::vector<std::pair<std::string, double>> phase_seconds;
  std::vector<ReportRow> rows;
  std::vector<SweepPoint> sweep;
  std::string peer_status;  ///< "bullet 3.24" or why there is no peer row
};

// ---------------------------------------------------------------------------
// Error against the reference (cmd_report.cpp).
// ---------------------------------------------------------------------------

/// Linear momentum, angular momentum about the origin (orbital p x m v plus
/// spin), kinetic energy, and the scales the drifts are divided by. Locked
/// axes (inverse moment 0) are left out of the spin terms: their spin never
/// changes, and their moment is infinite.
struct Totals {
  long double p[3] = {0, 0, 0};
  long double l[3] = {0, 0, 0};
  long double energy = 0;
  long double p_scale = 0;  ///< sum m |v|
  long double l_scale = 0;  ///< sum |p x m v| + |I w|
};
template <class T>
Totals body_totals(const BodyView<const T>& bodies);

/// The long double reference for one error sample.
struct ReferenceResult {
  ImpulseBuffer<long double> impulses;
  std::vector<ReferenceContact<long double>> diagnostics;
  Totals before, after;
};
/// Solves convert_scene<long double>(sample) with reference_solve<long double>.
template <class T>
ReferenceResult reference_of(const Scene<T>& sample);

/// Fills the error columns of `row` from a variant's impulses and final
/// bodies on the sample, in units of eps (the row's precision).
template <class T>
void fill_error(ReportRow& row, const ImpulseView<const T>& impulses, const BodyView<const T>& after,
                const ReferenceResult& reference, double eps);

/// Median of a list of run times.
double median(std::vector<double> values);

// ---------------------------------------------------------------------------
// The peer (cmd_report_bullet.cpp, only with COLLIDE_WITH_BULLET).
// ---------------------------------------------------------------------------

/// "bullet <version>" when the peer is compiled in, "" otherwise.
std::string bullet_version();
/// Measures btSequentialImpulseConstraintSolver on the first `n` contacts of
/// the pairs scene `scene` (frictionless, float), `runs` timed runs, and on
/// the error sample.
ReportRow bullet_row(const Scene<float>& scene, std::size_t n, const Scene<float>& sample,
                     const ReferenceResult& reference, int runs, double triad_bytes_per_second);

// ---------------------------------------------------------------------------
// Output (report_output.cpp).
// ---------------------------------------------------------------------------

/// Puts the rows into the canonical order of the table and the JSON.
void sort_rows(Report& report);
/// The fixed-width table printed on stdout.
std::string format_table(const Report& report);
/// The JSON document: {"machine": ..., "rows": [one object per row], "sweep": [...]}.
std::string format_json(const Report& report);
/// Writes the PNG with gnuplot. Returns "" on success, or why it failed.
std::string write_plot(const Report& report, const std::string& png_path);

}  // namespace collide::cli
