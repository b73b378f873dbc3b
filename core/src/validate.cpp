// validate.cpp - the boundary checks of validate.hpp.
//
// Design notes
// ------------
// Two passes of different kinds, so that valid input (the common case, and
// the one whose cost every Python call pays) is cheap:
//  * the screen: branch-free passes that only answer "all good", written on
//    the lane layer's lanes (lanes.hpp; 4 float or 2 double lanes in the
//    SSE2 baseline this file is built for; their cost against the scan's:
//    docs/decisions/0013-python-call-overhead.md), and run in parallel
//    chunks on large scenes, where one core's memory bandwidth is the
//    limit. Each screen is as strict as the scan's rule or stricter (the
//    unit-norm screen uses a band inside the scan's tolerance; -0.0 fails
//    the sign screen), so when every screen passes the scan would find
//    nothing. A screen ORs the bits of its values into integer lanes (a bit
//    cast of the lanes) across iterations and tests them once at the end,
//    with no compare in the loop and no floating-point value carried from
//    one iteration to the next. Compare masks OR-ed the same way give the
//    same verdicts but cost more on SSE2 with GCC 12's
//    std::experimental::simd: a double mask is OR-ed lane by lane through
//    general registers, and signbit of a double is a 64-bit integer compare
//    that SSE2 lacks, so validate() ran more instructions, most in double
//    (decision 0013 has the counts), where the bit form runs the
//    instructions of hand-written vectors;
//  * the scan: element by element in a fixed order, stopping at the first
//    problem so the message names one element. It runs only when a screen
//    fails, so the message does not depend on the screens.
#include "collide/validate.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>
#include <type_traits>
#include <vector>

#include "collide/accuracy.hpp"

#include "collide/rules.hpp"
#include "contact_indices.hpp"
#include "lanes.hpp"
#include "screen_chunks.hpp"

