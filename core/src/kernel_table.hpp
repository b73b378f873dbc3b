// kernel_table.hpp - the seam between the driver (solve.cpp, compiled for the
// baseline) and the kernel's loops (kernel/loops.hpp), compiled once per
// instruction set in units of one body model, precision and accuracy mode.
//
// Design notes
// ------------
// The driver owns everything that is not arithmetic on lanes: the schedule
// walk, TBB, the stats. It hands a kernel a KernelJob and a range of the
// schedule's order. Each loop of the kernel is one named function for one
// choice of body model, precision, accuracy mode, friction and body layout,
// and a table per ISA holds a pointer to each, in arrays indexed by those
// choices (KernelLoops). The choice is made once per solve, by one lookup
// (job_kernels), not by branches inside the loops; an indirect call per
// block of ~1024 contacts (and one for its tail) is then the whole cost of
// dispatch.
//
// Why one function per choice, and several objects per ISA: one object that
// held every loop of an ISA, all inlined into a few entry points, was the
// longest compile of a build (decision 0032 has the times), and a change to
// one loop moved the others' code and with it their speed
// (docs/decisions/0036-the-avx512-gather-instruction-measured.md). Now the
// loops of one model, precision and accuracy mode are an object of their own
// (kernel/units.hpp: kernel/rigid_float_fast.cpp, ...), a short compile each,
// and every function and loop of a kernel object starts on a 64-byte
// boundary (cmake/flags.cmake), so a loop's placement does not depend on
// what precedes it.
//
// The per-ISA objects contain nothing but the kernel templates, in an inline
// namespace named for their ISA (lanes.hpp) and an anonymous one, and their
// entry points with ISA-suffixed names: no TBB, no standard-library code
// that is not inlined (tests/core/test_isa_objects.sh checks the objects), so
// the linker can never pick a wide-ISA copy of a function for a narrow path.
//
// The scalar path, and the last (count mod W) contacts of every SIMD range,
// run the one-lane loops (OneLaneTable, kernel/scalar.cpp, compiled for the
// baseline): the same operations in the same order, so each lane and the
// tail agree bit for bit whatever the ISA.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <variant>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/packed.hpp"

namespace collide::detail {

/// The velocity-free half of the law (contact_kernel.hpp, ContactGeometry)
/// and the inverse masses of a span of contacts, one array per value, by
/// position in the span: a piece of a run (RunPiece), or every prepared
/// contact of a colour-order solve with several passes, formed once and
/// read by every pass (prepared_contacts.hpp). The geometry pass stores
/// lanes, the velocity step reads lanes or one value.
template <class T>
struct GeometryView {
  T* ra[3] = {};            ///< [m] c - pa (sphere, rigid)
  T* rb[3] = {};            ///< [m] c - pb
  T* response_a[3] = {};    ///< [1/(kg m)] a's angular response per unit impulse along n
  T* response_b[3] = {};    ///< [1/(kg m)]
  T* k_a = nullptr;         ///< [1/kg] a's rotational share of K(n)
  T* k_b = nullptr;         ///< [1/kg]
  T* inv_mass_a = nullptr;  ///< [1/kg] as stored: 0 for an immovable body
  T* inv_mass_b = nullptr;  ///< [1/kg]

  /// The same arrays from position `at` on.
  [[nodiscard]] GeometryView from(std::size_t at) const {
    GeometryView g = *this;
    for (std::size_t i = 0; i < 3; ++i) {
      g.ra[i] = ra[i] + at;
      g.rb[i] = rb[i] + at;
      g.response_a[i] = response_a[i] + at;
      g.response_b[i] = response_b[i] + at;
    }
    g.k_a = k_a + at;
    g.k_b = k_b + at;
    g.inv_mass_a = inv_mass_a + at;
    g.inv_mass_b = inv_mass_b + at;
    return g;
  }
};

/// The totals of the accumulated passes (Iteration::accumulate;
/// contact_kernel.hpp, Accumulated), one array per value, indexed as J is:
/// by the job's contact index.
template <class T>
struct AccumulatedView {
  T* normal = nullptr;  ///< lambda [N s / |n|]: the normal impulse is lambda n
  T* target = nullptr;  ///< [m/s |n|] the u . n the passes drive towards
  T* friction[3] = {};  ///< G [N s]: the friction impulse on a is -G (with friction only)
};

/// A warm start's visits before the first accumulated pass (contact_kernel.hpp,
/// warm_start_target and warm_start_step): none, the targets measured from
/// the velocities the solve was given, or the totals applied to the bodies.
enum class WarmVisit : std::uint8_t { none, targets, apply };

/// The bodies of a job: one of the six views, SoA or packed, of the three
/// models, in the order of Model's values (particle, sphere, rigid) and SoA
/// before packed, so that the alternative's index names the model and the
/// layout (KernelJob::model, KernelJob::packed).
template <class T>
using JobBodies = std::variant<ParticleView<T>, SphereView<T>, BodyView<T>, PackedView<PackedParticle<T>>,
                               PackedView<PackedSphere<T>>, PackedView<PackedRigid<T>>>;
static_assert(static_cast<int>(Model::particle) == 0 && static_cast<int>(Model::sphere) == 1 &&
                  static_cast<int>(Model::rigid) == 2,
              "JobBodies lists the views in the order of Model's values");

/// Everything a kernel needs besides the range: the bodies (in the view of
/// their model and layout), the contacts, where J goes, and the schedule's
/// order.
template <class T>
struct KernelJob {
  JobBodies<T> bodies;
  bool friction = false;  ///< contacts.mu is set: run the Coulomb step
  bool accurate = false;  ///< Accuracy::accurate: the law in wider lanes (exact_lanes.hpp)
  /// J is added to what the impulse arrays hold (the passes after the first,
  /// SolverOptions::passes) rather than written.
  bool accumulate = false;
  ContactView<T> contacts;
  ImpulseView<T> impulses;
  const std::uint32_t* order = nullptr;
  /// Set when `geometry` holds the velocity-free half of the law of every
  /// contact, by position in `order` (fast mode, frictionless): the kernels
  /// take the velocity step alone, on the geometry stored there.
  bool stepped = false;
  GeometryView<T> geometry;
  /// Set for Iteration::accumulate (fast mode, never stepped): each pass
  /// writes J and moves the totals there (the first pass records them).
  AccumulatedView<T> accumulated;
  bool first_pass = false;  ///< the accumulated pass is the first: the law, recording the totals
  /// With first_pass: the walk is one of a warm start's visits
  /// (SolverOptions::warm_start), before the passes; they write no J.
  WarmVisit warm = WarmVisit::none;

