// solve.cpp - the Solver: its options and threads, the checks at its
// boundary, and each solve put together from the schedule walk
// (run_schedule.hpp), the policies (solve_policy.hpp) and, for SoA input that
// is packed, the solver's own buffer.
//
// Design notes
// ------------
// * Batches run one after another; inside a batch no movable body appears
//   twice, so blocks of a batch run on any thread and contacts in any lane.
//   The result of a contact depends only on its own two bodies, so the thread
//   count and the block size cannot change a single bit.
// * A forced ISA (SolverOptions::isa, or COLLIDE_ISA) is resolved once,
//   when the Solver is built, to a table of function pointers; a solve then
//   costs one indirect call per block. Isa::automatic with COLLIDE_ISA unset
//   picks the table per solve: the fastest ISA for the solve's model,
//   precision, accuracy and scene kind (isa_calibration.hpp), a cached
//   lookup after the first solve of that kind in the process.
// * Nothing here allocates once the packing and prepared buffers are sized: the Solver owns
//   its task_arena (or borrows the caller's, collide/tbb.hpp), the Schedule
//   owns the order.
// * The allocate phase: a solve sizes each buffer it uses before the pass
//   that fills it (the packed records before packing, the prepared contacts
//   before their copy) and has the pages of what grew touched by the arena's
//   threads (first_touch.hpp), so the faults of a fresh Solver's first solve
//   are paid there, timed (both parts summed) as
//   SolveStats::allocate_seconds, and not by the passes. A solve that finds
//   its buffers sized reports 0.
#include <cassert>
#include <chrono>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>

#include <oneapi/tbb/task_arena.h>

#include "collide/external_arena.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "first_touch.hpp"
#include "iteration_scratch.hpp"
#include "kernel_table.hpp"
#include "prepared_contacts.hpp"
#include "run_schedule.hpp"
#include "scratch_records.hpp"
#include "solve_policy.hpp"

namespace collide {

struct Solver::Impl {
  SolverOptions options;
  IsaChoice isa_choice;                  // how the SIMD path's ISA is chosen
  const detail::KernelTable* kernels;    // the fixed choice; nullptr when measured per solve
  std::optional<tbb::task_arena> owned;  // empty when the caller's arena is borrowed
  tbb::task_arena* arena;
  // Where SoA input is packed (BodyLayout): one buffer per record type, grown
  // to the largest scene and kept; the mutex makes packing solves on one
  // Solver take turns.
  std::mutex pack_mutex;
  std::tuple<detail::ScratchRecords<PackedRigid<float>>, detail::ScratchRecords<PackedRigid<double>>,
             detail::ScratchRecords<PackedSphere<float>>, detail::ScratchRecords<PackedSphere<double>>,
             detail::ScratchRecords<PackedParticle<float>>, detail::ScratchRecords<PackedParticle<double>>>
      records;

  // Where a colour-order solve copies its contacts (prepared_contacts.hpp);
  // such solves on one Solver take turns.
  std::mutex prepare_mutex;
  std::tuple<detail::PreparedContacts<float>, detail::PreparedContacts<double>> prepared;

  // What a solve of several passes keeps between them (the accumulated
  // totals, J before the last pass); such solves on one Solver take turns.
  std::mutex iteration_mutex;
  std::tuple<detail::IterationScratch<float>, detail::IterationScratch<double>> iteration;

  explicit Impl(const SolverOptions& o)
      // int{...}: a prvalue copy, so that the static constant
      // task_arena::automatic (which libtbb does not define) is not bound to
      // the in_place constructor's reference: unoptimised builds failed to link.
      : options(o),
        isa_choice(detail::isa_choice_for(o.isa)),
        kernels(detail::fixed_kernels(o.isa, isa_choice)),
        owned(std::in_place, o.threads > 0 ? o.threads : int{tbb::task_arena::automatic}),
        arena(&*owned) {}
  Impl(const SolverOptions& o, tbb::task_arena& borrowed)
      : options(o),
        isa_choice(detail::isa_choice_for(o.isa)),
        kernels(detail::fixed_kernels(o.isa, isa_choice)),
        arena(&borrowed) {}

