// solve.cpp - the driver: the Solver, the schedule walk and the threads; the
// arithmetic is the kernel of the chosen instruction set (kernel_table.hpp,
// kernel_isa.cpp).
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
// * Nothing here allocates: the Solver owns its task_arena (or borrows the
//   caller's, collide/tbb.hpp), the Schedule owns the order.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/solve.hpp"
#include "collide/tbb.hpp"
#include "collide/validate.hpp"
#include "isa_calibration.hpp"
#include "kernel_table.hpp"
#include "run_pipeline.hpp"
#include "scratch_records.hpp"

namespace collide {

namespace detail {
namespace {

/// How a Solver with `requested` picks its ISA: forced (a named ISA),
/// environment (automatic and COLLIDE_ISA names one; "auto" there is the same
/// as unset) or measured per solve.
IsaChoice isa_choice_for(Isa requested) {
  if (requested != Isa::automatic) return IsaChoice::forced;
  const char* env = std::getenv("COLLIDE_ISA");
  if (env == nullptr || *env == '\0' || std::string_view(env) == to_string(Isa::automatic)) {
    return IsaChoice::measured;
  }
  return IsaChoice::environment;
}

/// The table of a fixed choice (resolve_isa checks the CPU and reads
/// COLLIDE_ISA, throwing for an unknown or unsupported ISA); none when the
/// choice is measured per solve.
const KernelTable* fixed_kernels(Isa requested, IsaChoice choice) {
  return choice == IsaChoice::measured ? nullptr : &kernel_table(resolve_isa(requested));
}

}  // namespace

/// The kernels of one solve and how they were chosen.
struct IsaPick {
  const KernelTable* kernels;
  IsaChoice choice;
  double calibration_seconds;  // spent measuring by this solve (SolveStats::isa_calibration_seconds)
};

}  // namespace detail

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
  detail::ScratchRecords<PackedRigid<float>> rigid_f;
  detail::ScratchRecords<PackedRigid<double>> rigid_d;
  detail::ScratchRecords<PackedSphere<float>> sphere_f;
  detail::ScratchRecords<PackedSphere<double>> sphere_d;
  detail::ScratchRecords<PackedParticle<float>> particle_f;
  detail::ScratchRecords<PackedParticle<double>> particle_d;

  template <class Record>
  detail::ScratchRecords<Record>& buffer() {
    using T = typename PackedValue<Record>::type;
    constexpr bool f = std::is_same_v<T, float>;
    if constexpr (std::is_same_v<Record, PackedRigid<T>>) {
      if constexpr (f) {
        return rigid_f;
      } else {
        return rigid_d;
      }
    } else if constexpr (std::is_same_v<Record, PackedSphere<T>>) {
      if constexpr (f) {
        return sphere_f;
      } else {
        return sphere_d;
      }
    } else {
      if constexpr (f) {
        return particle_f;
      } else {
        return particle_d;
      }
    }
  }

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

  /// The ISA of a solve of `model` in T: the fixed one, or the fastest for
  /// the solve's kind (measured on first use). The scalar path runs the
  /// baseline's one-lane kernel whatever the choice, and measures nothing.
  /// `scattered` is the schedule's scattered contacts (scattered_contacts).
  template <class T>
  detail::IsaPick pick(Model model, std::size_t scattered, std::size_t contacts) const {
    if (options.path == Path::scalar) return {&detail::kernel_table(Isa::sse2), IsaChoice::baseline, 0.0};
    if (kernels != nullptr) return {kernels, isa_choice, 0.0};
    double spent = 0;
    const Isa isa = detail::measured_isa<T>(model, options.accuracy, 2 * scattered > contacts, &spent).fastest;
    return {&detail::kernel_table(isa), IsaChoice::measured, spent};
  }
};

