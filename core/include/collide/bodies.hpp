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

#include <cstddef>
#include <cstdint>
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

/// Calls f(name, array, role) for every array of the view, in member order:
/// the one list of a view's arrays that the checks at the solver's
/// boundaries (validate(), Solver::solve) walk.
template <class T, class F>
void for_each_array(const BodyView<T>& b, F&& f) {
  f("inv_mass", b.inv_mass, ArrayRole::inverse);
  f("inv_inertia.x", b.inv_inertia.x, ArrayRole::inverse);
  f("inv_inertia.y", b.inv_inertia.y, ArrayRole::inverse);
  f("inv_inertia.z", b.inv_inertia.z, ArrayRole::inverse);
  f("q.w", b.q.w, ArrayRole::state);
  f("q.x", b.q.x, ArrayRole::state);
  f("q.y", b.q.y, ArrayRole::state);
  f("q.z", b.q.z, ArrayRole::state);
  f("p.x", b.p.x, ArrayRole::state);
  f("p.y", b.p.y, ArrayRole::state);
  f("p.z", b.p.z, ArrayRole::state);
  f("v.x", b.v.x, ArrayRole::velocity);
  f("v.y", b.v.y, ArrayRole::velocity);
  f("v.z", b.v.z, ArrayRole::velocity);
  f("w.x", b.w.x, ArrayRole::velocity);
  f("w.y", b.w.y, ArrayRole::velocity);
  f("w.z", b.w.z, ArrayRole::velocity);
}
template <class T, class F>
void for_each_array(const SphereView<T>& b, F&& f) {
  f("inv_mass", b.inv_mass, ArrayRole::inverse);
  f("inv_inertia", b.inv_inertia, ArrayRole::inverse);
  f("p.x", b.p.x, ArrayRole::state);
  f("p.y", b.p.y, ArrayRole::state);
  f("p.z", b.p.z, ArrayRole::state);
  f("v.x", b.v.x, ArrayRole::velocity);
  f("v.y", b.v.y, ArrayRole::velocity);
  f("v.z", b.v.z, ArrayRole::velocity);
  f("w.x", b.w.x, ArrayRole::velocity);
  f("w.y", b.w.y, ArrayRole::velocity);
  f("w.z", b.w.z, ArrayRole::velocity);
}
template <class T, class F>
void for_each_array(const ParticleView<T>& b, F&& f) {
  f("inv_mass", b.inv_mass, ArrayRole::inverse);
  f("v.x", b.v.x, ArrayRole::velocity);
  f("v.y", b.v.y, ArrayRole::velocity);
  f("v.z", b.v.z, ArrayRole::velocity);
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
  [[nodiscard]] std::size_t size() const { return inv_mass_.size(); }

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
  Column inv_mass_, ix_, iy_, iz_, qw_, qx_, qy_, qz_;
  Column px_, py_, pz_, vx_, vy_, vz_, wx_, wy_, wz_;
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
