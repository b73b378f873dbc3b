// report/hard_rows.cpp - the hard section of `collide report --hard`: every
// scene of hard::hard_scene_catalogue() (collide/eval/hard_scenes.hpp), float and
// double, solved in the fast and in the accurate mode, with speed and error
// in both modes' units.
//
// Design notes
// ------------
// * The scenes are the tests' (tests/hard/ builds them from the same
//   catalogue and seeds): pair families of `hard_n` pairs (1000 by
//   default, as the tests), the shared scenes at their fixed sizes.
// * Speed: the SIMD path at one thread on the default ISA (the shared
//   scenes are chains, a batch per link, so threads would measure the
//   schedule's barriers, not the arithmetic). The rule of
//   collide/eval/timing.hpp: one untimed warm-up solve, then timed solves,
//   each after an untimed restore of the stored bodies; the timed runs are
//   as many as fit about 20 ms, at least `runs` and at most 1000 (a hard
//   scene of 1000 contacts solves in microseconds); the median is reported.
// * Error, two units per row, for both modes:
//   - max_err_eps: |J - Jref| in the fast mode's unit, eps(T) times the
//     contact's impulse scale (error_bound.hpp), against
//     reference_solve<long double> carried through the scene, the figure
//     kImpulseErrorTargetEps (2) is the fast mode's target for;
//   - max_err_ulps: the plain relative error |J - Jref| / (eps(T) |Jref| +
//     denorm_min(T)), the accurate mode's unit (kAccurateErrorUlps, 8),
//     against the exact law in a precision that can judge it: long double
//     for float, __float128 for double where GCC has it (long double's 64
//     bits cannot judge double's accurate mode: a grazing contact turns its
//     5e-20 into thousands of double ulps). Without __float128 (the clang
//     builds) the double rows have no ulps figure: judge "none",
//     max_err_ulps NaN (null in the JSON, n/a in the table), no check.
//     On the shared scenes each contact is judged against the law applied
//     to the velocities as stored before it (the mode's own solve, one
//     contact at a time, which gives exactly the full solve's bytes): the
//     accurate mode promises each contact's evaluation, not to undo the
//     rounding of the state a chain stores (docs/collision-law.md,
//     "Accuracy modes").
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/eval/error_bound.hpp"
#include "collide/eval/hard_scenes.hpp"
#include "collide/eval/reference.hpp"
#include "collide/eval/timing.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "measure.hpp"

