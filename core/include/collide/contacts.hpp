// collide/contacts.hpp - the contact data model and the impulse output.
//
// A contact joins body `a` and body `b` at world point `c` with normal `n`
// pointing from b towards a (the impulse on a is along +n); the law takes
// n / |n|, so n need be unit only within the input tolerance. Restitution
// and friction are optional arrays so that a scene pays only for what it
// models:
//   * `e == nullptr`   - every contact uses `uniform_e`;
//   * `mu == nullptr`  - the scene is frictionless; no tangent is computed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/large_allocator.hpp"

namespace collide {

/// Body index type. A scene holds at most 2^32 - 1 bodies.
using BodyIndex = std::uint32_t;

/// Non-owning, read-only view of `count` contacts.
template <class T>
struct ContactView {
  std::size_t count = 0;
  const BodyIndex* a = nullptr;  ///< body receiving +J
  const BodyIndex* b = nullptr;  ///< body receiving -J
  Vec3Array<const T> c;          ///< contact point, world frame [m]
  Vec3Array<const T> n;          ///< normal from b towards a, |n| = 1 within 1e-3 (the kernels normalise it)
  const T* e = nullptr;          ///< restitution in [0, 1]; nullptr = uniform_e
  T uniform_e = 1;               ///< restitution when `e` is nullptr
  const T* mu = nullptr;         ///< Coulomb friction >= 0; nullptr = frictionless
};

/// Contacts first .. first + count - 1 of `v`, as a view of the same arrays
/// (no copy, no renormalising). Requires first + count <= v.count. Null
/// arrays stay null (e, mu, and c, which a particle solve does not need).
template <class T>
ContactView<T> contact_slice(ContactView<T> v, std::size_t first, std::size_t count) {
  v.count = count;
  v.a += first;
  v.b += first;
  if (v.c.x) v.c.x += first;
  if (v.c.y) v.c.y += first;
  if (v.c.z) v.c.z += first;
  v.n.x += first;
  v.n.y += first;
  v.n.z += first;
  if (v.e) v.e += first;
  if (v.mu) v.mu += first;
  return v;
}

/// Non-owning view of the impulse output: J, the total impulse on body a [N s].
template <class T>
struct ImpulseView {
  std::size_t count = 0;
  Vec3Array<T> j;
};

/// One contact in scene-file form. Convenience for building scenes.
template <class T>
struct ContactRecord {
  BodyIndex a = 0, b = 0;
  T c[3] = {0, 0, 0};
  T n[3] = {0, 0, 1};  ///< unit within 1e-3; stored as given (the kernels normalise it)
  T e = 1;
  T mu = 0;
};

/// Owning storage for contacts. Always carries per-contact e and mu arrays;
/// `view()` drops `mu` when every mu is 0, so such scenes run frictionless.
template <class T>
class ContactBuffer {
 public:
  ContactBuffer() = default;
  explicit ContactBuffer(std::size_t n) { resize(n); }
  void resize(std::size_t n);
  void reserve(std::size_t n);
  [[nodiscard]] std::size_t size() const { return a_.size(); }

  /// Appends a contact. One that breaks a rule of collide/rules.hpp (NaN,
  /// inf, |n| not 1 within kNormalTolerance, e outside [0, 1], mu < 0,
  /// a == b; ids are not checked against a body count, which the buffer does
  /// not know) is refused, nothing stored: std::invalid_argument(
  /// "collide::ContactBuffer::push_back: contact 3, column 'e': ...").
  void push_back(const ContactRecord<T>& contact);
  /// Writes contact i, as push_back does (std::invalid_argument naming
  /// "collide::ContactBuffer::set").
  void set(std::size_t i, const ContactRecord<T>& contact);
  [[nodiscard]] ContactRecord<T> record(std::size_t i) const;

  /// Copies another view element by element with static_cast and no
  /// renormalisation (see convert_contacts in scene.hpp).
  template <class U>
  void assign_exact(const ContactView<U>& src) {
    resize(src.count);
    for (std::size_t i = 0; i < src.count; ++i) {
      a_[i] = src.a[i];
      b_[i] = src.b[i];
      cx_[i] = static_cast<T>(src.c.x[i]);
      cy_[i] = static_cast<T>(src.c.y[i]);
      cz_[i] = static_cast<T>(src.c.z[i]);
      nx_[i] = static_cast<T>(src.n.x[i]);
      ny_[i] = static_cast<T>(src.n.y[i]);
      nz_[i] = static_cast<T>(src.n.z[i]);
      e_[i] = static_cast<T>(src.e ? src.e[i] : src.uniform_e);
      mu_[i] = static_cast<T>(src.mu ? src.mu[i] : U(0));
    }
  }

  [[nodiscard]] ContactView<T> view() const;
  /// True when some contact has mu > 0.
  [[nodiscard]] bool has_friction() const;

 private:
  std::vector<BodyIndex, LargeAllocator<BodyIndex>> a_, b_;
  std::vector<T, LargeAllocator<T>> cx_, cy_, cz_, nx_, ny_, nz_, e_, mu_;
};

/// Owning storage for impulses.
template <class T>
class ImpulseBuffer {
 public:
  ImpulseBuffer() = default;
  explicit ImpulseBuffer(std::size_t n) { resize(n); }
  void resize(std::size_t n) {
    x_.assign(n, T(0));
    y_.assign(n, T(0));
    z_.assign(n, T(0));
  }
  [[nodiscard]] std::size_t size() const { return x_.size(); }
  [[nodiscard]] ImpulseView<T> view() { return {x_.size(), {x_.data(), y_.data(), z_.data()}}; }
  [[nodiscard]] ImpulseView<const T> view() const { return {x_.size(), {x_.data(), y_.data(), z_.data()}}; }

 private:
  std::vector<T, LargeAllocator<T>> x_, y_, z_;
};

extern template class ContactBuffer<float>;
extern template class ContactBuffer<double>;
extern template class ContactBuffer<long double>;

}  // namespace collide