namespace collide {
namespace {

namespace stdx = std::experimental;

/// |q| and |n| must be 1 within the tolerance of the scene files
/// (rules.hpp): the law normalises them.
constexpr double kUnitTolerance = kNormalTolerance;

template <class T>
Validation fail(const char* view, const char* field, std::size_t i, T value, const char* what) {
  std::ostringstream s;
  s.precision(9);
  s << view << "." << field << "[" << i << "] = " << value << ": " << what;
  return {false, s.str()};
}

Validation fail_text(const std::string& text) { return {false, text}; }

/// One array of a body view (or one field of its packed records), with the
/// rule it must obey.
template <class T>
struct CheckedArray {
  const char* name;
  const T* data;
  bool inverse;            // an inverse mass or moment: finite and >= 0; otherwise finite
  std::size_t stride = 1;  // values from one body to the next: 1 in SoA views, the record size when packed
  [[nodiscard]] T operator[](std::size_t i) const { return data[i * stride]; }
};

/// The arrays of a SoA view (for_each_array), with their rules.
template <class View, class T = std::remove_const_t<std::remove_pointer_t<decltype(View::inv_mass)>>>
std::vector<CheckedArray<T>> fields_of(const View& b) {
  std::vector<CheckedArray<T>> fields;
  for_each_array(b, [&](const char* name, const T* data, ArrayRole role) {
    fields.push_back({name, data, role == ArrayRole::inverse});
  });
  return fields;
}

/// The fields of packed records, in table order (so the messages name the
/// same fields as the SoA views'); one null field when the records, or a
/// rigid view's inverse masses, are null.
template <class Record, class T = typename PackedValue<Record>::type>
std::vector<CheckedArray<T>> fields_of(const PackedView<Record>& b) {
  constexpr bool kRigid = std::is_same_v<Record, PackedRigid<T>>;
  if (b.bodies == nullptr) return {{"records", nullptr, false, 1}};
  if constexpr (kRigid) {
    if (b.inv_mass == nullptr) return {{"inv_mass", nullptr, true, 1}};
  }
  std::vector<CheckedArray<T>> fields;
  for_each_body_field<Record>([&](auto at) {
    using At = decltype(at);
    const bool inverse = At::field.role == ArrayRole::inverse;
    if constexpr (kKeptBeside<Record, At::field.member>) {
      fields.push_back({At::field.name, beside_records(b), inverse, 1});
    } else {
      fields.push_back({At::field.name, &At::of(b.bodies[0]), inverse, sizeof(Record) / sizeof(T)});
    }
  });
  return fields;
}

/// The quaternion of the rigid model, under the scene files' rule
/// (collide/rules.hpp): the law normalises q, so any q whose |q|^2 is a
/// normal, finite number in T is taken as given. Other models have none.
template <class T>
Validation check_quaternion(const T* q, std::size_t i) {
  if (quaternion_normalisable(q[0], q[1], q[2], q[3])) return {};
  return fail("bodies", "|q|^2", i, quaternion_square(q[0], q[1], q[2], q[3]),
              "must be a normal, finite number (the law normalises q)");
}
template <class T>
Validation check_orientation(const BodyView<T>& b, std::size_t i) {
  const T q[4] = {b.q.w[i], b.q.x[i], b.q.y[i], b.q.z[i]};
  return check_quaternion(q, i);
}
template <class T>
Validation check_orientation(const PackedView<PackedRigid<T>>& b, std::size_t i) {
  return check_quaternion(b.bodies[i].q, i);
}
template <class View>
Validation check_orientation(const View&, std::size_t) {
  return {};
}

// ---------------------------------------------------------------------------
// Screens: no early exit and no compare-and-branch per element; true = all good.
// ---------------------------------------------------------------------------

/// The lanes of the screens: the lane layer's (lanes.hpp) for the ISA this
/// file is built for, the x86-64 baseline SSE2: 4 float or 2 double lanes.
template <class T>
using Lanes = detail::SimdLanes<T>;

/// Integer lanes as wide as the values of V, for their bits.
template <class V>
using BitLanes =
    stdx::rebind_simd_t<std::conditional_t<sizeof(typename V::value_type) == 8, std::int64_t, std::int32_t>, V>;

/// The bits of every lane of x (std::bit_cast: no instruction).
template <class V>
COLLIDE_LANE_INLINE BitLanes<V> bits(const V& x) {
  static_assert(sizeof(BitLanes<V>) == sizeof(V));
  return std::bit_cast<BitLanes<V>>(x);
}

/// The test of a screen's bits: no bit but the sign bit in `finite_bits`
/// (the bits of values x * 0), no sign bit in `sign` (the bits of values
/// that must be >= 0).
template <class I>
bool bits_ok(const I& finite_bits, const I& sign) {
  using Int = typename I::value_type;
  const I defects = (finite_bits & I(std::numeric_limits<Int>::max())) | (sign & I(std::numeric_limits<Int>::min()));
  return stdx::none_of(defects != I(0));
}

/// A screen over lanes of T with no compares and no floating-point chain
/// across iterations: the bits of the values are OR-ed into integer lanes
/// and tested once, in ok(). `finite` ors the bits of x * 0, which is +-0
/// for finite x and NaN for inf or NaN; `nonnegative` ors the bits of
/// values that must be >= 0 (so -0.0, which the scan accepts, fails the
/// screen and is left to the scan).
template <class T>
struct Screen {
  using V = Lanes<T>;
  using I = BitLanes<V>;
  static constexpr std::size_t kLanes = V::size();
  I finite_bits = I(0);
  I sign = I(0);

