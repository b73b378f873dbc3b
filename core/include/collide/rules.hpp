// collide/rules.hpp - the input rules of the law, in one place.
//
// Design notes
// ------------
// * One statement of what a body and a contact may hold, in physical units:
//   what a scene file row or a caller's constructor gives (BodyRecord<T>,
//   ContactRecord<T>), in the precision T the kernel will run in. The scene
//   reader (scene_io.hpp), the buffers' set() and push_back() (bodies.hpp,
//   contacts.hpp) and the Python constructors all ask these functions, so a
//   defect is refused everywhere, with the same reason text.
// * The rules (docs/collision-law.md, "Bad input"):
//     - NaN nowhere; inf only in m (immovable) and in Ix, Iy, Iz (locked
//       axis);
//     - m > 0 and 1/m finite in T, and each moment the same: what each
//       precision can represent (in float 1e-45 is > 0, but its inverse
//       overflows);
//     - q not all zero, and |q|^2, summed in T as the kernel's conversion
//       sums it, a normal finite number (not subnormal, not overflowing), so
//       that q / |q| can be computed in T;
//     - |n| within kNormalTolerance of 1, judged in double from the T values;
//     - e in [0, 1]; mu >= 0 (and finite, as above);
//     - a != b, and a and b below the body count where it is known.
// * A defect is reported as the CSV column it is in ("m", "Ix", "qw", "nx",
//   "mu", ...; the quaternion rule names "qw", the normal rule "nx", a
//   contact of a body with itself "b") and a reason formed from the values
//   (shortest round-trip text, std::to_chars), never from the text they
//   were read from, so that the same defect gives the same reason from every
//   source: "mass must be > 0, got -1". Callers prefix the location: the
//   reader "bodies.csv:5: row 3, column 'm': ", the buffers
//   "collide::BodyBuffer::set: body 3, column 'm': ".
// * Rules are checked in column order, the multi-column ones (the quaternion,
//   the normal) after every single-column one; the first defect is reported.
// * `body_ok` and `contact_ok` give the same verdicts as `body_defect` and
//   `contact_defect` without forming a message: the cheap form for loops
//   over valid data.
// * The rules exist for float, double and long double (the buffers' precisions).
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"

namespace collide {

/// Columns of bodies.csv, in file order: the names rules report.
inline constexpr std::array<std::string_view, 17> kBodyColumns = {"m",  "Ix", "Iy", "Iz", "qw", "qx", "qy", "qz", "px",
                                                                  "py", "pz", "vx", "vy", "vz", "wx", "wy", "wz"};
/// Columns of contacts.csv, in file order.
inline constexpr std::array<std::string_view, 10> kContactColumns = {"a",  "b",  "cx", "cy", "cz",
                                                                     "nx", "ny", "nz", "e",  "mu"};

/// Allowed deviation of |n| from 1.
inline constexpr double kNormalTolerance = 1e-3;

/// "float", "double" or "long double": the precision a reason names.
template <class T>
constexpr const char* precision_name() {
  if constexpr (std::is_same_v<T, float>) {
    return "float";
  } else if constexpr (std::is_same_v<T, double>) {
    return "double";
  } else {
    return "long double";
  }
}

/// No body count to check ids against (a != b is still checked).
inline constexpr std::size_t kUnknownBodyCount = static_cast<std::size_t>(-1);

/// The first broken rule of a body or a contact.
struct Defect {
  std::string_view column;  ///< the CSV column (kBodyColumns / kContactColumns)
  std::string reason;       ///< e.g. "mass must be > 0, got -1"
};

/// The first defect of a body in physical units, or nothing.
template <class T>
std::optional<Defect> body_defect(const BodyRecord<T>& body);
/// Whether a body has no defect (the verdict of body_defect, no message).
template <class T>
bool body_ok(const BodyRecord<T>& body) noexcept;

/// The first defect of a contact, or nothing; ids are checked against
/// `body_count` unless it is kUnknownBodyCount.
template <class T>
std::optional<Defect> contact_defect(const ContactRecord<T>& contact, std::size_t body_count = kUnknownBodyCount);
/// Whether a contact has no defect (the verdict of contact_defect).
template <class T>
bool contact_ok(const ContactRecord<T>& contact, std::size_t body_count = kUnknownBodyCount) noexcept;

/// The reason for a body id at or above `body_count`, the id as written
/// (decimal digits): "body id 5 is out of range: the scene has 3 bodies (ids
/// 0 to 2)". contact_defect's text; the reader's too for ids too large for
/// BodyIndex.
std::string body_id_out_of_range(std::string_view id, std::size_t body_count);

/// |q|^2 summed in T in the kernels' order, ((w^2 + x^2) + y^2) + z^2.
template <class T>
T quaternion_square(T w, T x, T y, T z) noexcept {
  return ((w * w + x * x) + y * y) + z * z;
}

/// The quaternion rule: q / |q| can be formed in T, i.e. quaternion_square
/// is a normal, finite number (false for a zero q, NaN, or a q too small or
/// too large). The scene files and validate() apply it alike.
template <class T>
bool quaternion_normalisable(T w, T x, T y, T z) noexcept {
  const T q2 = quaternion_square(w, x, y, z);
  return std::isfinite(q2) && q2 >= std::numeric_limits<T>::min();
}

/// Whether a length is 1 within kNormalTolerance (false for NaN).
inline bool unit_length_ok(double length) { return std::fabs(length - 1.0) <= kNormalTolerance; }

/// |x| of n values of T, in double (no overflow, and far more accurate than
/// the tolerance).
template <class T>
double length_in_double(const T* x, std::size_t n) {
  double s = 0;
  for (std::size_t k = 0; k < n; ++k) s += static_cast<double>(x[k]) * static_cast<double>(x[k]);
  return std::sqrt(s);
}

}  // namespace collide
