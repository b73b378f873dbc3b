// collide/bodies.hpp - the body data model: structure-of-arrays views and buffers.
//
// Design notes
// ------------
// Every component of every body lives in its own contiguous array, so that a
// SIMD kernel can gather one component for eight contacts with eight loads and
// a particle system can hand over the arrays it already has. The kernels take
// `BodyView`, a bundle of non-owning pointers; `BodyBuffer` owns vectors and
// hands out views for callers that do not have arrays of their own.
//
// Bodies are stored the way the kernel consumes them, not the way a scene file
// writes them: inverse mass and inverse principal moments. An immovable body
// (mass = inf in a scene file) is inverse mass 0, and the kernels treat every
// body with inverse mass 0 as immovable whatever its inverse moments say (the
// law: "a body with m = inf is immovable whatever its I"). Storing inverses
// means no kernel ever evaluates 1/inf or 0 * inf.
//
// The header is C++17 so that C++17 programs can embed the kernel.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/large_allocator.hpp"

// __float128 (113-bit significand) exists with GCC on x86-64. collide::eval
// instantiates the body and contact buffers and the reference
// (collide/eval/reference.hpp, with libquadmath's sqrtq) for it there, to
// judge the accurate mode in double, which long double's 64-bit significand
// cannot; the core itself instantiates its buffers for float, double and long
// double only.
#if defined(__SIZEOF_FLOAT128__) && defined(__GNUC__) && !defined(__clang__)
#define COLLIDE_HAS_FLOAT128 1
#else
#define COLLIDE_HAS_FLOAT128 0
#endif

