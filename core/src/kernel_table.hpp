// kernel_table.hpp - the seam between the driver (solve.cpp, compiled for the
// baseline) and the kernel compiled once per instruction set (kernel_isa.cpp).
//
// Design notes
// ------------
// The driver owns everything that is not arithmetic on lanes: the schedule
// walk, TBB, the stats. It hands a kernel a KernelJob and a range of the
// schedule's order, through a function pointer looked up once, when the
// Solver is built (kernel_table(Isa)). The per-ISA objects contain nothing but
// the kernel templates, in an inline namespace named for their ISA
// (lanes.hpp), and these entry points with ISA-suffixed names: no TBB, no
// standard-library code that is not inlined (tests/core/test_isa_objects.sh
// checks the objects), so the linker can never pick a wide-ISA copy of a
// function for a narrow path. One indirect call per block of ~1024 contacts is
// the whole cost of dispatch.
//
// The scalar path, and the last (count mod W) contacts of every SIMD range,
// run the baseline object's one-lane kernel: the same operations in the same
// order, so each lane and the tail agree bit for bit whatever the ISA.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

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

/// Everything a kernel needs besides the range: the bodies in the view of
/// `model` and layout (only that member is set), the contacts, where J goes,
/// and the schedule's order.
template <class T>
struct KernelJob {
  Model model = Model::rigid;
  bool friction = false;  ///< contacts.mu is set: run the Coulomb step
  bool packed = false;    ///< the bodies are in a packed_* member, not a SoA view
  bool accurate = false;  ///< Accuracy::accurate: the law in wider lanes (exact_lanes.hpp)
  /// J is added to what the impulse arrays hold (the passes after the first,
  /// SolverOptions::passes) rather than written.
  bool accumulate = false;
  BodyView<T> rigid;
  SphereView<T> sphere;
  ParticleView<T> particle;
  PackedView<PackedRigid<T>> packed_rigid;
  PackedView<PackedSphere<T>> packed_sphere;
  PackedView<PackedParticle<T>> packed_particle;
  ContactView<T> contacts;
  ImpulseView<T> impulses;
  const std::uint32_t* order = nullptr;
  /// Set when `geometry` holds the velocity-free half of the law of every
  /// contact, by position in `order` (fast mode, frictionless): the kernels
  /// take the velocity step alone, on the geometry stored there.
  bool stepped = false;
  GeometryView<T> geometry;
};

/// Resolves order[begin, end) (all inside one batch; `contiguous` when the
/// batch's order is consecutive indices).
template <class T>
using RangeKernel = void (*)(const KernelJob<T>& job, bool contiguous, std::size_t begin, std::size_t end);

/// Resolves order[begin, end) one contact after another: a run of batches
/// too small to fill the lanes (a chain), whose contacts may share bodies.
template <class T>
using RunKernel = void (*)(const KernelJob<T>& job, std::size_t begin, std::size_t end);

/// Contacts per piece of a run (solve_run in kernel_isa.cpp): the geometry
/// of a piece, 64 bytes a contact in float, stays in L1 between the pass that
/// forms it and the walk that reads it.
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

/// The SIMD kernels of one instruction set.
struct KernelTable {
  Isa isa = Isa::sse2;
  std::size_t lanes_float = 0;
  std::size_t lanes_double = 0;
  RangeKernel<float> simd_float = nullptr;
  RangeKernel<double> simd_double = nullptr;
  RunKernel<float> run_float = nullptr;
  RunKernel<double> run_double = nullptr;
  RunGeometryKernel<float> run_geometry_float = nullptr;
  RunGeometryKernel<double> run_geometry_double = nullptr;
  RunWalkKernel<float> run_walk_float = nullptr;
  RunWalkKernel<double> run_walk_double = nullptr;
};

/// The entry of a KernelTable for precision T: its float one or its double one.
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

/// The one-lane kernel (the scalar path and every SIMD tail), from the
/// baseline object.
template <class T>
void solve_range_scalar(const KernelJob<T>& job, bool contiguous, std::size_t begin, std::size_t end);

// One per kernel object (kernel_isa.cpp defines the one of its ISA).
const KernelTable& kernel_table_sse2();
const KernelTable& kernel_table_avx2();
const KernelTable& kernel_table_avx512();
const KernelTable& kernel_table_native();

}  // namespace collide::detail