  /// Runs the job's contacts over the schedule with the picked kernels: on
  /// the caller's contacts, or on contacts prepared in the schedule's order
  /// (detail::prepares_contacts). `allocate_seconds` is what the solve's
  /// allocate phase took before (the packing buffer's); the prepared
  /// contacts' is added.
  template <class T>
  SolveStats run(const detail::IsaPick& pick, const detail::KernelJob<T>& job, const Schedule& schedule,
                 double allocate_seconds);
};

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The options a Solver refuses, before it starts its threads.
void check_options(const SolverOptions& options) {
  if (options.threads < 0) throw std::invalid_argument("collide::Solver: threads must be >= 0");
  if (options.passes < 1) {
    throw std::invalid_argument("collide::Solver: passes must be >= 1, got " + std::to_string(options.passes));
  }
  if (options.iteration == Iteration::accumulate && options.accuracy == Accuracy::accurate) {
    throw std::invalid_argument(
        "collide::Solver: iteration accumulate runs in the fast mode; accuracy accurate takes iteration repeat");
  }
  if (options.warm_start && options.iteration != Iteration::accumulate) {
    throw std::invalid_argument(
        "collide::Solver: a warm start needs iteration accumulate (the repeat mode's passes add impulses and "
        "cannot start from a J)");
  }
}

}  // namespace

Solver::Solver(const SolverOptions& options) {
  check_options(options);
  impl_ = std::make_unique<Impl>(options);
  impl_->arena->initialize();
}
Solver::Solver(const ExternalArena& arena, const SolverOptions& options) {
  check_options(options);
  if (options.threads != 0) {
    throw std::invalid_argument("collide::Solver: threads must be 0 in a caller's arena (the arena decides)");
  }
  impl_ = std::make_unique<Impl>(options, arena.arena);
  impl_->arena->initialize();  // no-op for an arena the caller already initialised
}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

const SolverOptions& Solver::options() const { return impl_->options; }

template <class T>
SolveStats Solver::Impl::run(const detail::IsaPick& pick, const detail::KernelJob<T>& job, const Schedule& schedule,
                             double allocate_seconds) {
  const detail::KernelTable& table = *pick.kernels;
  detail::WalkPlan plan;
  plan.simd = options.path == Path::simd;
  plan.width = plan.simd ? detail::of_precision<T>(table.lanes_float, table.lanes_double) : 1;
  plan.block = std::max<std::size_t>(plan.width, (options.block + plan.width - 1) / plan.width * plan.width);
  plan.passes = static_cast<std::size_t>(options.passes);
  plan.stop = options.stop;
  // Several passes keep J before the last one for the residual; the
  // accumulated passes keep their totals. Sized in the allocate phase.
  const bool accumulates = options.iteration == Iteration::accumulate;
  // A warm start measures its one pass too: against the J it started from.
  const bool warm = options.warm_start;
  const bool measures = plan.passes > 1 || warm;
  const bool prepares = detail::prepares_contacts(schedule);
  detail::IterationScratch<T>& scratch = std::get<detail::IterationScratch<T>>(iteration);
  std::unique_lock<std::mutex> iteration_lock(iteration_mutex, std::defer_lock);
  detail::KernelJob<T> iterated = job;
  if (accumulates || measures) {
    iteration_lock.lock();
    const auto t_allocate = Clock::now();
    if (scratch.allocate(*arena, job.contacts.count, accumulates, job.friction, measures)) {
      allocate_seconds += seconds_since(t_allocate);
    }
    if (accumulates) iterated.accumulated = scratch.totals(job.friction);
    // The totals are indexed as the walked J is: by prepared position when
    // the contacts are prepared in the schedule's order.
    if (warm) {
      scratch.warm(*arena, job.contacts, job.impulses, prepares ? schedule.solve_order() : nullptr, job.friction,
                   measures);
    }
  }
  double residual = 1;
  // A warm start's visit, then the passes, the last one apart when the
  // residual is measured.
  const auto walk = [&](const detail::KernelJob<T>& on) {
    detail::WalkPlan rest = plan;
    if (warm) {
      // Its two visits, before any contact steps (warm_start_target, then
      // warm_start_step): no pass of the solve's count, and J written by
      // the passes that follow.
      detail::WalkPlan visit = plan;
      visit.passes = 1;
      for (const detail::WarmVisit kind : {detail::WarmVisit::targets, detail::WarmVisit::apply}) {
        detail::KernelJob<T> visiting = on;
        visiting.warm = kind;
        (void)detail::walk_schedule(table, visit, *arena, visiting, schedule);
      }
      rest.continues = true;
    }
    if (!measures) return detail::walk_schedule(table, rest, *arena, on, schedule);
    detail::WalkPlan before = rest;
    before.passes = plan.passes - 1;
    // A warm start's one pass is measured against the J it started from,
    // which warm() saved.
    if (before.passes > 0) {
      const std::size_t done = detail::walk_schedule(table, before, *arena, on, schedule);
      if (done < before.passes || (plan.stop != nullptr && plan.stop->load(std::memory_order_relaxed))) {
        residual = std::numeric_limits<double>::quiet_NaN();
        return done;
      }
      scratch.save(*arena, on.impulses);
    }
    detail::WalkPlan last = rest;
    last.passes = 1;
    last.continues = rest.continues || before.passes > 0;
    detail::walk_schedule(table, last, *arena, on, schedule);
    residual = scratch.residual(*arena, on.impulses);
    return plan.passes;
  };
  std::size_t passes = 0;
  if (prepares) {
    // Copied in, walked every pass, J copied out: the copies cost two
    // streaming passes, the gathers they spare one per colour. With several
    // passes of the fast frictionless law, the velocity-free half is formed
    // with the copy and every pass takes the velocity step alone.
    const std::lock_guard<std::mutex> lock(prepare_mutex);
    detail::PreparedContacts<T>& prepared_contacts = std::get<detail::PreparedContacts<T>>(prepared);
    const bool stepped = detail::steps_prepared_contacts(plan.passes, job.accurate, job.friction);
    const auto t_allocate = Clock::now();
    if (prepared_contacts.allocate(*arena, job, stepped)) allocate_seconds += seconds_since(t_allocate);
    const detail::KernelJob<T> on_prepared = prepared_contacts.prepare(
        *arena, iterated, stepped ? detail::job_kernels(table, job, plan.simd).geometry : nullptr);
    plan.prepared = true;
    passes = walk(on_prepared);
    prepared_contacts.write_back(*arena, job.impulses, schedule.solve_order());
  } else {
    passes = walk(iterated);
  }

  SolveStats stats;
  stats.contacts = job.contacts.count;
  stats.batches = schedule.batch_count();
  stats.largest_batch = schedule.largest_batch();
  stats.conflicts = schedule.conflicts();
  stats.lanes = plan.width;
  stats.threads = arena->max_concurrency();
  stats.model = job.model();
  stats.path = options.path;
  stats.friction = job.friction;
  // The scalar path is the one-lane loops, compiled for the baseline, on every ISA.
  stats.isa = plan.simd ? table.isa : Isa::sse2;
  stats.isa_choice = pick.choice;
  stats.isa_calibration_seconds = pick.calibration_seconds;
  stats.allocate_seconds = allocate_seconds;
  stats.layout = job.packed() ? BodyLayout::packed : BodyLayout::soa;
  stats.accuracy = options.accuracy;
  stats.order = schedule.order();
  stats.colours = schedule.colours();
  stats.overflow_contacts = schedule.overflow_contacts();
  stats.passes = passes;
  stats.iteration = options.iteration;
  stats.warm_start = warm;
  stats.residual = residual;
  return stats;
}