Solver::Solver(const SolverOptions& options) {
  if (options.threads < 0) throw std::invalid_argument("collide::Solver: threads must be >= 0");
  impl_ = std::make_unique<Impl>(options);
  impl_->arena->initialize();
}
Solver::Solver(const ExternalArena& arena, const SolverOptions& options) {
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

namespace detail {

const KernelTable& kernel_table(Isa isa) {
#if defined(__x86_64__)
  switch (isa) {
#if defined(COLLIDE_HAVE_KERNEL_avx512)
    case Isa::avx512:
      return kernel_table_avx512();
#endif
#if defined(COLLIDE_HAVE_KERNEL_avx2)
    case Isa::avx2:
      return kernel_table_avx2();
#endif
    default:
      break;
  }
  return kernel_table_sse2();
#else
  (void)isa;
  return kernel_table_native();
#endif
}

namespace {

/// The entry of a KernelTable for precision T: its float one or its double one.
template <class T, class F, class D>
auto of_precision(const F& for_float, const D& for_double) {
  if constexpr (std::is_same_v<T, float>) {
    return for_float;
  } else {
    return for_double;
  }
}

template <class T>
std::size_t simd_lanes(const KernelTable& table) {
  return of_precision<T>(table.lanes_float, table.lanes_double);
}

/// Walks the batches of the schedule; blocks of a large batch run in parallel.
/// The counts and arrays were checked (check_solve_input).
template <class T>
SolveStats run_schedule(const SolverOptions& opt, const IsaPick& pick, tbb::task_arena& arena, const KernelJob<T>& job,
                        const Schedule& schedule) {
  const KernelTable& table = *pick.kernels;
  const bool simd = opt.path == Path::simd;
  const std::size_t width = simd ? simd_lanes<T>(table) : 1;
  const std::size_t block = std::max<std::size_t>(width, (opt.block + width - 1) / width * width);
  const RangeKernel<T> kernel = simd ? of_precision<T>(table.simd_float, table.simd_double) : &solve_range_scalar<T>;

  const std::size_t batches = schedule.batch_count();

  arena.execute([&] {
    const bool one_thread = arena.max_concurrency() == 1;
    // Whether the one-lane kernel runs all of a batch of n contacts on this
    // thread: one too small to fill a group of lanes, or any batch on the
    // scalar path that does not split across threads.
    const auto one_lane = [&](std::size_t n) { return simd ? n < width : n < 2 * block || one_thread; };
    for (std::size_t k = 0; k < batches; ++k) {
      const std::size_t begin = schedule.batch_begin(k);
      std::size_t end = schedule.batch_begin(k + 1);
      const std::size_t n = end - begin;
      if (one_lane(n) && k + 1 < batches && one_lane(schedule.batch_begin(k + 2) - end)) {
        // A run of such batches (a chain, a stack, a column: one contact per
        // level) is applied contact after contact in one call, in schedule
        // order. That is the law's order, and each of these contacts would
        // have run in the one-lane kernel anyway (on the SIMD path as a
        // range's tail), whose bits the run kernel keeps (kernel_isa.cpp,
        // solve_run); only the call and dispatch per batch are saved, and on
        // the SIMD path the lever arms are formed in lanes.
        while (k + 1 < batches && one_lane(schedule.batch_begin(k + 2) - end)) end = schedule.batch_begin(++k + 1);
        if (simd && !one_thread && !job.packed && !job.accurate && !job.friction &&
            end - begin >= kPipelinedRunPieces * kRunPiece) {
          // The pieces' geometry on a second thread (run_pipeline.hpp).
          run_pipelined<T>(of_precision<T>(table.run_geometry_float, table.run_geometry_double),
                           of_precision<T>(table.run_walk_float, table.run_walk_double), job, begin, end);
        } else if (simd) {
          of_precision<T>(table.run_float, table.run_double)(job, begin, end);
        } else {
          solve_range_scalar<T>(job, false, begin, end);
        }
        continue;
      }
      const bool contiguous = schedule.batch_is_contiguous(k);
      if (n < 2 * block || one_thread) {
        kernel(job, contiguous, begin, end);
        continue;
      }
      const std::size_t blocks = (n + block - 1) / block;
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, blocks, 1),
          [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
              kernel(job, contiguous, begin + bi * block, std::min(end, begin + (bi + 1) * block));
            }
          },
          tbb::simple_partitioner());
    }
  });

  SolveStats stats;
  stats.contacts = job.contacts.count;
  stats.batches = schedule.batch_count();
  stats.largest_batch = schedule.largest_batch();
  stats.conflicts = schedule.conflicts();
  stats.lanes = width;
  stats.threads = arena.max_concurrency();
  stats.model = job.model;
  stats.path = opt.path;
  stats.friction = job.friction;
  // The scalar path is the baseline object's one-lane kernel, on every ISA.
  stats.isa = simd ? table.isa : Isa::sse2;
  stats.isa_choice = pick.choice;
  stats.isa_calibration_seconds = pick.calibration_seconds;
  stats.layout = job.packed ? BodyLayout::packed : BodyLayout::soa;
  stats.accuracy = opt.accuracy;
  return stats;
}

