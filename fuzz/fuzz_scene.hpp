// fuzz_scene.hpp - what the kernel fuzz targets share: reading values from the
// fuzz bytes, a decoded scene, caller-owned arrays in T and the views on
// them, and solvers kept across inputs.
//
// A value is two bytes: a fixed-point number in [-512, 512) or, for the top
// 8 of 256 high bytes, one of a table of hard values (0, -0, subnormals,
// 1e-30, 1e30, FLT_MAX, DBL_MAX, +-inf, NaN, ...). Missing bytes read as 0.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/solve.hpp"

namespace collide::fuzz {

/// Stops the run with a message: libFuzzer keeps the input as a crash.
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz: %s\n", what.c_str());
  std::abort();
}

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : p_(data), end_(data + size) {}
  std::uint8_t byte() { return p_ < end_ ? *p_++ : 0; }
  double value() {
    const std::uint8_t hi = byte(), lo = byte();
    if (hi < 248) return static_cast<std::int16_t>(static_cast<std::uint16_t>(hi << 8 | lo)) / 64.0;
    static const double kHard[] = {0.0,
                                   -0.0,
                                   1e-45,
                                   -1.4e-45,
                                   1e-39,
                                   1e-30,
                                   1e-20,
                                   1e20,
                                   1e30,
                                   3.4e38,
                                   1e39,
                                   1e300,
                                   4.9e-324,
                                   std::numeric_limits<double>::max(),
                                   std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::quiet_NaN(),
                                   1.0 + 1e-5,
                                   0.9999,
                                   double{std::numeric_limits<float>::max()},
                                   -1e30,
                                   -double{std::numeric_limits<float>::max()}};
    return kHard[lo % (sizeof kHard / sizeof kHard[0])];
  }

 private:
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

/// x[0 .. n) scaled to unit length; (1, 0, ...) when that is not possible.
inline void normalise(double* x, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += x[i] * x[i];
  s = std::sqrt(s);
  if (!(s > 1e-3) || !std::isfinite(s)) {
    x[0] = 1;
    for (int i = 1; i < n; ++i) x[i] = 0;
    return;
  }
  for (int i = 0; i < n; ++i) x[i] /= s;
}

/// The scene as decoded, in double; converted to T per run.
struct RawScene {
  bool uniform_e = false, frictionless = false;
  double e = 1;
  std::size_t bodies = 0, contacts = 0;
  std::vector<std::array<double, 17>> body;  // inv_mass, inv I (3), q (4), p, v, w
  std::vector<std::array<std::uint32_t, 2>> index;
  std::vector<std::array<double, 8>> contact;  // c (3), n (3), e, mu
};

/// Every input moderate: |x| <= 1e4, inverse mass and moments 0 or in
/// [1e-4, 1e4]. Valid scenes of moderate values give finite results.
inline bool moderate(const RawScene& s) {
  for (const auto& b : s.body) {
    for (int i = 0; i < 4; ++i) {
      if (b[i] != 0 && !(b[i] >= 1e-4 && b[i] <= 1e4)) return false;
    }
    for (int i = 4; i < 17; ++i) {
      if (!(std::abs(b[i]) <= 1e4)) return false;
    }
  }
  for (const auto& c : s.contact) {
    for (const double x : c) {
      if (!(std::abs(x) <= 1e4)) return false;
    }
  }
  return true;
}

/// Caller-owned structure-of-arrays storage in T, and the views on it.
template <class T>
struct Arrays {
  std::array<std::vector<T>, 17> body;
  std::vector<BodyIndex> a, b;
  std::array<std::vector<T>, 8> contact;
  std::array<std::vector<T>, 3> j;

  explicit Arrays(const RawScene& s) {
    for (std::size_t f = 0; f < 17; ++f) {
      for (const auto& x : s.body) body[f].push_back(static_cast<T>(x[f]));
    }
    for (std::size_t k = 0; k < s.contacts; ++k) {
      a.push_back(s.index[k][0]);
      b.push_back(s.index[k][1]);
      for (std::size_t f = 0; f < 8; ++f) contact[f].push_back(static_cast<T>(s.contact[k][f]));
    }
    for (auto& x : j) x.assign(s.contacts, T(7));  // overwritten by every solve
  }
  BodyView<T> bodies() {
    auto* f = body.data();
    return {f[0].size(),
            f[0].data(),
            {f[1].data(), f[2].data(), f[3].data()},
            {f[4].data(), f[5].data(), f[6].data(), f[7].data()},
            {f[8].data(), f[9].data(), f[10].data()},
            {f[11].data(), f[12].data(), f[13].data()},
            {f[14].data(), f[15].data(), f[16].data()}};
  }
  ContactView<T> contacts(const RawScene& s) const {
    ContactView<T> v;
    v.count = a.size();
    v.a = a.data();
    v.b = b.data();
    v.c = {contact[0].data(), contact[1].data(), contact[2].data()};
    v.n = {contact[3].data(), contact[4].data(), contact[5].data()};
    v.e = s.uniform_e ? nullptr : contact[6].data();
    v.uniform_e = static_cast<T>(s.e);
    v.mu = s.frictionless ? nullptr : contact[7].data();
    return v;
  }
  ImpulseView<T> impulses() { return {j[0].size(), {j[0].data(), j[1].data(), j[2].data()}}; }
};

/// A solver per set of options, kept across inputs (a Solver owns a task
/// arena; making one per input would dominate the run).
inline const Solver& cached_solver(const SolverOptions& o) {
  using Key = std::tuple<Path, int, std::size_t, Accuracy, BodyLayout>;
  static std::map<Key, std::unique_ptr<Solver>> solvers;
  std::unique_ptr<Solver>& s = solvers[Key{o.path, o.threads, o.block, o.accuracy, o.layout}];
  if (!s) s = std::make_unique<Solver>(o);
  return *s;
}

}  // namespace collide::fuzz