namespace detail {
namespace {

/// The job of a solve of `bodies`, SoA or packed (the view's type names its
/// model and layout: JobBodies); the solver may swap SoA bodies for the
/// records it packs them into.
template <class T, class View>
KernelJob<T> make_job(const View& bodies, Accuracy accuracy, const ContactView<T>& contacts,
                      const ImpulseView<T>& impulses, const Schedule& schedule) {
  KernelJob<T> job;
  job.bodies = bodies;
  job.accurate = accuracy == Accuracy::accurate;
  job.friction = contacts.mu != nullptr;
  job.contacts = contacts;
  job.impulses = impulses;
  job.order = schedule.solve_order();
  return job;
}

/// The name of the first null array of a SoA view (for_each_array), or nullptr.
template <class View>
const char* first_null(const View& b) {
  const char* name = nullptr;
  for_each_array(b, [&](const char* array, const auto* p, ArrayRole) {
    if (name == nullptr && p == nullptr) name = array;
  });
  return name;
}
template <class T>
const char* first_null(const PackedView<PackedRigid<T>>& b) {
  if (b.bodies == nullptr) return "records";
  return b.inv_mass == nullptr ? "inv_mass" : nullptr;
}
template <class Record>
const char* first_null(const PackedView<Record>& b) {
  return b.bodies == nullptr ? "records" : nullptr;
}

/// The first null of the named arrays, or nullptr.
template <class T>
const char* first_null(std::initializer_list<std::pair<const char*, const T*>> arrays) {
  for (const auto& [name, p] : arrays) {
    if (p == nullptr) return name;
  }
  return nullptr;
}

/// What keeps a solve inside the caller's arrays, checked in O(1) before
/// anything is read or written: the schedule was built for as many contacts
/// and bodies as the views hold (its build checked every index against that
/// body count), J has a slot per contact, and no array the kernels of
/// `model` read is null. Throws std::invalid_argument naming the counts or
/// the array. The values are the caller's to
/// vouch for (validate()).
template <class T, class View>
void check_solve_input(Model model, const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                       const Schedule& schedule) {
  const char* const where = "collide::Solver::solve: ";  // a string only when it throws: a solve allocates nothing
  if (schedule.contact_count() != contacts.count || schedule.body_count() != bodies.count) {
    throw std::invalid_argument(
        std::string(where) + "the schedule was built for " + std::to_string(schedule.contact_count()) +
        " contacts and " + std::to_string(schedule.body_count()) + " bodies, not " + std::to_string(contacts.count) +
        " contacts and " + std::to_string(bodies.count) + " bodies");
  }
  if (impulses.count != contacts.count) {
    throw std::invalid_argument(std::string(where) + "impulses.count = " + std::to_string(impulses.count) +
                                " but contacts.count = " + std::to_string(contacts.count));
  }
  if (bodies.count > 0) {
    if (const char* name = first_null(bodies)) {
      throw std::invalid_argument(std::string(where) + "bodies." + name +
                                  " is null but bodies.count = " + std::to_string(bodies.count));
    }
  }
  if (contacts.count > 0) {
    const char* name = first_null<BodyIndex>({{"a", contacts.a}, {"b", contacts.b}});
    if (name == nullptr) name = first_null<T>({{"n.x", contacts.n.x}, {"n.y", contacts.n.y}, {"n.z", contacts.n.z}});
    if (name == nullptr && model != Model::particle) {  // particles never read the contact point
      name = first_null<T>({{"c.x", contacts.c.x}, {"c.y", contacts.c.y}, {"c.z", contacts.c.z}});
    }
    if (name != nullptr) {
      throw std::invalid_argument(std::string(where) + "contacts." + name +
                                  " is null but contacts.count = " + std::to_string(contacts.count));
    }
    if (const char* j = first_null<T>({{"j.x", impulses.j.x}, {"j.y", impulses.j.y}, {"j.z", impulses.j.z}})) {
      throw std::invalid_argument(std::string(where) + "impulses." + j +
                                  " is null but impulses.count = " + std::to_string(impulses.count));
    }
  }
}

}  // namespace
}  // namespace detail