  static V load(const T* x) { return detail::load<V>(x); }
  void finite(const V& v) { finite_bits |= bits(v * V(0)); }
  void nonnegative(const V& v) { sign |= bits(v); }
  [[nodiscard]] bool ok() const { return bits_ok(finite_bits, sign); }
};

/// Every x[i] finite, and >= 0 when `nonnegative`.
template <class T>
bool screen_values(const T* x, std::size_t n, bool nonnegative) {
  Screen<T> s;
  std::size_t i = 0;
  for (; i + Screen<T>::kLanes <= n; i += Screen<T>::kLanes) {
    const typename Screen<T>::V v = Screen<T>::load(x + i);
    s.finite(v);
    if (nonnegative) s.nonnegative(v);
  }
  bool ok = s.ok();
  for (; i < n; ++i) ok = ok && std::isfinite(x[i]) && (!nonnegative || x[i] >= T(0));
  return ok;
}

/// Every x[i] in [0, 1].
template <class T>
bool screen_unit_interval(const T* x, std::size_t n) {
  using V = typename Screen<T>::V;
  Screen<T> s;
  std::size_t i = 0;
  const V one(1);
  for (; i + Screen<T>::kLanes <= n; i += Screen<T>::kLanes) {
    const V v = Screen<T>::load(x + i);
    s.finite(v);
    s.nonnegative(v);
    s.nonnegative(one - v);
  }
  bool ok = s.ok();
  for (; i < n; ++i) ok = ok && x[i] >= T(0) && x[i] <= T(1);
  return ok;
}

/// The squared norm band the unit screens accept: 1 - 0.99e-3 <= |x| <= 1 +
/// 0.99e-3. The norm is summed in T; in float its rounding (< 4e-7 of the
/// sum) moves |x| by less than 2e-7, inside the 1e-5 between this band and
/// the scan's tolerance of 1e-3.
constexpr double kUnitScreenLow = (1 - 0.99 * kUnitTolerance) * (1 - 0.99 * kUnitTolerance);
constexpr double kUnitScreenHigh = (1 + 0.99 * kUnitTolerance) * (1 + 0.99 * kUnitTolerance);

/// The norm of (c[0][i], c[1][i], ...) within the unit band for every i.
template <class T, std::size_t K>
bool screen_unit(const std::array<const T*, K>& c, std::size_t n) {
  using V = typename Screen<T>::V;
  const V lo(static_cast<T>(kUnitScreenLow)), hi(static_cast<T>(kUnitScreenHigh));
  Screen<T> s;
  std::size_t i = 0;
  for (; i + Screen<T>::kLanes <= n; i += Screen<T>::kLanes) {
    V sum(0);
    for (const T* x : c) {
      const V v = Screen<T>::load(x + i);
      sum += v * v;
    }
    s.finite(sum);
    s.nonnegative(sum - lo);
    s.nonnegative(hi - sum);
  }
  bool ok = s.ok();
  for (; i < n; ++i) {
    double sum = 0;
    for (const T* x : c) sum += double(x[i]) * x[i];
    ok = ok && sum >= kUnitScreenLow && sum <= kUnitScreenHigh;
  }
  return ok;
}

/// quaternion_normalisable for every i: |q|^2 summed in T in the kernels'
/// order ((w^2 + x^2) + y^2) + z^2, finite and at least the smallest normal.
template <class T>
bool screen_quaternion(const std::array<const T*, 4>& q, std::size_t n) {
  using V = typename Screen<T>::V;
  const V smallest(std::numeric_limits<T>::min());
  Screen<T> s;
  std::size_t i = 0;
  for (; i + Screen<T>::kLanes <= n; i += Screen<T>::kLanes) {
    const V w = Screen<T>::load(q[0] + i), x = Screen<T>::load(q[1] + i);
    const V y = Screen<T>::load(q[2] + i), z = Screen<T>::load(q[3] + i);
    const V square = ((w * w + x * x) + y * y) + z * z;
    s.finite(square);
    s.nonnegative(square - smallest);
  }
  bool ok = s.ok();
  for (; i < n; ++i) ok = ok && quaternion_normalisable(q[0][i], q[1][i], q[2][i], q[3][i]);
  return ok;
}

// The index screen is the one check of every call (memory safety, even with
// check=False in the Python module): contact_indices.hpp's, shared with
// Schedule::build.
bool screen_indices(const BodyIndex* a, const BodyIndex* b, std::size_t count, std::size_t body_count) {
  return detail::indices_below(a, b, count, detail::index_bound(body_count));
}

/// The body rules of validate_any's scan, screened over bodies [i0, i1) of
/// SoA views: one screen per array, and |q| for the rigid model.
template <class T>
bool screen_soa(const std::vector<CheckedArray<T>>& fields, std::size_t i0, std::size_t i1) {
  for (const CheckedArray<T>& f : fields) {
    if (!screen_values(f.data + i0, i1 - i0, f.inverse)) return false;
  }
  return true;
}
template <class T>
bool screen_bodies(const BodyView<T>& b, const std::vector<CheckedArray<T>>& fields, std::size_t i0, std::size_t i1) {
  return screen_soa(fields, i0, i1) && screen_quaternion<T>({b.q.w + i0, b.q.x + i0, b.q.y + i0, b.q.z + i0}, i1 - i0);
}
template <class T>
bool screen_bodies(const SphereView<T>&, const std::vector<CheckedArray<T>>& fields, std::size_t i0, std::size_t i1) {
  return screen_soa(fields, i0, i1);
}
template <class T>
bool screen_bodies(const ParticleView<T>&, const std::vector<CheckedArray<T>>& fields, std::size_t i0, std::size_t i1) {
  return screen_soa(fields, i0, i1);
}

/// Packed records [i0, i1) screened as one run of lanes: a record is a
/// whole number of lane vectors, so vector j of every record holds the same
/// fields, and per-position masks pick the values of the fields (the padding
/// is never read by the kernels and may hold anything) and those that must
/// be >= 0. The vectors are the screens' lanes, narrowed to a divisor of the
/// record should this file be built for wider ones.
template <class Record>
bool screen_records(const PackedView<Record>& b,
                    const std::vector<CheckedArray<typename PackedValue<Record>::type>>& fields, std::size_t i0,
                    std::size_t i1) {
  using T = typename PackedValue<Record>::type;
  using S = Screen<T>;
  constexpr std::size_t kValues = sizeof(Record) / sizeof(T);
  constexpr std::size_t kLanes = std::gcd(S::kLanes, kValues);
  using V = stdx::simd<T, stdx::simd_abi::deduce_t<T, kLanes>>;
  using I = BitLanes<V>;
  constexpr std::size_t kVectors = kValues / kLanes;
  static_assert(sizeof(Record) == kValues * sizeof(T), "a record holds values of T only");
  if (i0 == i1) return true;
  std::array<I, kVectors> used;
  std::array<I, kVectors> inverse;
  used.fill(I(0));
  inverse.fill(I(0));
  const T* base = &b.bodies[0].v[0];
  for (const CheckedArray<T>& f : fields) {
    if (f.stride != kValues) continue;  // not in the record (a rigid view's inv_mass)
    const auto at = static_cast<std::size_t>(f.data - base);
    used[at / kLanes][at % kLanes] = -1;
    if (f.inverse) inverse[at / kLanes][at % kLanes] = -1;
  }
  I finite_bits(0), sign(0);
  for (std::size_t i = i0; i < i1; ++i) {
    const T* r = &b.bodies[i].v[0];
    for (std::size_t j = 0; j < kVectors; ++j) {
      const V v = detail::load<V>(r + j * kLanes);
      finite_bits |= bits(v * V(0)) & used[j];
      sign |= bits(v) & inverse[j];
    }
  }
  return bits_ok(finite_bits, sign);
}
template <class T>
bool screen_bodies(const PackedView<PackedRigid<T>>& b, const std::vector<CheckedArray<T>>& fields, std::size_t i0,
                   std::size_t i1) {
  if (!screen_records(b, fields, i0, i1)) return false;
  if (!screen_values(b.inv_mass + i0, i1 - i0, true)) return false;
  std::uint64_t bad = 0;
  for (std::size_t i = i0; i < i1; ++i) {
    const T* q = b.bodies[i].q;
    bad |= static_cast<std::uint64_t>(!quaternion_normalisable(q[0], q[1], q[2], q[3]));
  }
  return bad == 0;
}
template <class T>
bool screen_bodies(const PackedView<PackedSphere<T>>& b, const std::vector<CheckedArray<T>>& fields, std::size_t i0,
                   std::size_t i1) {
  return screen_records(b, fields, i0, i1);
}
template <class T>
bool screen_bodies(const PackedView<PackedParticle<T>>& b, const std::vector<CheckedArray<T>>& fields, std::size_t i0,
                   std::size_t i1) {
  return screen_records(b, fields, i0, i1);
}

/// The contact rules of validate_any's scan, screened over contacts [k0, k1).
template <class T>
bool screen_contacts(const ContactView<T>& c, std::size_t body_count, std::size_t k0, std::size_t k1) {
  const std::size_t m = k1 - k0;
  if (!screen_indices(c.a + k0, c.b + k0, m, body_count)) return false;
  for (const T* x : {c.c.x, c.c.y, c.c.z, c.n.x, c.n.y, c.n.z}) {
    if (x != nullptr && !screen_values(x + k0, m, false)) return false;
  }
  if (!screen_unit<T, 3>({c.n.x + k0, c.n.y + k0, c.n.z + k0}, m)) return false;
  if (c.e != nullptr && !screen_unit_interval(c.e + k0, m)) return false;
  return c.mu == nullptr || screen_values(c.mu + k0, m, true);
}

// ---------------------------------------------------------------------------
// Shared memory: the arrays of a solve as bytes, for validate_disjoint.
// ---------------------------------------------------------------------------

/// The arrays of one solve's views: at most 17 of the bodies, 10 of the
/// contacts and 3 of the impulses.
struct SolveArrays {
  std::array<ArrayBytes, 32> list{};
  std::size_t size = 0;
  void add(const char* owner, const char* name, const void* data, std::size_t bytes, bool written) {
    list[size++] = {owner, name, data, bytes, written};
  }
};

/// The arrays of SoA bodies: each with its role (the velocities are written).
template <class View>
void add_bodies(SolveArrays& arrays, const View& b) {
  for_each_array(b, [&](const char* name, const auto* data, ArrayRole role) {
    arrays.add("bodies", name, data, b.count * sizeof(*data), role == ArrayRole::velocity);
  });
}
/// Packed records are written whole; rigid records' inverse masses are read.
template <class T>
void add_bodies(SolveArrays& arrays, const PackedView<PackedRigid<T>>& b) {
  arrays.add("bodies", "records", b.bodies, b.count * sizeof(PackedRigid<T>), true);
  arrays.add("bodies", "inv_mass", b.inv_mass, b.count * sizeof(T), false);
}
template <class Record>
void add_bodies(SolveArrays& arrays, const PackedView<Record>& b) {
  arrays.add("bodies", "records", b.bodies, b.count * sizeof(Record), true);
}

template <class T, class View>
Validation check_disjoint(const View& bodies, const ContactView<T>& c, const ImpulseView<T>& j) {
  SolveArrays arrays;
  add_bodies(arrays, bodies);
  const std::size_t m = c.count;
  arrays.add("contacts", "a", c.a, m * sizeof(BodyIndex), false);
  arrays.add("contacts", "b", c.b, m * sizeof(BodyIndex), false);
  const std::pair<const char*, const T*> values[] = {{"c.x", c.c.x}, {"c.y", c.c.y}, {"c.z", c.c.z}, {"n.x", c.n.x},
                                                     {"n.y", c.n.y}, {"n.z", c.n.z}, {"e", c.e},     {"mu", c.mu}};
  for (const auto& [name, data] : values) arrays.add("contacts", name, data, m * sizeof(T), false);
  arrays.add("impulses", "j.x", j.j.x, j.count * sizeof(T), true);
  arrays.add("impulses", "j.y", j.j.y, j.count * sizeof(T), true);
  arrays.add("impulses", "j.z", j.j.z, j.count * sizeof(T), true);
  return validate_disjoint(arrays.list.data(), arrays.size);
}

}  // namespace

Validation validate_disjoint(const ArrayBytes* arrays, std::size_t count) {
  const auto named = [](const ArrayBytes& x) { return std::string(x.owner) + "." + x.name; };
  for (std::size_t i = 0; i < count; ++i) {
    const ArrayBytes& x = arrays[i];
    if (x.data == nullptr || x.bytes == 0) continue;
    const auto x0 = reinterpret_cast<std::uintptr_t>(x.data);
    for (std::size_t k = i + 1; k < count; ++k) {
      const ArrayBytes& y = arrays[k];
      if ((!x.written && !y.written) || y.data == nullptr || y.bytes == 0) continue;
      const auto y0 = reinterpret_cast<std::uintptr_t>(y.data);
      if (x0 < y0 + y.bytes && y0 < x0 + x.bytes) {
        const std::string how = x.written && y.written ? "the solve writes both"
                                : x.written            ? "the solve writes " + named(x) + " while it reads " + named(y)
                                                       : "the solve writes " + named(y) + " while it reads " + named(x);
        return fail_text(named(x) + " and " + named(y) + " share memory: " + how);
      }
    }
  }
  return {};
}

template <class T>
bool contacts_pass_screen(const ContactView<T>& contacts, std::size_t body_count) {
  return detail::screen_chunks(
      contacts.count, [&](std::size_t k0, std::size_t k1) { return screen_contacts(contacts, body_count, k0, k1); });
}
template bool contacts_pass_screen<float>(const ContactView<float>&, std::size_t);
template bool contacts_pass_screen<double>(const ContactView<double>&, std::size_t);

template <class T, class View>
Validation validate_any(const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                        bool needs_contact_point) {
  if (impulses.count != contacts.count) {
    return fail_text("impulses.count = " + std::to_string(impulses.count) +
                     " but contacts.count = " + std::to_string(contacts.count));
  }
  const std::vector<CheckedArray<T>> fields = fields_of(bodies);
  if (bodies.count > 0) {
    for (const CheckedArray<T>& f : fields) {
      if (f.data == nullptr) {
        return fail_text(std::string("bodies.") + f.name +
                         " is null but bodies.count = " + std::to_string(bodies.count));
      }
    }
  }
  if (contacts.count > 0) {
    const bool no_point = !contacts.c.x || !contacts.c.y || !contacts.c.z;
    if (!contacts.a || !contacts.b || (needs_contact_point && no_point) || !contacts.n.x || !contacts.n.y ||
        !contacts.n.z) {
      return fail_text("contacts: an array is null but contacts.count = " + std::to_string(contacts.count));
    }
    if (!impulses.j.x || !impulses.j.y || !impulses.j.z) {
      return fail_text("impulses: an array is null but impulses.count = " + std::to_string(impulses.count));
    }
  }

  if (Validation v = check_disjoint<T>(bodies, contacts, impulses); !v) return v;

  const bool uniform_e_ok = contacts.e != nullptr || (contacts.uniform_e >= T(0) && contacts.uniform_e <= T(1));
  if (uniform_e_ok &&
      detail::screen_chunks(bodies.count,
                            [&](std::size_t i0, std::size_t i1) { return screen_bodies(bodies, fields, i0, i1); }) &&
      detail::screen_chunks(contacts.count, [&](std::size_t k0, std::size_t k1) {
        return screen_contacts(contacts, bodies.count, k0, k1);
      })) {
    return {};
  }

  for (std::size_t i = 0; i < bodies.count; ++i) {
    for (const CheckedArray<T>& f : fields) {
      const T x = f[i];
      if (f.inverse && (!std::isfinite(x) || x < T(0))) return fail("bodies", f.name, i, x, "must be finite and >= 0");
      if (!f.inverse && !std::isfinite(x)) return fail("bodies", f.name, i, x, "must be finite");
    }
    if (Validation v = check_orientation(bodies, i); !v) return v;
  }

  for (std::size_t k = 0; k < contacts.count; ++k) {
    if (detail::first_bad_contact(contacts.a, contacts.b, k, k + 1, bodies.count) == k) {
      return fail_text(detail::bad_contact_message(contacts.a, contacts.b, k, bodies.count));
    }
    const std::pair<const char*, const T*> finite[] = {{"c.x", contacts.c.x}, {"c.y", contacts.c.y},
                                                       {"c.z", contacts.c.z}, {"n.x", contacts.n.x},
                                                       {"n.y", contacts.n.y}, {"n.z", contacts.n.z}};
    for (const auto& [name, a] : finite) {
      if (a != nullptr && !std::isfinite(a[k])) return fail("contacts", name, k, a[k], "must be finite");
    }
    const T n[3] = {contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]};
    const double nn = length_in_double(n, 3);
    if (!unit_length_ok(nn)) {
      std::ostringstream s;
      s.precision(9);
      s << "contact " << k << ": normal length " << nn << " is not 1 within 1e-3";
      return fail_text(s.str());
    }
    if (contacts.e && !(contacts.e[k] >= T(0) && contacts.e[k] <= T(1))) {
      return fail("contacts", "e", k, contacts.e[k], "must be in [0, 1]");
    }
    if (contacts.mu && !(std::isfinite(contacts.mu[k]) && contacts.mu[k] >= T(0))) {
      return fail("contacts", "mu", k, contacts.mu[k], "must be finite and >= 0");
    }
  }
  if (!contacts.e && !(contacts.uniform_e >= T(0) && contacts.uniform_e <= T(1))) {
    std::ostringstream s;  // one value for every contact: no element index
    s.precision(9);
    s << "contacts.uniform_e = " << contacts.uniform_e << ": must be in [0, 1]";
    return fail_text(s.str());
  }
  return {};
}

