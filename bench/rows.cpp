// bench/rows.cpp - the bodies of collide_bench's rows: each takes its scene
// from the cache (scenes.hpp), times its solve and writes the common
// counters (support.hpp).
//
// Design notes
// ------------
// * Every row is timed by the rule of collide/eval/timing.hpp, the one
//   `collide report` follows for its rows and its N sweep (time_iterations,
//   support.hpp, drives collide::RunSeries inside Google Benchmark's loop):
//   one untimed warm-up solve before the loop, whatever the scene's size
//   (worker threads started, the solver's buffers sized and first touched);
//   before every solve, the warm-up's included, the scene is reset untimed
//   (Prepared::reset_for_solve: the pristine velocities back); only the
//   solve itself is timed; the row's figure is the median iteration.
//   Google Benchmark keeps its own loop, which decides how many iterations
//   run; the warm-up, the reset and the median are the shared rule.
// * What differs on purpose: for a scene larger than the LLC the reset also
//   streams the caches (scenes.hpp), so each solve starts cold, as a large
//   scene starts every frame; `collide report` does not, and such a row's
//   label ends in "cold caches". The twin rows (twin/, order_twin/) time
//   the memory traffic of a solve without its law (label "memory only").
// * The Schedule is built once per scene (untimed, it is reusable) and a
//   Solver once per row. Schedule::build has its own rows.
// * Isa::automatic measures the ISAs at the first solve of each kind in a
//   process; every row asks for that measurement before its timed loop, so
//   that no row times the one-off cost.
#include "rows.hpp"

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <type_traits>
#include <utility>

#include "collide/eval/traffic.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "memory_twin.hpp"
#include "packed_twin.hpp"
#include "support.hpp"
#include "textbook.hpp"