/// SoA input, solved in place or packed (should_pack).
template <class Record, class View, class T>
SolveStats Solver::solve_soa(Model model, const View& bodies, const ContactView<T>& contacts,
                             const ImpulseView<T>& impulses, const Schedule& schedule) const {
  detail::check_solve_input(model, bodies, contacts, impulses, schedule);
  detail::KernelJob<T> job = detail::make_job(bodies, impl_->options.accuracy, contacts, impulses, schedule);
  const std::size_t scattered = detail::scattered_contacts(schedule, contacts.a, contacts.b);
  const detail::IsaPick pick = detail::pick_isa<T>(impl_->options.path, impl_->options.accuracy, impl_->isa_choice,
                                                   impl_->kernels, model, scattered, schedule.contact_count());
  if (!detail::should_pack(impl_->options.layout, scattered, bodies.count)) {
    return impl_->run(pick, job, schedule, 0.0);
  }
  const std::lock_guard<std::mutex> lock(impl_->pack_mutex);
  PackedView<Record> packed;
  packed.count = bodies.count;
  double allocate_seconds = 0;
  {
    const auto t_allocate = Clock::now();
    detail::FirstTouch touch;
    packed.bodies = std::get<detail::ScratchRecords<Record>>(impl_->records).reserve(bodies.count, touch);
    if (!touch.empty()) {
      touch.run(*impl_->arena);
      allocate_seconds = seconds_since(t_allocate);
    }
  }
  // A rigid view's inverse masses are the caller's own array: the kernels
  // only read them, so they are not copied.
  if constexpr (std::is_same_v<Record, PackedRigid<T>>) packed.inv_mass = bodies.inv_mass;
  impl_->arena->execute([&] { pack(bodies, packed); });
  job.bodies = packed;
  SolveStats stats = impl_->run(pick, job, schedule, allocate_seconds);
  impl_->arena->execute([&] { unpack_velocities(packed, bodies); });
  return stats;
}