namespace collide {

/// Three pointers to the x, y and z arrays of one vector component.
template <class T>
struct Vec3Array {
  T* x = nullptr;
  T* y = nullptr;
  T* z = nullptr;
};

/// Four pointers to the arrays of a quaternion (w is the scalar part).
template <class T>
struct QuatArray {
  T* w = nullptr;
  T* x = nullptr;
  T* y = nullptr;
  T* z = nullptr;
};

/// Non-owning view of `count` bodies of the rigid model. T is float or double.
/// The kernels read every field and write only `v` and `w` of movable bodies.
template <class T>
struct BodyView {
  std::size_t count = 0;
  /// Inverse mass [1/kg]; 0 marks an immovable body. Finite and >= 0.
  T* inv_mass = nullptr;
  /// Inverse principal moments of inertia about the body's own axes
  /// [1/(kg m^2)]; 0 means no rotational response about that axis.
  Vec3Array<T> inv_inertia;
  /// Orientation: the quaternion q / |q| rotates the body frame into the
  /// world frame. The kernels normalise q (|q|^2 must be a normal, finite
  /// number in T), so the caller's q reaches the accurate mode as given.
  QuatArray<T> q;
  /// Centre of mass in the world frame [m].
  Vec3Array<T> p;
  /// Linear velocity in the world frame [m/s]. Updated by the kernels.
  Vec3Array<T> v;
  /// Angular velocity in the world frame [rad/s]. Updated by the kernels.
  Vec3Array<T> w;
};

/// Non-owning view of `count` bodies of the sphere model: isotropic inertia,
/// so no orientation is read. Same units as BodyView.
template <class T>
struct SphereView {
  std::size_t count = 0;
  T* inv_mass = nullptr;     ///< [1/kg], 0 = immovable
  T* inv_inertia = nullptr;  ///< the one inverse moment [1/(kg m^2)]
  Vec3Array<T> p;            ///< [m]
  Vec3Array<T> v;            ///< [m/s], updated
  Vec3Array<T> w;            ///< [rad/s], updated
};

/// Non-owning view of `count` bodies of the particle model: translation
/// only. Neither position nor angular velocity is read or written.
template <class T>
struct ParticleView {
  std::size_t count = 0;
  T* inv_mass = nullptr;  ///< [1/kg], 0 = immovable
  Vec3Array<T> v;         ///< [m/s], updated
};

/// What the solver does with a body array (for_each_array).
enum class ArrayRole {
  inverse,   ///< an inverse mass or moment: read; finite and >= 0
  state,     ///< a position or orientation component: read; finite
  velocity,  ///< a velocity component: read, and written for movable bodies; finite
};

/// The member of a body view an array belongs to. The kernel's lanes and the
/// packed records (collide/packed.hpp) name their members the same way, so
/// one field table serves them all (body_member).
enum class BodyMember : std::uint8_t { inv_mass, inv_inertia, q, p, v, w };

/// One member of a body model: where it lives, what the solver does with
/// it, and the name the checks give each of its arrays (one for a scalar,
/// three for a vector, four for the quaternion: w, x, y, z).
struct BodyMemberRow {
  BodyMember member;
  ArrayRole role;
  const char* names[4];
  [[nodiscard]] constexpr std::size_t components() const {
    std::size_t n = 0;
    while (n < 4 && names[n] != nullptr) ++n;
    return n;
  }
};

/// The field table of each model: its members in member order, the one list
/// of a model's arrays. Validation, the solver's boundary checks, packing,
/// the owning buffers and the kernel's loads and stores all walk these
/// tables (for_each_body_field).
inline constexpr BodyMemberRow kRigidFields[] = {
    {BodyMember::inv_mass, ArrayRole::inverse, {"inv_mass"}},
    {BodyMember::inv_inertia, ArrayRole::inverse, {"inv_inertia.x", "inv_inertia.y", "inv_inertia.z"}},
    {BodyMember::q, ArrayRole::state, {"q.w", "q.x", "q.y", "q.z"}},
    {BodyMember::p, ArrayRole::state, {"p.x", "p.y", "p.z"}},
    {BodyMember::v, ArrayRole::velocity, {"v.x", "v.y", "v.z"}},
    {BodyMember::w, ArrayRole::velocity, {"w.x", "w.y", "w.z"}},
};
inline constexpr BodyMemberRow kSphereFields[] = {
    {BodyMember::inv_mass, ArrayRole::inverse, {"inv_mass"}},
    {BodyMember::inv_inertia, ArrayRole::inverse, {"inv_inertia"}},
    {BodyMember::p, ArrayRole::state, {"p.x", "p.y", "p.z"}},
    {BodyMember::v, ArrayRole::velocity, {"v.x", "v.y", "v.z"}},
    {BodyMember::w, ArrayRole::velocity, {"w.x", "w.y", "w.z"}},
};
inline constexpr BodyMemberRow kParticleFields[] = {
    {BodyMember::inv_mass, ArrayRole::inverse, {"inv_mass"}},
    {BodyMember::v, ArrayRole::velocity, {"v.x", "v.y", "v.z"}},
};

/// One array of a body model: an element of one of its members.
struct BodyField {
  const char* name;
  BodyMember member;
  /// The element of a vector member: x, y, z = 0, 1, 2; of q: w, x, y, z =
  /// 0, 1, 2, 3; 0 for a scalar member.
  std::size_t component;
  ArrayRole role;
};

/// The number of arrays of a field table.
template <std::size_t N>
constexpr std::size_t field_count(const BodyMemberRow (&rows)[N]) {
  std::size_t n = 0;
  for (const BodyMemberRow& row : rows) n += row.components();
  return n;
}

/// Array K of a field table, counted over its members' elements in order.
template <std::size_t N>
constexpr BodyField field_at(const BodyMemberRow (&rows)[N], std::size_t k) {
  for (const BodyMemberRow& row : rows) {
    if (k < row.components()) return {row.names[k], row.member, k, row.role};
    k -= row.components();
  }
  return {nullptr, BodyMember::inv_mass, 0, ArrayRole::inverse};  // not reached: k < field_count(rows)
}

/// The field table of a model's view type (and, in collide/packed.hpp, of
/// its packed record): `rows` is one of the tables above.
template <class View>
struct BodyFieldTable;
template <class T>
struct BodyFieldTable<BodyView<T>> {
  static constexpr const auto& rows = kRigidFields;
};
template <class T>
struct BodyFieldTable<SphereView<T>> {
  static constexpr const auto& rows = kSphereFields;
};
template <class T>
struct BodyFieldTable<ParticleView<T>> {
  static constexpr const auto& rows = kParticleFields;
};

/// The number of arrays of Table's model.
template <class Table>
inline constexpr std::size_t kFieldCount = field_count(BodyFieldTable<Table>::rows);

namespace body_fields_detail {
template <class X, class = void>
struct HasX : std::false_type {};
template <class X>
struct HasX<X, std::void_t<decltype(std::declval<X&>().x)>> : std::true_type {};

// Element C of a member: of a C array by index, of a struct by x, y, z (a
// quaternion by w, x, y, z), and a scalar member (or a pointer to its
// array) is its own element 0.
template <std::size_t C, bool kQuaternion, class X>
constexpr auto& element(X& x) {
  using U = std::remove_const_t<X>;
  if constexpr (std::is_array_v<U>) {
    return x[C];
  } else if constexpr (kQuaternion) {
    static_assert(C < 4);
    if constexpr (C == 0) return x.w;
    if constexpr (C == 1) return x.x;
    if constexpr (C == 2) return x.y;
    if constexpr (C == 3) return x.z;
  } else if constexpr (HasX<U>::value) {
    static_assert(C < 3);
    if constexpr (C == 0) return x.x;
    if constexpr (C == 1) return x.y;
    if constexpr (C == 2) return x.z;
  } else {
    static_assert(C == 0);
    return x;
  }
}
}  // namespace body_fields_detail

/// Member M, element C, of anything that names its members as the views do:
/// a view (the array), the kernel's lanes (the lane), a packed record (the
/// value).
template <BodyMember M, std::size_t C, class S>
constexpr auto& body_member(S& s) {
  using body_fields_detail::element;
  if constexpr (M == BodyMember::inv_mass) return element<C, false>(s.inv_mass);
  if constexpr (M == BodyMember::inv_inertia) return element<C, false>(s.inv_inertia);
  if constexpr (M == BodyMember::q) return element<C, true>(s.q);
  if constexpr (M == BodyMember::p) return element<C, false>(s.p);
  if constexpr (M == BodyMember::v) return element<C, false>(s.v);
  if constexpr (M == BodyMember::w) return element<C, false>(s.w);
}

/// Array K of Table's model as a type, for code that walks the table at
/// compile time: `field` is the entry, of(s) its member element in s.
template <class Table, std::size_t K>
struct BodyFieldAt {
  static constexpr BodyField field = field_at(BodyFieldTable<Table>::rows, K);
  static constexpr std::size_t index = K;
  template <class S>
  static constexpr auto& of(S& s) {
    return body_member<field.member, field.component>(s);
  }
};

namespace body_fields_detail {
template <class Table, class F, std::size_t... K>
constexpr void each_field(F& f, std::index_sequence<K...> /*fields*/) {
  (f(BodyFieldAt<Table, K>{}), ...);
}
}  // namespace body_fields_detail

/// Calls f(BodyFieldAt<Table, K>{}) for every array K of Table's model, in
/// table order.
template <class Table, class F>
constexpr void for_each_body_field(F&& f) {
  body_fields_detail::each_field<Table>(f, std::make_index_sequence<kFieldCount<Table>>{});
}

/// Calls f(name, array, role) for every array of the view, in table order:
/// the walk the checks at the solver's boundaries (validate(),
/// Solver::solve) make.
template <class View, class F>
void for_each_array(const View& b, F&& f) {
  for_each_body_field<View>([&](auto at) {
    using At = decltype(at);
    f(At::field.name, At::of(b), At::field.role);
  });
}

/// The sphere-model view of rigid bodies (uses inv_inertia.x as the one
/// moment; see choose_model() in model.hpp for when that is the law).
template <class T>
SphereView<T> sphere_view(const BodyView<T>& b) {
  return {b.count, b.inv_mass, b.inv_inertia.x, b.p, b.v, b.w};
}

/// The particle-model view of rigid bodies.
template <class T>
ParticleView<T> particle_view(const BodyView<T>& b) {
  return {b.count, b.inv_mass, b.v};
}

/// The read-only form of a body view (the same arrays).
template <class T>
BodyView<const T> const_view(const BodyView<T>& b) {
  return {b.count,
          b.inv_mass,
          {b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z},
          {b.q.w, b.q.x, b.q.y, b.q.z},
          {b.p.x, b.p.y, b.p.z},
          {b.v.x, b.v.y, b.v.z},
          {b.w.x, b.w.y, b.w.z}};
}

/// One body as a scene file describes it, in physical units. Convenience for
/// building scenes; the kernels never see this type.
template <class T>
struct BodyRecord {
  T m = 1;                ///< mass [kg]; inf = immovable
  T I[3] = {1, 1, 1};     ///< principal moments [kg m^2]; inf = no rotation about that axis
  T q[4] = {1, 0, 0, 0};  ///< orientation (w, x, y, z), need not be normalised
  T p[3] = {0, 0, 0};     ///< centre of mass [m]
  T v[3] = {0, 0, 0};     ///< linear velocity [m/s]
  T w[3] = {0, 0, 0};     ///< angular velocity [rad/s]
};

/// Owning structure-of-arrays storage for bodies.
template <class T>
class BodyBuffer {
 public:
  BodyBuffer() = default;
  explicit BodyBuffer(std::size_t n) { resize(n); }