namespace collide_bench {
namespace {

using collide::Path;

/// Times `solve_once` by the rule (time_iterations): an untimed warm-up
/// solve, then the iterations, each solve after the scene's reset and then
/// `reset` (both untimed, the warm-up's too). Returns the median iteration.
template <class T, class F, class R = void (*)()>
double timed_solves(
    benchmark::State& state, Prepared<T>& p, F&& solve_once, R&& reset = [] {}) {
  const double seconds = time_iterations(state, solve_once, [&] {
    p.reset_for_solve();
    reset();
  });
  p.restore();
  return seconds;
}

/// What a row's label adds when its solves start from cold caches (a scene
/// larger than the LLC, scenes.hpp): ", cold caches" after `label`, or
/// "cold caches" alone; `label` unchanged otherwise.
template <class T>
std::string cache_label(const Prepared<T>& p, std::string label) {
  if (!p.exceeds_llc) return label;
  return label.empty() ? "cold caches" : label + ", cold caches";
}

/// Runs collide::fastest_isa's measurement for the model's solves, pairs and
/// scattered, before a row's timed loop.
template <class T>
void measure_isa_auto(collide::Model model, collide::Accuracy accuracy = collide::Accuracy::fast) {
  for (const bool scattered : {false, true}) (void)collide::fastest_isa<T>(model, accuracy, scattered);
}

/// The columns of a row that solves `n` contacts of `bytes_per_collision`
/// bytes each on `threads` threads.
Columns solve_columns(std::size_t n, std::size_t bytes_per_collision, double seconds, int threads) {
  Columns columns;
  columns.items = static_cast<double>(n);
  columns.bytes_per_item = static_cast<double>(bytes_per_collision);
  columns.seconds = seconds;
  columns.threads = threads;
  return columns;
}

/// "<model>, <layout>, <isa>, <lanes> lanes": what a model-dispatching solve
/// ran.
std::string model_label(const collide::SolveStats& stats) {
  return std::string(collide::to_string(stats.model)) + ", " + collide::to_string(stats.layout) + ", " +
         collide::to_string(stats.isa) + ", " + std::to_string(stats.lanes) + " lanes";
}

/// f(Record{}) with the packed record type of `model`: the one place the
/// layout and twin rows turn a model into a record type.
template <class T, class F>
auto with_record(collide::Model model, F&& f) {
  switch (model) {
    case collide::Model::particle:
      return f(collide::PackedParticle<T>{});
    case collide::Model::sphere:
      return f(collide::PackedSphere<T>{});
    case collide::Model::rigid:
      break;
  }
  return f(collide::PackedRigid<T>{});
}

/// The bench's rigid bodies packed into records of a model (they fit it:
/// Prepared scenes are generated for the model).
template <class T, class Record>
void pack_as(const collide::BodyView<T>& bodies, const collide::PackedView<Record>& view) {
  if constexpr (std::is_same_v<Record, collide::PackedRigid<T>>) {
    collide::pack(bodies, view);
  } else if constexpr (std::is_same_v<Record, collide::PackedSphere<T>>) {
    collide::pack(collide::sphere_view(bodies), view);
  } else {
    collide::pack(collide::particle_view(bodies), view);
  }
}

/// One model on one layout, the rigid view's arrays (SoA) or packed records.
template <class T, class Record>
double layout_solve(benchmark::State& state, Prepared<T>& p, const collide::Solver& solver, collide::Model model,
                    LayoutRow layout, collide::SolveStats& stats) {
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  if (layout != LayoutRow::records) {
    // The warm-up sizes the solver's buffers (packing, ordered contacts): a
    // frame loop pays that once, not per frame.
    return timed_solves(state, p, [&] { stats = solver.solve(model, bodies, contacts, impulses, p.schedule); });
  }
  collide::PackedBuffer<Record> records(bodies.count);
  const collide::PackedView<Record> view = collide::packed_view(records);
  return timed_solves(
      state, p, [&] { stats = solver.solve(view, contacts, impulses, p.schedule); }, [&] { pack_as(bodies, view); });
}

/// The packed twin's passes over records packed from the scene, walked in
/// `schedule` (the scene's own, or one of another order).
template <class T, class Record>
double packed_twin_solves(benchmark::State& state, Prepared<T>& p, int threads, const collide::Schedule& schedule) {
  oneapi::tbb::task_arena arena(threads);
  arena.initialize();
  collide::PackedBuffer<Record> records(p.bodies().count);
  pack_as(p.bodies(), collide::packed_view(records));
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  // The warm-up sizes the twin's buffers.
  return timed_solves(state, p,
                      [&] { packed_twin_pass(arena, collide::packed_view(records), contacts, impulses, schedule); });
}

}  // namespace

template <class T>
void solve_row(benchmark::State& state, Kind kind, std::size_t n, Path path, int threads, collide::Isa isa) {
  Prepared<T>& p = prepared_scene<T>(kind, n);
  measure_isa_auto<T>(collide::Model::rigid);
  collide::SolverOptions options;
  options.path = path;
  options.threads = threads;
  options.isa = isa;
  const collide::Solver solver(options);
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  collide::SolveStats stats;
  const double seconds = timed_solves(state, p, [&] { stats = solver.solve(bodies, contacts, impulses, p.schedule); });

  Columns columns = solve_columns(n, bytes_per_collision<T>(p.friction), seconds, threads);
  columns.batches = static_cast<double>(stats.batches);
  columns.schedule_bytes_per_contact = static_cast<double>(p.schedule.memory_bytes()) / static_cast<double>(n);
  set_counters(state, columns);
  state.SetLabel(cache_label(p, std::string(path == Path::simd ? collide::to_string(stats.isa) : "scalar") + ", " +
                                    std::to_string(stats.lanes) + " lanes"));
}

// Through the Model-dispatching Solver::solve: the views of the smaller
// models read only their own arrays, so the bytes per collision are the
// model's own (collide/eval/traffic.hpp).
template <class T>
void model_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads,
               collide::Accuracy accuracy) {
  Prepared<T>& p = prepared_scene<T>(kind, n, model, friction);
  measure_isa_auto<T>(model, accuracy);
  collide::SolverOptions options;
  options.path = Path::simd;
  options.threads = threads;
  options.accuracy = accuracy;
  const collide::Solver solver(options);
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  if (!collide::model_misfit(model, bodies, contacts).empty()) {
    state.SkipWithError("the scene does not fit the model");
    return;
  }
  collide::SolveStats stats;
  const double seconds =
      timed_solves(state, p, [&] { stats = solver.solve(model, bodies, contacts, impulses, p.schedule); });

  Columns columns = solve_columns(n, collide::bytes_per_collision(model, sizeof(T), p.friction), seconds, threads);
  columns.batches = static_cast<double>(stats.batches);
  columns.schedule_bytes_per_contact = static_cast<double>(p.schedule.memory_bytes()) / static_cast<double>(n);
  set_counters(state, columns);
  state.SetLabel(cache_label(p, model_label(stats)));
}

