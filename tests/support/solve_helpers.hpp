// tests/support/solve_helpers.hpp - running the kernel and the reference on a
// scene, and comparing results bit for bit.
#pragma once

#include <array>
#include <cstddef>
#include <cstring>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/eval/reference.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"

namespace collide::test {

/// Builds a schedule in `order` and runs one Solver with `options` on the
/// bodies in place.
template <class T>
ImpulseBuffer<T> kernel_solve(BodyBuffer<T>& bodies, const ContactView<T>& contacts, const SolverOptions& options,
                              Order order = Order::input) {
  ImpulseBuffer<T> j(contacts.count);
  Schedule schedule(order);
  schedule.build(contacts, bodies.view());
  Solver(options).solve(bodies.view(), contacts, j.view(), schedule);
  return j;
}

inline SolverOptions options_for(Path path, int threads = 1, std::size_t block = 4096) {
  SolverOptions o;
  o.path = path;
  o.threads = threads;
  o.block = block;
  return o;
}

/// The world-frame reference, in input order, on the bodies in place.
template <class S>
ImpulseBuffer<S> reference(BodyBuffer<S>& bodies, const ContactView<S>& contacts,
                           std::vector<ReferenceContact<S>>* diagnostics = nullptr) {
  ImpulseBuffer<S> j(contacts.count);
  if (diagnostics) diagnostics->assign(contacts.count, ReferenceContact<S>{});
  reference_solve<S>(bodies.view(), contacts, j.view(), diagnostics ? diagnostics->data() : nullptr);
  return j;
}

/// The 17 arrays of a body view, in a fixed order, with their names.
inline const char* const kBodyFieldNames[17] = {"inv_mass", "inv_Ix", "inv_Iy", "inv_Iz", "qw", "qx", "qy", "qz", "px",
                                                "py",       "pz",     "vx",     "vy",     "vz", "wx", "wy", "wz"};

template <class T>
std::array<const T*, 17> body_arrays(const BodyView<const T>& v) {
  return {v.inv_mass, v.inv_inertia.x, v.inv_inertia.y, v.inv_inertia.z, v.q.w, v.q.x, v.q.y, v.q.z, v.p.x,
          v.p.y,      v.p.z,           v.v.x,           v.v.y,           v.v.z, v.w.x, v.w.y, v.w.z};
}

template <class T>
bool same_bits(const T& x, const T& y) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "bitwise comparison of padded types");
  return std::memcmp(&x, &y, sizeof(T)) == 0;  // NOLINT(bugprone-suspicious-memory-comparison): the bits, on purpose
}

/// Every field of every body identical bit for bit, except bodies for which
/// `skip(i)` is true.
template <class T>
::testing::AssertionResult same_bodies(const BodyBuffer<T>& x, const BodyBuffer<T>& y,
                                       const std::function<bool(std::size_t)>& skip = nullptr) {
  if (x.size() != y.size()) return ::testing::AssertionFailure() << "body counts differ";
  const auto ax = body_arrays<T>(x.view());
  const auto ay = body_arrays<T>(y.view());
  std::size_t mismatches = 0;
  std::ostringstream first;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (skip && skip(i)) continue;
    for (std::size_t f = 0; f < 17; ++f) {
      if (!same_bits(ax[f][i], ay[f][i])) {
        if (mismatches++ == 0) {
          first.precision(std::numeric_limits<T>::max_digits10);
          first << "body " << i << " field " << kBodyFieldNames[f] << ": " << ax[f][i] << " vs " << ay[f][i];
        }
      }
    }
  }
  if (mismatches == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << mismatches << " body values differ; first: " << first.str();
}

/// Every impulse identical bit for bit, except contacts for which `skip(k)`.
template <class T>
::testing::AssertionResult same_impulses(const ImpulseBuffer<T>& x, const ImpulseBuffer<T>& y,
                                         const std::function<bool(std::size_t)>& skip = nullptr) {
  if (x.size() != y.size()) return ::testing::AssertionFailure() << "impulse counts differ";
  const auto vx = x.view();
  const auto vy = y.view();
  const T* ax[3] = {vx.j.x, vx.j.y, vx.j.z};
  const T* ay[3] = {vy.j.x, vy.j.y, vy.j.z};
  std::size_t mismatches = 0;
  std::ostringstream first;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (skip && skip(k)) continue;
    for (int c = 0; c < 3; ++c) {
      if (!same_bits(ax[c][k], ay[c][k])) {
        if (mismatches++ == 0) {
          first.precision(std::numeric_limits<T>::max_digits10);
          first << "contact " << k << " component " << c << ": " << ax[c][k] << " vs " << ay[c][k];
        }
      }
    }
  }
  if (mismatches == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << mismatches << " impulse values differ; first: " << first.str();
}

/// Type name for traces.
template <class T>
const char* type_name() {
  if constexpr (std::is_same_v<T, float>) return "float";
  if constexpr (std::is_same_v<T, double>) return "double";
  return "long double";
}

}  // namespace collide::test