template <class T>
Validation validate(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, false);
}

template <class T>
Validation validate(const PackedView<PackedRigid<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const PackedView<PackedSphere<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, true);
}
template <class T>
Validation validate(const PackedView<PackedParticle<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses) {
  return validate_any<T>(bodies, contacts, impulses, false);
}

Validation validate_indices(const BodyIndex* a, const BodyIndex* b, std::size_t count, std::size_t body_count) {
  if (detail::screen_chunks(
          count, [&](std::size_t k0, std::size_t k1) { return screen_indices(a + k0, b + k0, k1 - k0, body_count); })) {
    return {};
  }
  const std::size_t k = detail::first_bad_contact(a, b, 0, count, body_count);
  if (k == count) return {};
  return fail_text(detail::bad_contact_message(a, b, k, body_count));
}

// Written out (clang-tidy: no macros over types).
template <class T>
bool warm_start_accepted(const T (&j)[3], const T (&n)[3]) {
  const auto length = [](const T(&x)[3]) {
    return std::sqrt(double(x[0]) * double(x[0]) + double(x[1]) * double(x[1]) + double(x[2]) * double(x[2]));
  };
  if (!(std::isfinite(j[0]) && std::isfinite(j[1]) && std::isfinite(j[2]))) return false;
  const double along = double(j[0]) * double(n[0]) + double(j[1]) * double(n[1]) + double(j[2]) * double(n[2]);
  return along >= kWarmStartLeastCosine * length(j) * length(n);
}