template <class T>
void layout_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads,
                LayoutRow layout) {
  Prepared<T>& p = prepared_scene<T>(kind, n, model, friction);
  measure_isa_auto<T>(model);
  collide::SolverOptions options;
  options.path = Path::simd;
  options.threads = threads;
  options.layout = layout == LayoutRow::soa ? collide::BodyLayout::soa : collide::BodyLayout::packed;
  const collide::Solver solver(options);
  collide::SolveStats stats;
  const double seconds = with_record<T>(
      model, [&](auto record) { return layout_solve<T, decltype(record)>(state, p, solver, model, layout, stats); });
  Columns columns = solve_columns(n, collide::bytes_per_collision(model, sizeof(T), p.friction), seconds, threads);
  columns.batches = static_cast<double>(stats.batches);
  set_counters(state, columns);
  state.SetLabel(cache_label(p, model_label(stats)));
}

// On the scene of the model rows: the ceiling of the model's data layout, in
// the same bytes per collision.
template <class T>
void twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, bool friction, int threads) {
  Prepared<T>& p = prepared_scene<T>(kind, n, model, friction);
  oneapi::tbb::task_arena arena(threads);
  arena.initialize();
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  const double seconds = timed_solves(state, p, [&] { memory_twin_pass<T>(model, arena, bodies, contacts, impulses); });

  set_counters(state, solve_columns(n, collide::bytes_per_collision(model, sizeof(T), p.friction), seconds, threads));
  state.SetLabel(cache_label(p, "memory only"));
}

// On the scene of the layout rows: the ceiling of the layout/.../records
// rows.
template <class T>
void packed_twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Model model, int threads) {
  Prepared<T>& p = prepared_scene<T>(kind, n, model, false);
  const double seconds = with_record<T>(
      model, [&](auto record) { return packed_twin_solves<T, decltype(record)>(state, p, threads, p.schedule); });
  set_counters(state, solve_columns(n, collide::bytes_per_collision(model, sizeof(T), false), seconds, threads));
  state.SetLabel(cache_label(p, "memory only, packed"));
}

template <class T>
void textbook_row(benchmark::State& state, Kind kind, std::size_t n) {
  Prepared<T>& p = prepared_scene<T>(kind, n);
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  const double seconds = timed_solves(state, p, [&] { textbook_solve(bodies, contacts, impulses); });

  set_counters(state, solve_columns(n, bytes_per_collision<T>(p.friction), seconds, 1));
  state.SetLabel(cache_label(p, ""));
}

template <class T>
void schedule_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order) {
  Prepared<T>& p = prepared_scene<T>(kind, n);
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  // A schedule of its own; the warm-up builds it once untimed, and later
  // builds reuse its buffers, as a simulation that rebuilds every frame does.
  collide::Schedule schedule(order);
  const double seconds = time_iterations(state, [&] { schedule.build(contacts, bodies); });
  Columns columns;
  columns.items = static_cast<double>(n);
  columns.seconds = seconds;
  columns.batches = static_cast<double>(schedule.batch_count());
  columns.schedule_bytes_per_contact = static_cast<double>(schedule.memory_bytes()) / static_cast<double>(n);
  set_counters(state, columns);
}

