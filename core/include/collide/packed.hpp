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
// ran far below pairs: decision 0005, named below). A packed record holds
// the body's state in one or two adjacent cache lines, so a random body
// costs one or two misses, which the solver prefetches a few groups ahead.
//
// Each record is aligned to its size (a cache line, or a fraction of one that
// divides it), so no record straddles more lines than it must:
//
//   record               float            double
//   PackedRigid<T>       64 B (1 line)    128 B (2 lines)   16 values + inv_mass
//   PackedSphere<T>      64 B (1 line)    128 B (2 lines)   11 values
//   PackedParticle<T>    16 B (4/line)    32 B (2/line)      4 values
//
// v and w come first, so the values the kernel writes share the first line.
//
// A rigid body has 17 values, one more than a float line holds. Its inverse
// mass therefore lives beside the records, in a dense array of its own
// (PackedView<PackedRigid<T>>::inv_mass), and the record holds the other 16:
// one line per body in float, two in double, instead of two and three, and
// half (float) or two thirds (double) of the memory. The dense array is 4 or
// 8 bytes per body: it stays in the caches far better than the records it
// serves, and the schedule reads it in one stream. A solve reads it and
// never writes it, so SoA input that the solver packs lends it its own
// inv_mass array.
//
// It pays in cache (rigid double most); on large scattered scenes the
// solve is bound by the contacts' lines, read level by level, not by the
// records (the memory-only twin of the same accesses, bench/packed_twin.cpp,
// runs at the kernel's speed). The measurements:
// docs/decisions/0005-packed-records-for-scattered-contacts.md.
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

/// One rigid body, packed: everything but its inverse mass, which is in the
/// view's dense inv_mass array (see above). Same meaning and units as BodyView.
template <class T>
struct alignas(16 * sizeof(T)) PackedRigid {
  T v[3];            ///< linear velocity, world frame [m/s]; updated by the kernels
  T w[3];            ///< angular velocity, world frame [rad/s]; updated by the kernels
  T p[3];            ///< centre of mass, world frame [m]
  T q[4];            ///< orientation (w, x, y, z), unit, body frame to world frame
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

static_assert(sizeof(PackedRigid<float>) == 64 && sizeof(PackedRigid<double>) == 128);
static_assert(sizeof(PackedSphere<float>) == 64 && sizeof(PackedSphere<double>) == 128);
static_assert(sizeof(PackedParticle<float>) == 16 && sizeof(PackedParticle<double>) == 32);
static_assert(std::is_trivially_copyable_v<PackedRigid<float>> && std::is_standard_layout_v<PackedRigid<float>>);

/// Non-owning view of `count` packed records. Record is PackedSphere<T> or
/// PackedParticle<T> (PackedRigid<T> has its own view, below); the records
/// must be aligned as the type says (std::vector<Record> is, since C++17).
template <class Record>
struct PackedView {
  std::size_t count = 0;
  Record* bodies = nullptr;
};

/// Non-owning view of `count` packed rigid bodies: the records and, beside
/// them, the inverse masses.
template <class T>
struct PackedView<PackedRigid<T>> {
  std::size_t count = 0;
  PackedRigid<T>* bodies = nullptr;
  T* inv_mass = nullptr;  ///< body i's inverse mass [1/kg] at inv_mass[i]; 0 = immovable. Never written by a solve.
};

/// Owning storage for `size()` packed bodies: std::vectors, whose allocator
/// honours the records' alignment.
template <class Record>
struct PackedBuffer {
  std::vector<Record> bodies;

  PackedBuffer() = default;
  explicit PackedBuffer(std::size_t count) : bodies(count) {}
  [[nodiscard]] std::size_t size() const { return bodies.size(); }
  void resize(std::size_t count) { bodies.resize(count); }
  void push_back(const Record& body) { bodies.push_back(body); }
  Record& operator[](std::size_t i) { return bodies[i]; }
  const Record& operator[](std::size_t i) const { return bodies[i]; }
};

/// ... of rigid bodies, with their inverse masses.
template <class T>
struct PackedBuffer<PackedRigid<T>> {
  std::vector<PackedRigid<T>> bodies;
  std::vector<T> inv_mass;  ///< [1/kg]; 0 = immovable