  void resize(std::size_t n);
  void reserve(std::size_t n);
  [[nodiscard]] std::size_t size() const { return columns_[0].size(); }

  /// Appends a body given in physical units: stores 1/m and 1/I (0 for inf),
  /// zeroes the inverse moments of an immovable body and keeps q as given
  /// (the kernels normalise it, as the law says). A body that breaks a rule
  /// of collide/rules.hpp is refused, nothing stored:
  /// std::invalid_argument("collide::BodyBuffer::push_back: body 3,
  /// column 'm': mass must be > 0, got -1"). (Tests that need a poisoned
  /// value in a kernel write it through view() afterwards.)
  void push_back(const BodyRecord<T>& body);
  /// Writes body i from physical units, as push_back does (and refuses what
  /// push_back refuses, naming "collide::BodyBuffer::set").
  void set(std::size_t i, const BodyRecord<T>& body);
  /// Reads body i back in physical units (1/0 gives inf).
  [[nodiscard]] BodyRecord<T> record(std::size_t i) const;

  [[nodiscard]] BodyView<T> view();
  [[nodiscard]] BodyView<const T> view() const;

 private:
  using Column = std::vector<T, LargeAllocator<T>>;
  /// One column per array of kRigidFields, in table order.
  std::array<Column, field_count(kRigidFields)> columns_;
};

/// True for the inverse mass of an immovable body: 0, whatever the moments
/// say. The one rule the kernels, the schedule and the islands apply.
template <class T>
[[nodiscard]] constexpr bool is_immovable(T inv_mass) {
  return inv_mass == T(0);
}

/// True when the view's body i is immovable (inverse mass 0).
template <class T>
[[nodiscard]] inline bool is_immovable(const BodyView<T>& bodies, std::size_t i) {
  return is_immovable(bodies.inv_mass[i]);
}

extern template class BodyBuffer<float>;
extern template class BodyBuffer<double>;
extern template class BodyBuffer<long double>;

}  // namespace collide