namespace {
template <class T>
void warm_start_at(const ContactView<T>& contacts, const ImpulseView<const T>& warm, std::size_t k, T (&j)[3],
                   T (&n)[3]) {
  j[0] = warm.j.x[k];
  j[1] = warm.j.y[k];
  j[2] = warm.j.z[k];
  n[0] = contacts.n.x[k];
  n[1] = contacts.n.y[k];
  n[2] = contacts.n.z[k];
}
}  // namespace

template <class T>
std::size_t first_refused_warm_start(const ContactView<T>& contacts, const ImpulseView<const T>& warm) {
  for (std::size_t k = 0; k < contacts.count; ++k) {
    T j[3], n[3];
    warm_start_at(contacts, warm, k, j, n);
    if (!warm_start_accepted(j, n)) return k;
  }
  return contacts.count;
}

template <class T>
std::string warm_start_refusal(const ContactView<T>& contacts, const ImpulseView<const T>& warm, std::size_t k) {
  T j[3], n[3];
  warm_start_at(contacts, warm, k, j, n);
  if (!(std::isfinite(j[0]) && std::isfinite(j[1]) && std::isfinite(j[2]))) return "is not finite";
  const double along = double(j[0]) * double(n[0]) + double(j[1]) * double(n[1]) + double(j[2]) * double(n[2]);
  std::ostringstream text;
  const double size =
      std::sqrt(double(j[0]) * double(j[0]) + double(j[1]) * double(j[1]) + double(j[2]) * double(j[2])) *
      std::sqrt(double(n[0]) * double(n[0]) + double(n[1]) * double(n[1]) + double(n[2]) * double(n[2]));
  text << std::setprecision(std::numeric_limits<T>::max_digits10) << "points against the normal (J . n = " << along
       << ", below " << kWarmStartLeastCosine << " |J| |n| = " << kWarmStartLeastCosine * size
       << "): a normal impulse never pulls the bodies together";
  return text.str();
}