  PackedBuffer() = default;
  explicit PackedBuffer(std::size_t count) : bodies(count), inv_mass(count) {}
  [[nodiscard]] std::size_t size() const { return bodies.size(); }
  void resize(std::size_t count) {
    bodies.resize(count);
    inv_mass.resize(count);
  }
  void push_back(const PackedRigid<T>& body, T body_inv_mass) {
    bodies.push_back(body);
    inv_mass.push_back(body_inv_mass);
  }
  PackedRigid<T>& operator[](std::size_t i) { return bodies[i]; }
  const PackedRigid<T>& operator[](std::size_t i) const { return bodies[i]; }
};

template <class Record>
PackedView<Record> packed_view(PackedBuffer<Record>& buffer) {
  return {buffer.size(), buffer.bodies.data()};
}
template <class T>
PackedView<PackedRigid<T>> packed_view(PackedBuffer<PackedRigid<T>>& buffer) {
  return {buffer.size(), buffer.bodies.data(), buffer.inv_mass.data()};
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

/// Body i's inverse mass [1/kg] in a packed view: in the record, or for
/// rigid bodies in the view's inv_mass array.
template <class Record>
typename PackedValue<Record>::type packed_inv_mass(const PackedView<Record>& view, std::size_t i) {
  return view.bodies[i].inv_mass;
}
template <class T>
T packed_inv_mass(const PackedView<PackedRigid<T>>& view, std::size_t i) {
  return view.inv_mass[i];
}

/// A packed record's fields: its model's table (collide/bodies.hpp), which
/// names the record's members as it names the view's.
template <class T>
struct BodyFieldTable<PackedRigid<T>> : BodyFieldTable<BodyView<T>> {};
template <class T>
struct BodyFieldTable<PackedSphere<T>> : BodyFieldTable<SphereView<T>> {};
template <class T>
struct BodyFieldTable<PackedParticle<T>> : BodyFieldTable<ParticleView<T>> {};

/// True for the member a record keeps beside itself, in its view: a rigid
/// body's inverse mass (PackedView<PackedRigid<T>>::inv_mass).
template <class Record, BodyMember M>
inline constexpr bool kKeptBeside =
    M == BodyMember::inv_mass&& std::is_same_v<Record, PackedRigid<typename PackedValue<Record>::type>>;

/// The array kept beside the records (kKeptBeside): a rigid view's inverse
/// masses; none (nullptr) for the other records, which keep every field.
template <class T>
T* beside_records(const PackedView<PackedRigid<T>>& view) {
  return view.inv_mass;
}
template <class Record>
typename PackedValue<Record>::type* beside_records(const PackedView<Record>& /*view*/) {
  return nullptr;
}

/// The values a record holds, from its first: its model's fields but those
/// kept beside it.
template <class Record>
inline constexpr std::size_t kRecordValues =
    kFieldCount<Record> - (std::is_same_v<Record, PackedRigid<typename PackedValue<Record>::type>> ? 1 : 0);

/// Where a record holds member M: the index, among its values, of the
/// member's element 0.
template <class Record, BodyMember M>
constexpr std::size_t record_member_offset() {
  using T = typename PackedValue<Record>::type;
  static_assert(!kKeptBeside<Record, M>, "a member kept beside the record has no place in it");
  if constexpr (M == BodyMember::inv_mass) return offsetof(Record, inv_mass) / sizeof(T);
  if constexpr (M == BodyMember::inv_inertia) return offsetof(Record, inv_inertia) / sizeof(T);
  if constexpr (M == BodyMember::q) return offsetof(Record, q) / sizeof(T);
  if constexpr (M == BodyMember::p) return offsetof(Record, p) / sizeof(T);
  if constexpr (M == BodyMember::v) return offsetof(Record, v) / sizeof(T);
  if constexpr (M == BodyMember::w) return offsetof(Record, w) / sizeof(T);
}

/// The index, among a record's values, of the field At (a BodyFieldAt).
template <class Record, class At>
constexpr std::size_t record_slot() {
  return record_member_offset<Record, At::field.member>() + At::field.component;
}

// Conversions. Exact copies in both directions; `to.count` must equal
// `from.count` (std::invalid_argument otherwise). Independent bodies are
// converted in parallel in the calling thread's TBB arena.

/// The packed record of a SoA view's model, and the SoA view of a record's.
template <class View>
struct RecordOf;
template <class U>
struct RecordOf<BodyView<U>> {
  using type = PackedRigid<std::remove_const_t<U>>;
};
template <class U>
struct RecordOf<SphereView<U>> {
  using type = PackedSphere<std::remove_const_t<U>>;
};
template <class U>
struct RecordOf<ParticleView<U>> {
  using type = PackedParticle<std::remove_const_t<U>>;
};
template <class Record>
struct SoaViewOf;
template <class T>
struct SoaViewOf<PackedRigid<T>> {
  using type = BodyView<T>;
};
template <class T>
struct SoaViewOf<PackedSphere<T>> {
  using type = SphereView<T>;
};
template <class T>
struct SoaViewOf<PackedParticle<T>> {
  using type = ParticleView<T>;
};

/// SoA to packed: every field. View is a BodyView, SphereView or
/// ParticleView of T or const T, the records its model's. A rigid view whose
/// inv_mass is the SoA's own array (the solver packs that way) leaves it as
/// it is.
template <class View>
void pack(const View& from, const PackedView<typename RecordOf<View>::type>& to);

/// Packed to SoA: every field.
template <class Record>
void unpack(const PackedView<Record>& from, const typename SoaViewOf<Record>::type& to);

/// Packed to SoA: only what the kernels write (v, and w where the model has
/// it), and only for movable bodies (inverse mass != 0): the rest did not
/// change.
template <class Record>
void unpack_velocities(const PackedView<Record>& from, const typename SoaViewOf<Record>::type& to);

/// The body layout a solve runs on (SolverOptions::layout).
enum class BodyLayout {
  automatic,  ///< SoA input is packed when its contacts reach bodies at random (see Solver)
  soa,        ///< the caller's SoA arrays, read and written in place
  packed,     ///< packed records: the caller's, or SoA input packed into the solver's buffer
};

/// "auto", "soa" or "packed".
const char* to_string(BodyLayout layout);

}  // namespace collide
