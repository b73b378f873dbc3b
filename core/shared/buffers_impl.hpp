// buffers_impl.hpp - the member definitions of the owning SoA buffers of
// bodies.hpp and contacts.hpp, for the files that instantiate them: the core's
// buffers.cpp (float, double, long double) and the evaluation's
// quad_buffers.cpp (__float128, the reference's precision where GCC has it),
// so the core itself needs no quad-precision runtime.
//
// The only arithmetic here is the conversion from scene-file units to what the
// kernel consumes: 1/m and 1/I (0 for inf). It is done once, at the boundary,
// so that the kernels never divide by a mass. q and n are stored as given:
// the law normalises them, and the kernels do so in the precision of the
// accuracy mode, so the accurate mode starts from the caller's values.
//
// set() and push_back() first check the record with the rules of
// collide/rules.hpp (std::invalid_argument naming the element and the
// column). The __float128 buffers of the reference have no rules of their
// own: they are filled by exact conversion (convert_bodies, assign_exact)
// from buffers that were checked in their own precision.
#pragma once

#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/rules.hpp"

namespace collide {
namespace buffers_detail {

// isinf and inf for every T a buffer holds (__float128 has no std::
// overloads, and numeric_limits knows it only in GNU mode).
template <class T>
bool is_infinite(T x) {
  // x == x fails only for NaN, x - x == x - x only for inf and NaN.
  // NOLINTNEXTLINE(misc-redundant-expression): both sides are the same on purpose
  return x == x && !(x - x == x - x);
}
template <class T>
T infinity() {
  // double's inf converts exactly to inf in every T (HUGE_VALQ would need quadmath.h).
  return static_cast<T>(std::numeric_limits<double>::infinity());
}

// 1/x with 1/inf = 0 (an immovable body or a locked axis).
template <class T>
T inverse_or_zero(T x) {
  return is_infinite(x) ? T(0) : T(1) / x;
}

// 1/x with 1/0 = inf, the inverse of inverse_or_zero.
template <class T>
T inverse_or_inf(T x) {
  return x == T(0) ? infinity<T>() : T(1) / x;
}

// The precisions rules.hpp states its rules for.
template <class T>
constexpr bool kHasRules = std::is_same_v<T, float> || std::is_same_v<T, double> || std::is_same_v<T, long double>;

[[noreturn]] inline void throw_defect(const char* where, const char* element, std::size_t i, const Defect& defect) {
  throw std::invalid_argument(std::string(where) + ": " + element + " " + std::to_string(i) + ", column '" +
                              std::string(defect.column) + "': " + defect.reason);
}

// Throws std::invalid_argument("<where>: body <i>, column 'm': <reason>")
// for a body that breaks a rule of rules.hpp.
template <class T>
void check_body(const char* where, std::size_t i, const BodyRecord<T>& body) {
  if constexpr (kHasRules<T>) {
    if (body_ok(body)) return;
    if (const std::optional<Defect> d = body_defect(body)) throw_defect(where, "body", i, *d);
  }
}

// The same for a contact (no body count: ids are not range-checked).
template <class T>
void check_contact(const char* where, std::size_t i, const ContactRecord<T>& contact) {
  if constexpr (kHasRules<T>) {
    if (contact_ok(contact)) return;
    if (const std::optional<Defect> d = contact_defect(contact)) throw_defect(where, "contact", i, *d);
  }
}

}  // namespace buffers_detail

// The columns follow kRigidFields (collide/bodies.hpp): column K holds
// field K, so every member below walks the table.

template <class T>
void BodyBuffer<T>::resize(std::size_t n) {
  for_each_body_field<BodyView<T>>([&](auto at) {
    using At = decltype(at);
    // A new body is immovable, at rest, with the identity orientation.
    const bool unit = At::field.member == BodyMember::q && At::field.component == 0;
    columns_[At::index].resize(n, unit ? T(1) : T(0));
  });
}

template <class T>
void BodyBuffer<T>::reserve(std::size_t n) {
  for (Column& c : columns_) c.reserve(n);
}

template <class T>
void BodyBuffer<T>::push_back(const BodyRecord<T>& body) {
  buffers_detail::check_body("collide::BodyBuffer::push_back", size(), body);
  resize(size() + 1);
  set(size() - 1, body);
}

template <class T>
void BodyBuffer<T>::set(std::size_t i, const BodyRecord<T>& body) {
  buffers_detail::check_body("collide::BodyBuffer::set", i, body);
  const T inv_m = buffers_detail::inverse_or_zero(body.m);
  const bool immovable = inv_m == T(0);
  for_each_body_field<BodyView<T>>([&](auto at) {
    using At = decltype(at);
    T& value = columns_[At::index][i];
    if constexpr (At::field.member == BodyMember::inv_mass) {
      value = inv_m;
    } else if constexpr (At::field.member == BodyMember::inv_inertia) {
      // The law: "a body with m = inf is immovable whatever its I".
      value = immovable ? T(0) : buffers_detail::inverse_or_zero(body.I[At::field.component]);
    } else {
      // q (and p, v, w) as given: the kernels normalise q, as the law says,
      // in the precision of the accuracy mode (normalising here would round
      // it for both).
      value = At::of(body);
    }
  });
}

template <class T>
BodyRecord<T> BodyBuffer<T>::record(std::size_t i) const {
  BodyRecord<T> r;
  for_each_body_field<BodyView<T>>([&](auto at) {
    using At = decltype(at);
    const T value = columns_[At::index][i];
    if constexpr (At::field.member == BodyMember::inv_mass) {
      r.m = buffers_detail::inverse_or_inf(value);
    } else if constexpr (At::field.member == BodyMember::inv_inertia) {
      r.I[At::field.component] = buffers_detail::inverse_or_inf(value);
    } else {
      At::of(r) = value;
    }
  });
  return r;
}

namespace buffers_detail {
// The view of a buffer's columns, one per array of kRigidFields; U is T or const T.
template <class U, class Columns>
BodyView<U> column_view(Columns& columns) {
  BodyView<U> b;
  b.count = columns[0].size();
  for_each_body_field<BodyView<U>>([&](auto at) {
    using At = decltype(at);
    At::of(b) = columns[At::index].data();
  });
  return b;
}
}  // namespace buffers_detail

template <class T>
BodyView<T> BodyBuffer<T>::view() {
  return buffers_detail::column_view<T>(columns_);
}

template <class T>
BodyView<const T> BodyBuffer<T>::view() const {
  return buffers_detail::column_view<const T>(columns_);
}

template <class T>
void ContactBuffer<T>::resize(std::size_t n) {
  a_.resize(n, 0);
  b_.resize(n, 0);
  for (auto* v : {&cx_, &cy_, &cz_, &nx_, &ny_, &e_, &mu_}) {
    v->resize(n, T(0));
  }
  nz_.resize(n, T(1));
}

template <class T>
void ContactBuffer<T>::reserve(std::size_t n) {
  a_.reserve(n);
  b_.reserve(n);
  for (auto* v : {&cx_, &cy_, &cz_, &nx_, &ny_, &nz_, &e_, &mu_}) {
    v->reserve(n);
  }
}

template <class T>
void ContactBuffer<T>::push_back(const ContactRecord<T>& contact) {
  buffers_detail::check_contact("collide::ContactBuffer::push_back", size(), contact);
  resize(size() + 1);
  set(size() - 1, contact);
}

template <class T>
void ContactBuffer<T>::set(std::size_t i, const ContactRecord<T>& contact) {
  buffers_detail::check_contact("collide::ContactBuffer::set", i, contact);
  a_[i] = contact.a;
  b_[i] = contact.b;
  cx_[i] = contact.c[0];
  cy_[i] = contact.c[1];
  cz_[i] = contact.c[2];
  // n as given, like q above.
  nx_[i] = contact.n[0];
  ny_[i] = contact.n[1];
  nz_[i] = contact.n[2];
  e_[i] = contact.e;
  mu_[i] = contact.mu;
}

template <class T>
ContactRecord<T> ContactBuffer<T>::record(std::size_t i) const {
  ContactRecord<T> r;
  r.a = a_[i];
  r.b = b_[i];
  r.c[0] = cx_[i];
  r.c[1] = cy_[i];
  r.c[2] = cz_[i];
  r.n[0] = nx_[i];
  r.n[1] = ny_[i];
  r.n[2] = nz_[i];
  r.e = e_[i];
  r.mu = mu_[i];
  return r;
}

template <class T>
bool ContactBuffer<T>::has_friction() const {
  for (const T mu : mu_) {
    if (mu > T(0)) return true;
  }
  return false;
}

template <class T>
ContactView<T> ContactBuffer<T>::view() const {
  ContactView<T> v;
  v.count = size();
  v.a = a_.data();
  v.b = b_.data();
  v.c = {cx_.data(), cy_.data(), cz_.data()};
  v.n = {nx_.data(), ny_.data(), nz_.data()};
  v.e = e_.data();
  v.mu = has_friction() ? mu_.data() : nullptr;
  return v;
}

}  // namespace collide