template <class T>
KernelJob<T> make_job(Model model, Accuracy accuracy, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                      const Schedule& schedule) {
  KernelJob<T> job;
  job.model = model;
  job.accurate = accuracy == Accuracy::accurate;
  job.friction = contacts.mu != nullptr;
  job.contacts = contacts;
  job.impulses = impulses;
  job.order = schedule.order();
  return job;
}

}  // namespace
}  // namespace detail

namespace detail {
namespace {

/// Positions sampled per contiguous batch by scattered_contacts.
constexpr std::size_t kLocalitySamples = 64;
/// A contact's body "follows" the one of the contact before it when their
/// indices differ by less than this: the records are a few lines apart and
/// streamed, as in the pairs layout (a difference of 2).
constexpr std::int64_t kNearBodies = 64;

/// Contacts of the schedule that reach their bodies at random: those of
/// batches that are not consecutive contacts, and those of consecutive
/// batches whose bodies do not follow one another. A caller who hands the
/// contacts over already grouped by level has every batch consecutive, but
/// the bodies of a debris scene are still read at random, and reading them
/// in place from SoA arrays (a line per component per body) is several
/// times slower than packing them: so consecutive batches of 1024 contacts
/// or more are sampled at kLocalitySamples evenly spaced places, and count
/// as scattered when most samples find both bodies far from those of the
/// contact before. The sample reads a few hundred indices: nothing beside
/// the solve.
std::size_t scattered_contacts(const Schedule& schedule, const BodyIndex* a, const BodyIndex* b) {
  std::size_t n = 0;
  const std::uint32_t* order = schedule.order();
  for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
    const std::size_t begin = schedule.batch_begin(k);
    const std::size_t size = schedule.batch_begin(k + 1) - begin;
    if (!schedule.batch_is_contiguous(k)) {
      n += size;
      continue;
    }
    if (size < 1024) continue;
    const std::size_t first = order[begin];
    std::size_t far = 0;
    for (std::size_t s = 0; s < kLocalitySamples; ++s) {
      const std::size_t c = first + 1 + s * (size - 1) / kLocalitySamples;
      const auto apart = [&](const BodyIndex* index) {
        return std::abs(static_cast<std::int64_t>(index[c]) - static_cast<std::int64_t>(index[c - 1])) >= kNearBodies;
      };
      far += apart(a) && apart(b) ? 1 : 0;
    }
    if (2 * far > kLocalitySamples) n += size;
  }
  return n;
}

/// Whether SoA input is packed. Packing reads every body once and writes v,
/// w back once (streaming, parallel); it pays when the scattered contacts
/// would otherwise touch a line per component per body at random. Measured
/// (docs/decisions/0005-packed-records-for-scattered-contacts.md): at a quarter as many scattered contacts as
/// bodies the two cost about the same; below that, or in scenes that stream
/// (pairs), the SoA arrays are used in place.

bool should_pack(BodyLayout layout, std::size_t scattered, std::size_t bodies) {
  switch (layout) {
    case BodyLayout::soa:
      return false;
    case BodyLayout::packed:
      return true;
    case BodyLayout::automatic:
      break;
  }
  return scattered >= 1024 && 4 * scattered >= bodies;
}

template <class T>
void set_packed(KernelJob<T>& job, const PackedView<PackedRigid<T>>& v) {
  job.packed_rigid = v;
}
template <class T>
void set_packed(KernelJob<T>& job, const PackedView<PackedSphere<T>>& v) {
  job.packed_sphere = v;
}
template <class T>
void set_packed(KernelJob<T>& job, const PackedView<PackedParticle<T>>& v) {
  job.packed_particle = v;
}

/// The name of the first null array the kernels of a view read, or nullptr.
template <class T, std::size_t N>
const char* first_null(const std::array<std::pair<const char*, const T*>, N>& arrays) {
  for (const auto& [name, p] : arrays) {
    if (p == nullptr) return name;
  }
  return nullptr;
}
template <class T>
const char* first_null(const BodyView<T>& b) {
  return first_null<T, 17>({{{"inv_mass", b.inv_mass},
                             {"inv_inertia.x", b.inv_inertia.x},
                             {"inv_inertia.y", b.inv_inertia.y},
                             {"inv_inertia.z", b.inv_inertia.z},
                             {"q.w", b.q.w},
                             {"q.x", b.q.x},
                             {"q.y", b.q.y},
                             {"q.z", b.q.z},
                             {"p.x", b.p.x},
                             {"p.y", b.p.y},
                             {"p.z", b.p.z},
                             {"v.x", b.v.x},
                             {"v.y", b.v.y},
                             {"v.z", b.v.z},
                             {"w.x", b.w.x},
                             {"w.y", b.w.y},
                             {"w.z", b.w.z}}});
}
template <class T>
const char* first_null(const SphereView<T>& b) {
  return first_null<T, 11>({{{"inv_mass", b.inv_mass},
                             {"inv_inertia", b.inv_inertia},
                             {"p.x", b.p.x},
                             {"p.y", b.p.y},
                             {"p.z", b.p.z},
                             {"v.x", b.v.x},
                             {"v.y", b.v.y},
                             {"v.z", b.v.z},
                             {"w.x", b.w.x},
                             {"w.y", b.w.y},
                             {"w.z", b.w.z}}});
}
template <class T>
const char* first_null(const ParticleView<T>& b) {
  return first_null<T, 4>({{{"inv_mass", b.inv_mass}, {"v.x", b.v.x}, {"v.y", b.v.y}, {"v.z", b.v.z}}});
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

/// What keeps a solve inside the caller's arrays, checked in O(1) before
/// anything is read or written: the schedule was built for as many contacts
/// and bodies as the views hold (its build checked every index against that
/// body count), J has a slot per contact, and no array the kernels of `model`
/// read is null. Throws std::invalid_argument naming the counts or the array.
/// The values are the caller's to vouch for (validate()).
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
    const char* name = contacts.a == nullptr ? "a" : contacts.b == nullptr ? "b" : nullptr;
    if (name == nullptr) {
      name = first_null<const T, 3>({{{"n.x", contacts.n.x}, {"n.y", contacts.n.y}, {"n.z", contacts.n.z}}});
    }
    if (name == nullptr && model != Model::particle) {  // particles never read the contact point
      name = first_null<const T, 3>({{{"c.x", contacts.c.x}, {"c.y", contacts.c.y}, {"c.z", contacts.c.z}}});
    }
    if (name != nullptr) {
      throw std::invalid_argument(std::string(where) + "contacts." + name +
                                  " is null but contacts.count = " + std::to_string(contacts.count));
    }
    if (const char* j = first_null<T, 3>({{{"j.x", impulses.j.x}, {"j.y", impulses.j.y}, {"j.z", impulses.j.z}}})) {
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
  detail::KernelJob<T> job = detail::make_job(model, impl_->options.accuracy, contacts, impulses, schedule);
  const std::size_t scattered = detail::scattered_contacts(schedule, contacts.a, contacts.b);
  const detail::IsaPick pick = impl_->pick<T>(model, scattered, schedule.contact_count());
  if (!detail::should_pack(impl_->options.layout, scattered, bodies.count)) {
    if constexpr (std::is_same_v<View, BodyView<T>>) {
      job.rigid = bodies;
    } else if constexpr (std::is_same_v<View, SphereView<T>>) {
      job.sphere = bodies;
    } else {
      job.particle = bodies;
    }
    return detail::run_schedule(impl_->options, pick, *impl_->arena, job, schedule);
  }
  const std::lock_guard<std::mutex> lock(impl_->pack_mutex);
  PackedView<Record> packed;
  packed.count = bodies.count;
  packed.bodies = impl_->buffer<Record>().reserve(bodies.count);
  // A rigid view's inverse masses are the caller's own array: the kernels
  // only read them, so they are not copied.
  if constexpr (std::is_same_v<Record, PackedRigid<T>>) packed.inv_mass = bodies.inv_mass;
  impl_->arena->execute([&] { pack(bodies, packed); });
  job.packed = true;
  detail::set_packed(job, packed);
  SolveStats stats = detail::run_schedule(impl_->options, pick, *impl_->arena, job, schedule);
  impl_->arena->execute([&] { unpack_velocities(packed, bodies); });
  return stats;
}

template <class Record, class T>
SolveStats Solver::solve_packed(Model model, const PackedView<Record>& bodies, const ContactView<T>& contacts,
                                const ImpulseView<T>& impulses, const Schedule& schedule) const {
  detail::check_solve_input(model, bodies, contacts, impulses, schedule);
  detail::KernelJob<T> job = detail::make_job(model, impl_->options.accuracy, contacts, impulses, schedule);
  job.packed = true;
  detail::set_packed(job, bodies);
  const detail::IsaPick pick =
      impl_->pick<T>(model, detail::scattered_contacts(schedule, contacts.a, contacts.b), schedule.contact_count());
  // The caller's records are solved in place: no buffer of the solver's is
  // used, so solves on one Solver may run at once, as on SoA views.
  return detail::run_schedule(impl_->options, pick, *impl_->arena, job, schedule);
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
                 const SolverOptions& options) {
  if (const Validation v = validate(bodies, contacts, impulses); !v) {
    throw std::invalid_argument("collide::solve: " + v.message);
  }
  const Solver solver(options);  // validates the options before any work
  Schedule schedule;
  schedule.build(contacts, bodies, options.threads);  // on no more threads than the solve may use
  return solver.solve(choose_model(bodies, contacts), bodies, contacts, impulses, schedule);
}

template <class T>
std::size_t simd_width(Isa isa) {
  return detail::simd_lanes<T>(detail::kernel_table(resolve_isa(isa)));
}

template <class T>
std::size_t simd_width() {
  return simd_width<T>(Isa::automatic);
}

const char* to_string(Path path) { return path == Path::simd ? "simd" : "scalar"; }

const char* to_string(BodyLayout layout) {
  switch (layout) {
    case BodyLayout::soa:
      return "soa";
    case BodyLayout::packed:
      return "packed";
    case BodyLayout::automatic:
      break;
  }
  return "auto";
}

const char* to_string(Accuracy accuracy) { return accuracy == Accuracy::accurate ? "accurate" : "fast"; }

Accuracy parse_accuracy(std::string_view name) {
  if (name == "fast") return Accuracy::fast;
  if (name == "accurate") return Accuracy::accurate;
  throw std::invalid_argument("unknown accuracy '" + std::string(name) + "' (expected fast or accurate)");
}

// The packed views, named so that the macro below takes T as a plain type.
template <class T>
using RigidRecords = PackedView<PackedRigid<T>>;
template <class T>
using SphereRecords = PackedView<PackedSphere<T>>;
template <class T>
using ParticleRecords = PackedView<PackedParticle<T>>;

#define COLLIDE_INSTANTIATE(T)                                                                                  \
  template SolveStats Solver::solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,        \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const SphereView<T>&, const ContactView<T>&, const ImpulseView<T>&,      \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const ParticleView<T>&, const ContactView<T>&, const ImpulseView<T>&,    \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const RigidRecords<T>&, const ContactView<T>&, const ImpulseView<T>&,    \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const SphereRecords<T>&, const ContactView<T>&, const ImpulseView<T>&,   \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const ParticleRecords<T>&, const ContactView<T>&, const ImpulseView<T>&, \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(Model, const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&, \
                                       const Schedule&) const;                                                  \
  template SolveStats solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,                \
                               const SolverOptions&);                                                           \
  template std::size_t simd_width<T>();                                                                         \
  template std::size_t simd_width<T>(Isa);
COLLIDE_INSTANTIATE(float)
COLLIDE_INSTANTIATE(double)
#undef COLLIDE_INSTANTIATE

}  // namespace collide
