// rules.cpp - the input rules of rules.hpp.
//
// Each rule is one small predicate below. The defect finders walk them in
// column order and add the text; the boolean verdicts (body_ok, contact_ok),
// which the reader's fast path runs on every row, evaluate the same
// predicates without a branch per value, and the defect finders call them
// first, so a valid record costs one verdict. tests/core/test_rules.cpp
// checks that verdicts and defects agree.
#include "collide/rules.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <type_traits>

namespace collide {
namespace {

/// The shortest text that reads back to the same T ("inf", "-0", "nan").
template <class T>
std::string number(T value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, r.ptr);
}

/// 9 significant digits of a derived double (a length), as %.9g.
std::string derived(double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, 9);
  return std::string(buf, r.ptr);
}

// ---------------------------------------------------------------------------
// Bodies
// ---------------------------------------------------------------------------

constexpr std::size_t kMass = 0;
constexpr std::size_t kLastMoment = 3;
constexpr std::size_t kQw = 4;

/// The seventeen values of a body in column order (kBodyColumns).
template <class T>
std::array<T, 17> body_values(const BodyRecord<T>& b) {
  return {b.m,    b.I[0], b.I[1], b.I[2], b.q[0], b.q[1], b.q[2], b.q[3], b.p[0],
          b.p[1], b.p[2], b.v[0], b.v[1], b.v[2], b.w[0], b.w[1], b.w[2]};
}

enum class ValueFault { none, nan, inf, not_positive, inverse_overflows };

/// The single-column rules of body column k.
template <class T>
ValueFault body_value_fault(std::size_t k, T v) {
  if (std::isnan(v)) return ValueFault::nan;
  if (k <= kLastMoment) {
    if (!(v > T(0))) return ValueFault::not_positive;
    if (!std::isfinite(T(1) / v)) return ValueFault::inverse_overflows;
    return ValueFault::none;
  }
  return std::isinf(v) ? ValueFault::inf : ValueFault::none;
}

enum class QuaternionFault { none, zero, too_small, too_large };

/// Why quaternion_normalisable(q) fails, if it does. Assumes finite
/// components.
template <class T>
QuaternionFault quaternion_fault(const T* q) {
  if (q[0] == T(0) && q[1] == T(0) && q[2] == T(0) && q[3] == T(0)) return QuaternionFault::zero;
  const T q2 = quaternion_square(q[0], q[1], q[2], q[3]);
  if (!std::isfinite(q2)) return QuaternionFault::too_large;
  if (!(q2 >= std::numeric_limits<T>::min())) return QuaternionFault::too_small;
  return QuaternionFault::none;
}

std::string inf_reason(const std::string& value) {
  return "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got " + value;
}

template <class T>
std::string value_reason(std::size_t k, T v, ValueFault fault) {
  const char* what = k == kMass ? "mass" : "moment of inertia";
  switch (fault) {
    case ValueFault::nan:
      return "NaN is not allowed";
    case ValueFault::inf:
      return inf_reason(number(v));
    case ValueFault::not_positive:
      // A zero names what the caller probably meant: inf, the immovable
      // body or the locked axis.
      return std::string(what) + " must be > 0, got " + number(v) +
             (v != T(0)    ? ""
              : k == kMass ? " (an immovable body has m = inf)"
                           : " (a locked axis has moment inf)");
    case ValueFault::inverse_overflows:
      return std::string(what) + " " + number(v) + " is too small: its inverse overflows " + precision_name<T>();
    case ValueFault::none:
      break;
  }
  return std::string();
}

template <class T>
std::string listed(const T* x, std::size_t n) {
  std::string s;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) s += ", ";
    s += number(x[k]);
  }
  return s;
}

// ---------------------------------------------------------------------------
// Contacts
// ---------------------------------------------------------------------------

constexpr std::size_t kFirstValue = 2;  // cx: the columns after a and b
constexpr std::size_t kNx = 5;
constexpr std::size_t kE = 8;
constexpr std::size_t kMu = 9;

/// cx, cy, cz, nx, ny, nz, e, mu.
template <class T>
std::array<T, 8> contact_values(const ContactRecord<T>& c) {
  return {c.c[0], c.c[1], c.c[2], c.n[0], c.n[1], c.n[2], c.e, c.mu};
}

bool id_in_range(BodyIndex id, std::size_t body_count) {
  return body_count == kUnknownBodyCount || static_cast<std::size_t>(id) < body_count;
}

template <class T>
bool e_ok(T e) {
  return e >= T(0) && e <= T(1);
}
template <class T>
bool mu_ok(T mu) {
  return mu >= T(0);
}

}  // namespace