  [[nodiscard]] bool accumulates() const { return accumulated.normal != nullptr; }
  /// The model of the bodies' view.
  [[nodiscard]] Model model() const { return static_cast<Model>(bodies.index() % 3); }
  /// True when the bodies are packed records, not SoA arrays.
  [[nodiscard]] bool packed() const { return bodies.index() >= 3; }
};

/// Resolves order[begin, end) (all inside one batch; `contiguous` when the
/// batch's order is consecutive indices) in groups of the loop's lanes;
/// returns where the groups stopped: the tail, fewer contacts than the
/// lanes, is the one-lane loop's (a one-lane loop returns `end`).
template <class T>
using GroupLoop = std::size_t (*)(const KernelJob<T>& job, bool contiguous, std::size_t begin, std::size_t end);

/// Resolves order[begin, end) one contact after another: a run of batches
/// too small to fill the lanes (a chain), whose contacts may share bodies.
template <class T>
using RunKernel = void (*)(const KernelJob<T>& job, std::size_t begin, std::size_t end);

/// Contacts per piece of a run (solve_run_pieces in kernel/loops.hpp): the
/// geometry of a piece, 64 bytes a contact in float, stays in L1 between the
/// pass that forms it and the walk that reads it.
inline constexpr std::size_t kRunPiece = 128;

/// The geometry of a piece of a run, in arrays of its own.
template <class T>
struct RunPiece {
  alignas(64) T ra[3][kRunPiece];
  alignas(64) T rb[3][kRunPiece];
  alignas(64) T response_a[3][kRunPiece];
  alignas(64) T response_b[3][kRunPiece];
  alignas(64) T k_a[kRunPiece];
  alignas(64) T k_b[kRunPiece];
  alignas(64) T inv_mass_a[kRunPiece];
  alignas(64) T inv_mass_b[kRunPiece];