namespace collide::report_detail {

namespace {

using L = long double;

/// The reference that judges the plain relative error of T.
#if COLLIDE_HAS_FLOAT128
template <class T>
using Judge = std::conditional_t<std::is_same_v<T, float>, long double, __float128>;
#else
template <class T>
using Judge = long double;
#endif
/// Whether this build has a reference that can judge T's accurate mode:
/// long double judges float; double needs __float128.
template <class T>
constexpr bool kCanJudge = std::is_same_v<T, float> || !std::is_same_v<Judge<T>, L>;

template <class S>
S judge_sqrt(S x) {
  if constexpr (std::is_same_v<S, L>) {
    return std::sqrt(x);
  } else {
    // Newton on the long double root: 113 bits in two steps.
    S y = static_cast<S>(std::sqrt(static_cast<L>(x)));
    if (y == 0) return 0;
    y = (y + x / y) / 2;
    return (y + x / y) / 2;
  }
}

template <class T>
const char* judge_name() {
  if constexpr (!kCanJudge<T>) return "none";
  return std::is_same_v<Judge<T>, L> ? "long double" : "__float128";
}

/// Max over the contacts of |J - Jref| / (eps(T) |Jref| + denorm_min(T)).
template <class T, class S>
double max_ulps(const ImpulseView<const T>& j, const ImpulseView<const S>& ref) {
  double worst = 0;
  for (std::size_t k = 0; k < j.count; ++k) {
    const S dx = S(j.j.x[k]) - ref.j.x[k], dy = S(j.j.y[k]) - ref.j.y[k], dz = S(j.j.z[k]) - ref.j.z[k];
    const S err = judge_sqrt(dx * dx + dy * dy + dz * dz);
    const S mag = judge_sqrt(ref.j.x[k] * ref.j.x[k] + ref.j.y[k] * ref.j.y[k] + ref.j.z[k] * ref.j.z[k]);
    const S unit = S(std::numeric_limits<T>::epsilon()) * mag + S(std::numeric_limits<T>::denorm_min());
    const double ulps = static_cast<double>(err / unit);
    // A NaN impulse is the worst error.
    if (!(ulps <= worst)) worst = std::isnan(ulps) ? std::numeric_limits<double>::infinity() : ulps;
  }
  return worst;
}

/// The plain relative error of a shared scene's contacts, each against the
/// law applied to the state the solver stored before it.
template <class T>
double chain_max_ulps(const Scene<T>& scene, Model model, const Solver& solver) {
  using S = Judge<T>;
  BodyBuffer<T> state = scene.bodies;
  const ContactView<T> all = scene.contacts.view();
  double worst = 0;
  for (std::size_t k = 0; k < all.count; ++k) {
    const ContactView<T> one = contact_slice(all, k, 1);
    BodyBuffer<S> ref_bodies = convert_bodies<S>(std::as_const(state).view());
    const ContactBuffer<S> ref_contact = convert_contacts<S>(one);
    ImpulseBuffer<S> ref(1);
    reference_solve<S>(ref_bodies.view(), ref_contact.view(), ref.view());
    ImpulseBuffer<T> j(1);
    Schedule schedule;
    schedule.build(one, state.view());
    solver.solve(model, state.view(), one, j.view(), schedule);
    worst = std::max(worst, max_ulps<T, S>(std::as_const(j).view(), std::as_const(ref).view()));
  }
  return worst;
}

template <class T>
void measure_scene(const hard::HardScene& hs, const ReportOptions& options, std::vector<HardRow>& rows) {
  const Scene<T> scene = hard::build_hard_scene<T>(hs, options.hard_n);
  const ReferenceResult reference = reference_of(scene);
  ImpulseBuffer<Judge<T>> judged;
  if (!hs.shared && kCanJudge<T>) {
    Scene<Judge<T>> s = convert_scene<Judge<T>>(scene);
    judged.resize(s.contacts.size());
    reference_solve<Judge<T>>(s.bodies.view(), s.contacts.view(), judged.view());
  }
  Schedule schedule;
  schedule.build(scene.contacts.view(), scene.bodies.size(), scene.bodies.view().inv_mass);
  std::size_t acting = 0;
  for (const ReferenceContact<L>& d : reference.diagnostics) acting += d.jn > 0;

  for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
    SolverOptions so;
    so.path = Path::simd;
    so.threads = 1;
    so.accuracy = accuracy;
    const Solver solver(so);
    HardRow row;
    row.family = hs.family;
    row.model = to_string(hs.fit);
    row.precision = std::is_same_v<T, float> ? "float" : "double";
    row.mode = accuracy == Accuracy::fast ? "fast" : "accurate";
    row.shared = hs.shared;
    row.n = scene.contacts.size();
    row.acting = acting;
    row.judge = judge_name<T>();

    BodyBuffer<T> bodies = scene.bodies;
    ImpulseBuffer<T> j(scene.contacts.size());
    SolveStats stats;
    const RunTimes times = time_solve(
        RunPlan{options.runs, 0.02, 1000}, [&] { bodies = scene.bodies; },
        [&] { stats = solver.solve(hs.fit, bodies.view(), scene.contacts.view(), j.view(), schedule); });
    row.threads = 1;
    row.isa = to_string(stats.isa);
    row.runs = times.runs();
    row.seconds = times.median;
    row.collisions_per_second = row.seconds > 0 ? static_cast<double>(row.n) / row.seconds : 0;

    ReportRow errors;
    fill_error<T>(errors, std::as_const(j).view(), std::as_const(bodies).view(), reference,
                  static_cast<double>(std::numeric_limits<T>::epsilon()));
    row.max_err_eps = errors.max_err_eps;
    row.p99_err_eps = errors.p99_err_eps;
    if constexpr (kCanJudge<T>) {
      row.max_err_ulps = hs.shared ? chain_max_ulps(scene, hs.fit, solver)
                                   : max_ulps<T, Judge<T>>(std::as_const(j).view(), std::as_const(judged).view());
    } else {
      row.max_err_ulps = std::numeric_limits<double>::quiet_NaN();  // not measured in this build
    }
    rows.push_back(std::move(row));
  }
}

}  // namespace

std::vector<HardRow> measure_hard_rows(const ReportOptions& options,
                                       const std::function<void(const std::string&)>& progress) {
  std::vector<HardRow> rows;
  for (const hard::HardScene& hs : hard::hard_scene_catalogue()) {
    const std::string what = "hard: " + hs.family + " (" + to_string(hs.fit) + ")";
    progress(what + " float");
    measure_scene<float>(hs, options, rows);
    if (hs.float_only) continue;
    progress(what + " double");
    measure_scene<double>(hs, options, rows);
  }
  return rows;
}

}  // namespace collide::report_detail