template <class Record, class T>
SolveStats Solver::solve_packed(Model model, const PackedView<Record>& bodies, const ContactView<T>& contacts,
                                const ImpulseView<T>& impulses, const Schedule& schedule) const {
  detail::check_solve_input(model, bodies, contacts, impulses, schedule);
  detail::KernelJob<T> job = detail::make_job(bodies, impl_->options.accuracy, contacts, impulses, schedule);
  const detail::IsaPick pick =
      detail::pick_isa<T>(impl_->options.path, impl_->options.accuracy, impl_->isa_choice, impl_->kernels, model,
                          detail::scattered_contacts(schedule, contacts.a, contacts.b), schedule.contact_count());
  // The caller's records are solved in place: no packing buffer of the
  // solver's is used, so solves on one Solver may run at once, as on SoA
  // views (colour-order ones take turns over the prepared contacts).
  return impl_->run(pick, job, schedule, 0.0);
}

template <class T>
SolveStats Solver::solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return solve_soa<PackedRigid<T>>(Model::rigid, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return solve_soa<PackedSphere<T>>(Model::sphere, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return solve_soa<PackedParticle<T>>(Model::particle, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(const PackedView<PackedRigid<T>>& bodies, const ContactView<T>& contacts,
                         const ImpulseView<T>& impulses, const Schedule& schedule) const {
  return solve_packed(Model::rigid, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(const PackedView<PackedSphere<T>>& bodies, const ContactView<T>& contacts,
                         const ImpulseView<T>& impulses, const Schedule& schedule) const {
  return solve_packed(Model::sphere, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(const PackedView<PackedParticle<T>>& bodies, const ContactView<T>& contacts,
                         const ImpulseView<T>& impulses, const Schedule& schedule) const {
  return solve_packed(Model::particle, bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats Solver::solve(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts,
                         const ImpulseView<T>& impulses, const Schedule& schedule) const {
  const auto run = [&](const auto& view) {
    // The counts and arrays first: a call they refuse never reaches the
    // debug builds' fit assertion, which reads the bodies of every contact.
    detail::check_solve_input(model, view, contacts, impulses, schedule);
    assert(model_misfit(model, bodies, contacts).empty());
    return solve(view, contacts, impulses, schedule);
  };
  switch (model) {
    case Model::particle:
      return run(particle_view(bodies));
    case Model::sphere:
      return run(sphere_view(bodies));
    case Model::rigid:
      break;
  }
  return run(bodies);
}

Isa Solver::isa() const { return impl_->kernels != nullptr ? impl_->kernels->isa : Isa::automatic; }

IsaChoice Solver::isa_choice() const { return impl_->isa_choice; }

template <class T>
SolveStats solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const SolverOptions& options, Order order) {
  if (const Validation v = validate(bodies, contacts, impulses); !v) {
    throw std::invalid_argument("collide::solve: " + v.message);
  }
  const Solver solver(options);  // validates the options before any work
  Schedule schedule(order);
  schedule.build(contacts, bodies, options.threads);  // on no more threads than the solve may use
  return solver.solve(choose_model(bodies, contacts), bodies, contacts, impulses, schedule);
}

template <class T>
std::size_t simd_width(Isa isa) {
  return detail::of_precision<T>(detail::kernel_table(resolve_isa(isa)).lanes_float,
                                 detail::kernel_table(resolve_isa(isa)).lanes_double);
}

template <class T>
std::size_t simd_width() {
  return simd_width<T>(Isa::automatic);
}

// The packed views, named so that the macro below takes T as a plain type.
template <class T>
using RigidRecords = PackedView<PackedRigid<T>>;
template <class T>
using SphereRecords = PackedView<PackedSphere<T>>;
template <class T>
using ParticleRecords = PackedView<PackedParticle<T>>;

#define COLLIDE_INSTANTIATE(T)                                                                                         \
  template SolveStats Solver::solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,               \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(const SphereView<T>&, const ContactView<T>&, const ImpulseView<T>&,             \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(const ParticleView<T>&, const ContactView<T>&, const ImpulseView<T>&,           \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(const RigidRecords<T>&, const ContactView<T>&, const ImpulseView<T>&,           \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(const SphereRecords<T>&, const ContactView<T>&, const ImpulseView<T>&,          \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(const ParticleRecords<T>&, const ContactView<T>&, const ImpulseView<T>&,        \
                                       const Schedule&) const;                                                         \
  template SolveStats Solver::solve<T>(Model, const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,        \
                                       const Schedule&) const;                                                         \
  template SolveStats solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&, const SolverOptions&, \
                               Order);                                                                                 \
  template std::size_t simd_width<T>();                                                                                \
  template std::size_t simd_width<T>(Isa);
COLLIDE_INSTANTIATE(float)
COLLIDE_INSTANTIATE(double)
#undef COLLIDE_INSTANTIATE

}  // namespace collide