template <class T>
bool body_ok(const BodyRecord<T>& body) noexcept {
  // body_value_fault(k, v) == none for every column, without a branch per
  // value: m and the moments > 0 (false for NaN) with a finite inverse, every
  // other value finite.
  const std::array<T, 17> v = body_values(body);
  bool ok = true;
  for (std::size_t k = 0; k <= kLastMoment; ++k) {
    ok &= v[k] > T(0);
    ok &= static_cast<bool>(std::isfinite(T(1) / v[k]));
  }
  for (std::size_t k = kLastMoment + 1; k < v.size(); ++k) ok &= static_cast<bool>(std::isfinite(v[k]));
  return ok && quaternion_fault(body.q) == QuaternionFault::none;
}

template <class T>
std::optional<Defect> body_defect(const BodyRecord<T>& body) {
  if (body_ok(body)) return std::nullopt;
  const std::array<T, 17> v = body_values(body);
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (const ValueFault f = body_value_fault(k, v[k]); f != ValueFault::none) {
      return Defect{kBodyColumns[k], value_reason(k, v[k], f)};
    }
  }
  const std::string values = " (qw, qx, qy, qz = " + listed(body.q, 4) + ")";
  switch (quaternion_fault(body.q)) {
    case QuaternionFault::zero:
      return Defect{kBodyColumns[kQw], "zero quaternion (qw, qx, qy, qz are all 0)"};
    case QuaternionFault::too_small:
      return Defect{kBodyColumns[kQw], std::string("quaternion cannot be normalised in ") + precision_name<T>() +
                                           ": it is too close to zero" + values};
    case QuaternionFault::too_large:
      return Defect{kBodyColumns[kQw], std::string("quaternion cannot be normalised in ") + precision_name<T>() +
                                           ": it is too large" + values};
    case QuaternionFault::none:
      break;
  }
  return std::nullopt;  // not reached: body_ok said there is a defect
}

template <class T>
bool contact_ok(const ContactRecord<T>& contact, std::size_t body_count) noexcept {
  if (!id_in_range(contact.a, body_count) || !id_in_range(contact.b, body_count) || contact.a == contact.b) {
    return false;
  }
  bool ok = true;
  for (const T x : contact_values(contact)) ok = ok && std::isfinite(x);
  return ok && e_ok(contact.e) && mu_ok(contact.mu) && unit_length_ok(length_in_double(contact.n, 3));
}

template <class T>
std::optional<Defect> contact_defect(const ContactRecord<T>& contact, std::size_t body_count) {
  if (contact_ok(contact, body_count)) return std::nullopt;
  if (!id_in_range(contact.a, body_count)) {
    return Defect{kContactColumns[0], body_id_out_of_range(std::to_string(contact.a), body_count)};
  }
  if (!id_in_range(contact.b, body_count)) {
    return Defect{kContactColumns[1], body_id_out_of_range(std::to_string(contact.b), body_count)};
  }
  if (contact.a == contact.b) {
    return Defect{kContactColumns[1], "contact of body " + std::to_string(contact.a) + " with itself (a == b)"};
  }
  const std::array<T, 8> v = contact_values(contact);
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (std::isnan(v[k])) return Defect{kContactColumns[kFirstValue + k], "NaN is not allowed"};
    if (std::isinf(v[k])) return Defect{kContactColumns[kFirstValue + k], inf_reason(number(v[k]))};
  }
  if (!e_ok(contact.e)) return Defect{kContactColumns[kE], "e must be in [0, 1], got " + number(contact.e)};
  if (!mu_ok(contact.mu)) return Defect{kContactColumns[kMu], "mu must be >= 0, got " + number(contact.mu)};
  const double length = length_in_double(contact.n, 3);
  return Defect{kContactColumns[kNx], "normal length " + derived(length) +
                                          " is not 1 within 1e-3 (nx, ny, nz = " + listed(contact.n, 3) + ")"};
}

std::string body_id_out_of_range(std::string_view id, std::size_t body_count) {
  std::string s = "body id ";
  s.append(id);
  s += " is out of range: the scene has " + std::to_string(body_count) + " bodies";
  if (body_count > 0) s += " (ids 0 to " + std::to_string(body_count - 1) + ")";
  return s;
}

// Written out (clang-tidy: no macros over types).
template std::optional<Defect> body_defect<float>(const BodyRecord<float>&);
template std::optional<Defect> body_defect<double>(const BodyRecord<double>&);
template std::optional<Defect> body_defect<long double>(const BodyRecord<long double>&);
template bool body_ok<float>(const BodyRecord<float>&) noexcept;
template bool body_ok<double>(const BodyRecord<double>&) noexcept;
template bool body_ok<long double>(const BodyRecord<long double>&) noexcept;
template std::optional<Defect> contact_defect<float>(const ContactRecord<float>&, std::size_t);
template std::optional<Defect> contact_defect<double>(const ContactRecord<double>&, std::size_t);
template std::optional<Defect> contact_defect<long double>(const ContactRecord<long double>&, std::size_t);
template bool contact_ok<float>(const ContactRecord<float>&, std::size_t) noexcept;
template bool contact_ok<double>(const ContactRecord<double>&, std::size_t) noexcept;
template bool contact_ok<long double>(const ContactRecord<long double>&, std::size_t) noexcept;

}  // namespace collide