  [[nodiscard]] GeometryView<T> view() {
    return {{ra[0], ra[1], ra[2]},
            {rb[0], rb[1], rb[2]},
            {response_a[0], response_a[1], response_a[2]},
            {response_b[0], response_b[1], response_b[2]},
            k_a,
            k_b,
            inv_mass_a,
            inv_mass_b};
  }
};

/// The two halves of the law over a span of contacts, the driver's to
/// sequence: the geometry of order[first, first + count) into `into` (at
/// positions 0 .. count), which reads positions, orientations and inverse
/// masses but no velocity (for a packed record, whose rows hold both, the
/// velocities are ignored); and the walk of those contacts over their
/// geometry, in order, one contact after another, reading and writing
/// velocities. Fast mode, frictionless. A run's pieces take turns on two
/// threads (run_pipeline.hpp); a colour-order solve with several passes
/// forms the geometry of every prepared contact once (solve.cpp).
template <class T>
using RunGeometryKernel = void (*)(const KernelJob<T>& job, std::size_t first, std::size_t count,
                                   const GeometryView<T>& into);
template <class T>
using RunWalkKernel = void (*)(const KernelJob<T>& job, std::size_t first, std::size_t count,
                               const GeometryView<T>& geometry);

// The choices that name a loop, the extents of the tables' arrays.
inline constexpr std::size_t kModels = 3;     ///< Model: particle, sphere, rigid
inline constexpr std::size_t kModes = 2;      ///< fast, accurate (KernelJob::accurate)
inline constexpr std::size_t kFrictions = 2;  ///< without, with (KernelJob::friction)
inline constexpr std::size_t kLayouts = 2;    ///< SoA views, packed records (KernelJob::packed)

/// The loops over groups of one lane width (an ISA's, or one lane), one per
/// choice of model, mode, friction and layout.
template <class T>
struct GroupLoops {
  /// The law: solve[model][accurate][friction][packed].
  GroupLoop<T> solve[kModels][kModes][kFrictions][kLayouts] = {};
  /// The velocity step on the stored geometry (KernelJob::stepped: fast
  /// mode, frictionless): step[model][packed].
  GroupLoop<T> step[kModels][kLayouts] = {};
  /// The accumulated passes (KernelJob::accumulates: fast mode):
  /// accumulate[model][friction][packed].
  GroupLoop<T> accumulate[kModels][kFrictions][kLayouts] = {};
  /// The same on the stored geometry (KernelJob::stepped: frictionless):
  /// accumulate_step[model][packed].
  GroupLoop<T> accumulate_step[kModels][kLayouts] = {};
};

/// The loops of one instruction set and precision: the group loops in its
/// lanes, and the loops of a run (fast mode, frictionless), by [model][packed].
template <class T>
struct KernelLoops {
  GroupLoops<T> groups;
  RunKernel<T> run[kModels][kLayouts] = {};  ///< a run in pieces, each its geometry then its walk
  RunGeometryKernel<T> geometry[kModels][kLayouts] = {};
  RunWalkKernel<T> walk[kModels][kLayouts] = {};
};

/// The loops of one instruction set.
struct KernelTable {
  Isa isa = Isa::sse2;
  std::size_t lanes_float = 0;
  std::size_t lanes_double = 0;
  KernelLoops<float> loops_float;
  KernelLoops<double> loops_double;
};

/// The one-lane loops: the scalar path and the tail of every SIMD range.
struct OneLaneTable {
  GroupLoops<float> loops_float;
  GroupLoops<double> loops_double;
};

/// The entry of a table for precision T: its float one or its double one.
template <class T, class F, class D>
auto of_precision(const F& for_float, const D& for_double) {
  if constexpr (std::is_same_v<T, float>) {
    return for_float;
  } else {
    return for_double;
  }
}

/// The table of a concrete ISA (not automatic) that this build has.
const KernelTable& kernel_table(Isa isa);

/// The one-lane loops, compiled for the baseline (kernel/scalar.cpp).
const OneLaneTable& one_lane_table();

/// The same tables, writable: only tests write them, to count the calls of
/// every entry (tests/core/test_dispatch.cpp). Nothing in the library does.
KernelTable& writable_kernel_table(Isa isa);
OneLaneTable& writable_one_lane_table();

/// The loops that run one job, looked up once per solve in the tables at
/// the job's model, mode, friction and layout (job_kernels).
template <class T>
struct JobKernels {
  /// The law, or the velocity step (KernelJob::stepped), in the lanes of
  /// the table's ISA; on the scalar path, the one-lane loop.
  GroupLoop<T> groups = nullptr;
  /// The same in one lane: the tail of a SIMD range, the scalar path, and a
  /// run in the accurate mode or with friction.
  GroupLoop<T> one_lane = nullptr;
  /// A run in pieces (fast mode, frictionless, not stepped); otherwise null.
  RunKernel<T> run_pieces = nullptr;
  /// The two halves of a run (fast mode, frictionless, repeated passes);
  /// otherwise null. (The accumulated passes' runs take the one-lane loop.)
  RunGeometryKernel<T> geometry = nullptr;
  RunWalkKernel<T> walk = nullptr;

  /// Resolves order[begin, end) of one batch: whole groups in the lanes,
  /// the tail in one lane.
  void range(const KernelJob<T>& job, bool contiguous, std::size_t begin, std::size_t end) const {
    const std::size_t tail = groups(job, contiguous, begin, end);
    if (tail < end) one_lane(job, contiguous, tail, end);
  }

  /// Resolves the run order[begin, end) on this thread (RunKernel): in
  /// pieces; or, when its geometry is formed (KernelJob::stepped), its walk
  /// alone; the accurate mode and friction take the one-lane loop, contact by
  /// contact.
  void run(const KernelJob<T>& job, std::size_t begin, std::size_t end) const {
    if (job.stepped && walk != nullptr) {
      walk(job, begin, end - begin, job.geometry.from(begin));
    } else if (run_pieces != nullptr) {
      run_pieces(job, begin, end);
    } else {
      one_lane(job, false, begin, end);
    }
  }
};

/// The loops of `job` in `table` (with `simd` false, the scalar path: the
/// one-lane loops for its groups).
template <class T>
JobKernels<T> job_kernels(const KernelTable& table, const KernelJob<T>& job, bool simd);

extern template JobKernels<float> job_kernels<float>(const KernelTable&, const KernelJob<float>&, bool);
extern template JobKernels<double> job_kernels<double>(const KernelTable&, const KernelJob<double>&, bool);

// One per instruction set (kernel/table.cpp defines the one of its ISA).
KernelTable& kernel_table_sse2();
KernelTable& kernel_table_avx2();
KernelTable& kernel_table_avx512();
KernelTable& kernel_table_native();

}  // namespace collide::detail