template bool warm_start_accepted<float>(const float (&)[3], const float (&)[3]);
template bool warm_start_accepted<double>(const double (&)[3], const double (&)[3]);
template std::size_t first_refused_warm_start<float>(const ContactView<float>&, const ImpulseView<const float>&);
template std::size_t first_refused_warm_start<double>(const ContactView<double>&, const ImpulseView<const double>&);
template std::string warm_start_refusal<float>(const ContactView<float>&, const ImpulseView<const float>&, std::size_t);
template std::string warm_start_refusal<double>(const ContactView<double>&, const ImpulseView<const double>&,
                                                std::size_t);

template Validation validate<float>(const BodyView<float>&, const ContactView<float>&, const ImpulseView<float>&);
template Validation validate<float>(const SphereView<float>&, const ContactView<float>&, const ImpulseView<float>&);
template Validation validate<float>(const ParticleView<float>&, const ContactView<float>&, const ImpulseView<float>&);
template Validation validate<float>(const PackedView<PackedRigid<float>>&, const ContactView<float>&,
                                    const ImpulseView<float>&);
template Validation validate<float>(const PackedView<PackedSphere<float>>&, const ContactView<float>&,
                                    const ImpulseView<float>&);
template Validation validate<float>(const PackedView<PackedParticle<float>>&, const ContactView<float>&,
                                    const ImpulseView<float>&);
template Validation validate<double>(const BodyView<double>&, const ContactView<double>&, const ImpulseView<double>&);
template Validation validate<double>(const SphereView<double>&, const ContactView<double>&, const ImpulseView<double>&);
template Validation validate<double>(const ParticleView<double>&, const ContactView<double>&,
                                     const ImpulseView<double>&);
template Validation validate<double>(const PackedView<PackedRigid<double>>&, const ContactView<double>&,
                                     const ImpulseView<double>&);
template Validation validate<double>(const PackedView<PackedSphere<double>>&, const ContactView<double>&,
                                     const ImpulseView<double>&);
template Validation validate<double>(const PackedView<PackedParticle<double>>&, const ContactView<double>&,
                                     const ImpulseView<double>&);

}  // namespace collide
