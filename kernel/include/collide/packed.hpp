// collide/packed.hpp - the packed body layout: the state of one body in one
// aligned record, for scenes whose contacts reach bodies at random.
//
// Design notes
// ------------
// The structure-of-arrays views (bodies.hpp) put every component of a body in
// its own array. That streams perfectly when contacts walk the bodies in
// order (the pairs scene), but a contact that reaches a random body touches
// one cache line per component: 17 lines read and 6 written for a rigid
// body, and the kernel then waits on memory latency, not bandwidth (debris
// ran at a twentieth of pairs). A packed record holds the body's state in
// one or two adjacent cache lines, so a random body costs one or two misses,
// which the solver prefetches a few groups ahead.
//
// Each record is aligned to its size (a cache line, or a fraction of one that
// divides it), so no record straddles more lines than it must:
//
//   record               float            double
//   PackedRigid<T>       128 B (2 lines)  192 B (3 lines)   17 values
//   PackedSphere<T>      64 B (1 line)    128 B (2 lines)   11 values
//   PackedParticle<T>    16 B (4/line)    32 B (2/line)      4 values
//
// v and w come first, so the values the kernel writes share the first line.
// Rigid float needs 68 bytes, 4 more than a line: its second line holds the
// last inverse moment alone. (A read-only/read-write split into two arrays
// touches two lines per body as well; one record keeps the two lines
// adjacent, where the hardware's adjacent-line prefetch fetches both.)
//
// The layout holds the same values as the SoA views, in the same units, and
// converts to and from them exactly (a copy, no arithmetic): a caller may
// keep its bodies packed across frames and never pack again, or hand the
// solver SoA views and let it pack when that is faster (SolverOptions::layout).
//
// The header is C++17 so that C++17 programs can embed the kernel.
#pragma once

#include <cstddef>
#include <type_traits>
#include <vector>

#include "collide/bodies.hpp"

namespace collide {

/// One rigid body, packed. Same meaning and units as BodyView.
template <class T>
struct alignas(64) PackedRigid {
  T v[3];            ///< linear velocity, world frame [m/s]; updated by the kernels
  T w[3];            ///< angular velocity, world frame [rad/s]; updated by the kernels
  T p[3];            ///< centre of mass, world frame [m]
  T q[4];            ///< orientation (w, x, y, z), unit, body frame to world frame
  T inv_mass;        ///< [1/kg]; 0 = immovable
  T inv_inertia[3];  ///< inverse principal moments, body frame [1/(kg m^2)]
};

/// One body of the sphere model (isotropic inertia), packed.
template <class T>
struct alignas(64) PackedSphere {
  T v[3];         ///< [m/s]; updated
  T w[3];         ///< [rad/s]; updated
  T p[3];         ///< [m]
  T inv_mass;     ///< [1/kg]; 0 = immovable
  T inv_inertia;  ///< the one inverse moment [1/(kg m^2)]
};

/// One body of the particle model (translation only), packed.
template <class T>
struct alignas(4 * sizeof(T)) PackedParticle {
  T v[3];      ///< [m/s]; updated
  T inv_mass;  ///< [1/kg]; 0 = immovable
};

static_assert(sizeof(PackedRigid<float>) == 128 && sizeof(PackedRigid<double>) == 192);
static_assert(sizeof(PackedSphere<float>) == 64 && sizeof(PackedSphere<double>) == 128);
static_assert(sizeof(PackedParticle<float>) == 16 && sizeof(PackedParticle<double>) == 32);
static_assert(std::is_trivially_copyable_v<PackedRigid<float>> && std::is_standard_layout_v<PackedRigid<float>>);

/// Non-owning view of `count` packed records. Record is PackedRigid<T>,
/// PackedSphere<T> or PackedParticle<T>; the records must be aligned as the
/// type says (std::vector<Record> is, since C++17).
template <class Record>
struct PackedView {
  std::size_t count = 0;
  Record* bodies = nullptr;
};

/// Owning storage for packed bodies: a std::vector, whose allocator honours
/// the records' alignment.
template <class Record>
using PackedBuffer = std::vector<Record>;

template <class Record>
PackedView<Record> packed_view(PackedBuffer<Record>& buffer) {
  return {buffer.size(), buffer.data()};
}

/// The value type of a packed record.
template <class Record>
struct PackedValue;
template <class T>
struct PackedValue<PackedRigid<T>> {
  using type = T;
};
template <class T>
struct PackedValue<PackedSphere<T>> {
  using type = T;
};
template <class T>
struct PackedValue<PackedParticle<T>> {
  using type = T;
};

// Conversions. Exact copies in both directions; `to.count` must equal
// `from.count` (std::invalid_argument otherwise). Independent bodies are
// converted in parallel in the calling thread's TBB arena.

/// SoA to packed: every field. U is T or const T.
template <class U>
void pack(const BodyView<U>& from, const PackedView<PackedRigid<std::remove_const_t<U>>>& to);
template <class U>
void pack(const SphereView<U>& from, const PackedView<PackedSphere<std::remove_const_t<U>>>& to);
template <class U>
void pack(const ParticleView<U>& from, const PackedView<PackedParticle<std::remove_const_t<U>>>& to);

/// Packed to SoA: every field.
template <class T>
void unpack(const PackedView<PackedRigid<T>>& from, const BodyView<T>& to);
template <class T>
void unpack(const PackedView<PackedSphere<T>>& from, const SphereView<T>& to);
template <class T>
void unpack(const PackedView<PackedParticle<T>>& from, const ParticleView<T>& to);

/// Packed to SoA: only what the kernels write (v, and w where the model has
/// it), and only for movable bodies (inverse mass != 0): the rest did not
/// change.
template <class T>
void unpack_velocities(const PackedView<PackedRigid<T>>& from, const BodyView<T>& to);
template <class T>
void unpack_velocities(const PackedView<PackedSphere<T>>& from, const SphereView<T>& to);
template <class T>
void unpack_velocities(const PackedView<PackedParticle<T>>& from, const ParticleView<T>& to);

}  // namespace collide