template <class T>
void order_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order, int passes, int threads,
               collide::Iteration iteration, bool warm) {
  Prepared<T>& p = prepared_scene<T>(kind, n);
  measure_isa_auto<T>(collide::Model::rigid);
  collide::SolverOptions options;
  options.threads = threads;
  options.passes = passes;
  options.iteration = iteration;
  options.warm_start = warm;
  const collide::Solver solver(options);
  collide::Schedule schedule(order);  // untimed: a schedule serves every frame while the contacts hold
  const collide::BodyView<T> bodies = p.bodies();
  const collide::ContactView<T> contacts = p.contacts();
  const collide::ImpulseView<T> impulses = p.impulses.view();
  schedule.build(contacts, bodies, threads);
  // The warm start: a converged J of the same input, the bodies as they were.
  collide::ImpulseBuffer<T> start;
  if (warm) {
    collide::SolverOptions converge = options;
    converge.passes = 64;
    converge.warm_start = false;
    start.resize(contacts.count);
    (void)collide::Solver(converge).solve(bodies, contacts, start.view(), schedule);
    p.restore();
  }
  const auto copy_start = [&] {
    if (!warm) return;
    const collide::ImpulseView<const T> from = std::as_const(start).view();
    std::copy(from.j.x, from.j.x + from.count, impulses.j.x);
    std::copy(from.j.y, from.j.y + from.count, impulses.j.y);
    std::copy(from.j.z, from.j.z + from.count, impulses.j.z);
  };
  // The warm-up sizes the solver's buffers (packing), as a frame loop's first frame does.
  collide::SolveStats stats;
  const double seconds = timed_solves(
      state, p, [&] { stats = solver.solve(bodies, contacts, impulses, schedule); }, copy_start);
  Columns columns =
      solve_columns(n * static_cast<std::size_t>(passes), bytes_per_collision<T>(p.friction), seconds, threads);
  columns.batches = static_cast<double>(stats.batches);
  columns.schedule_bytes_per_contact = static_cast<double>(schedule.memory_bytes()) / static_cast<double>(n);
  set_counters(state, columns);
  std::string label = std::string(collide::to_string(stats.layout)) + ", " + collide::to_string(stats.isa) + ", " +
                      std::to_string(stats.colours) + " colours, " + std::to_string(stats.overflow_contacts) +
                      " overflow";
  if (passes > 1 || warm) {
    char residual[32];
    std::snprintf(residual, sizeof residual, ", residual %.3g", stats.residual);
    label += residual;
  }
  state.SetLabel(cache_label(p, label));
}

/// The packed twin (packed_twin.hpp: every byte the solve reads and writes,
/// none of the law) on rigid records, walked in the given order's schedule:
/// the memory-only ceiling of that order's index pattern.
template <class T>
void order_twin_row(benchmark::State& state, Kind kind, std::size_t n, collide::Order order, int threads) {
  Prepared<T>& p = prepared_scene<T>(kind, n);
  collide::Schedule schedule(order);
  schedule.build(p.contacts(), p.bodies(), threads);
  const double seconds = packed_twin_solves<T, collide::PackedRigid<T>>(state, p, threads, schedule);
  Columns columns = solve_columns(n, bytes_per_collision<T>(p.friction), seconds, threads);
  columns.batches = static_cast<double>(schedule.batch_count());
  set_counters(state, columns);
  state.SetLabel(cache_label(p, "memory only, packed"));
}

#define COLLIDE_BENCH_ROWS(T)                                                                                     \
  template void solve_row<T>(benchmark::State&, Kind, std::size_t, Path, int, collide::Isa);                      \
  template void model_row<T>(benchmark::State&, Kind, std::size_t, collide::Model, bool, int, collide::Accuracy); \
  template void layout_row<T>(benchmark::State&, Kind, std::size_t, collide::Model, bool, int, LayoutRow);        \
  template void twin_row<T>(benchmark::State&, Kind, std::size_t, collide::Model, bool, int);                     \
  template void packed_twin_row<T>(benchmark::State&, Kind, std::size_t, collide::Model, int);                    \
  template void textbook_row<T>(benchmark::State&, Kind, std::size_t);                                            \
  template void schedule_row<T>(benchmark::State&, Kind, std::size_t, collide::Order);                            \
  template void order_row<T>(benchmark::State&, Kind, std::size_t, collide::Order, int, int, collide::Iteration,  \
                             bool);                                                                               \
  template void order_twin_row<T>(benchmark::State&, Kind, std::size_t, collide::Order, int);
COLLIDE_BENCH_ROWS(float)
COLLIDE_BENCH_ROWS(double)
#undef COLLIDE_BENCH_ROWS

}  // namespace collide_bench
