// fuzz_kernel.cpp - libFuzzer target: the kernel API on scenes made of
// arbitrary bytes.
//
// The bytes become a scene of up to 63 bodies and 64 contacts (layout
// below), written straight into caller-owned arrays as an embedding program
// would, in float and in double. Then:
// * validate() must accept or reject it without crashing, and a rejection
//   must say what is wrong (non-empty message);
// * an accepted scene is scheduled and solved with the cheapest model that
//   fits and with the rigid model, on the scalar and the SIMD path, with 1
//   and 2 threads (blocks of 8 contacts, so a batch of 16 or more splits
//   across threads). For each model the four runs must give identical bytes
//   (impulses, v and w); immovable bodies must come out untouched; a contact
//   between two immovable bodies must have J = 0;
// * when every input is moderate (|x| <= 1e4, inverse mass and moments 0 or
//   in [1e-4, 1e4]) no impulse or velocity may be NaN or inf. Outside that
//   range valid finite input may legitimately overflow, so nothing is
//   claimed there.
// Crashes, UB (UBSan), memory errors and leaks (ASan) and hangs (-timeout)
// are libFuzzer failures. The kernel's debug asserts are on in this build.
//
// Layout: byte 0 flags (bit 0: tidy - masses, moments, mu made >= 0, q and n
// normalised, e folded into [0, 1], so that most inputs are valid; bit 1:
// one uniform e; bit 2: frictionless), byte 1 body count, byte 2 contact
// count, then per body 17 values (inverse mass, 3 inverse moments, q, p, v,
// w) and per contact two index bytes and 8 values (c, n, e, mu). A value is
// two bytes: a fixed-point number in [-512, 512) or, for the top 8 of 256
// high bytes, one of a table of hard values (0, -0, subnormals, 1e38, inf,
// NaN, ...). Missing bytes read as 0.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"

namespace {

using namespace collide;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_kernel: %s\n", what);
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
                                   0.9999};
    return kHard[lo % (sizeof kHard / sizeof kHard[0])];
  }

 private:
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

/// The scene as decoded, in double; converted to T per run.
struct RawScene {
  bool uniform_e = false, frictionless = false;
  double e = 1;
  std::size_t bodies = 0, contacts = 0;
  std::vector<std::array<double, 17>> body;  // inv_mass, inv I (3), q (4), p, v, w
  std::vector<std::array<std::uint32_t, 2>> index;
  std::vector<std::array<double, 8>> contact;  // c (3), n (3), e, mu
};

void normalise(double* x, int n) {
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

RawScene decode(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  RawScene s;
  const std::uint8_t flags = in.byte();
  const bool tidy = flags & 1;
  s.uniform_e = flags & 2;
  s.frictionless = flags & 4;
  s.bodies = 2 + in.byte() % 62;
  s.contacts = in.byte() % 65;
  s.e = in.value();
  if (tidy) s.e = std::isfinite(s.e) ? std::fmod(std::abs(s.e), 1.0) : 0.5;
  s.body.resize(s.bodies);
  for (auto& b : s.body) {
    for (double& x : b) x = in.value();
    if (tidy) {
      for (int i = 0; i < 4; ++i) b[i] = std::abs(b[i]);
      normalise(&b[4], 4);
    }
  }
  for (std::size_t k = 0; k < s.contacts; ++k) {
    // One past the last body is possible: an out-of-range index.
    const auto a = static_cast<std::uint32_t>(in.byte() % (s.bodies + 1));
    const auto b = static_cast<std::uint32_t>(in.byte() % (s.bodies + 1));
    s.index.push_back({a, b});
    std::array<double, 8> c{};
    for (double& x : c) x = in.value();
    if (tidy) {
      normalise(&c[3], 3);
      c[6] = std::isfinite(c[6]) ? std::fmod(std::abs(c[6]), 1.0) : 0.5;
      c[7] = std::isfinite(c[7]) ? std::abs(c[7]) : 0.5;
    }
    s.contact.push_back(c);
  }
  return s;
}

bool moderate(const RawScene& s) {
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

/// One solver per path and thread count, kept across inputs (a Solver owns
/// a task arena; making one per input would dominate the run).
const Solver& solver(Path path, int threads) {
  auto make = [](Path p, int t) {
    SolverOptions o;
    o.path = p;
    o.threads = t;
    o.block = 8;
    return o;
  };
  static const Solver scalar1(make(Path::scalar, 1)), scalar2(make(Path::scalar, 2)), simd1(make(Path::simd, 1)),
      simd2(make(Path::simd, 2));
  if (path == Path::scalar) return threads == 1 ? scalar1 : scalar2;
  return threads == 1 ? simd1 : simd2;
}

template <class T>
void run(const RawScene& raw) {
  Arrays<T> start(raw);
  const BodyView<T> bodies = start.bodies();
  const ContactView<T> contacts = start.contacts(raw);
  const Validation ok = validate(bodies, contacts, start.impulses());
  if (!ok) {
    if (ok.message.empty()) fail("validate() rejected a scene without saying why");
    return;
  }
  Schedule schedule;
  schedule.build(contacts, bodies);
  const Model cheapest = choose_model(bodies, contacts);
  const bool finite_promised = moderate(raw);
  for (const Model model : {cheapest, Model::rigid}) {
    if (!model_misfit(model, bodies, contacts).empty()) fail("choose_model() chose a model that does not fit");
    Arrays<T> first(raw);
    bool have_first = false;
    for (const Path path : {Path::scalar, Path::simd}) {
      for (const int threads : {1, 2}) {
        Arrays<T> out(raw);
        solver(path, threads).solve(model, out.bodies(), out.contacts(raw), out.impulses(), schedule);
        if (!have_first) {
          first = out;
          have_first = true;
        } else {
          for (std::size_t f = 11; f < 17; ++f) {
            if (std::memcmp(out.body[f].data(), first.body[f].data(), sizeof(T) * raw.bodies) != 0) {
              fail("velocities differ between paths or thread counts");
            }
          }
          for (std::size_t f = 0; f < 3 && raw.contacts > 0; ++f) {
            if (std::memcmp(out.j[f].data(), first.j[f].data(), sizeof(T) * raw.contacts) != 0) {
              fail("impulses differ between paths or thread counts");
            }
          }
        }
      }
    }
    for (std::size_t i = 0; i < raw.bodies; ++i) {
      const bool immovable = start.body[0][i] == T(0);
      for (std::size_t f = 11; f < 17; ++f) {
        const T x = first.body[f][i];
        if (immovable && std::memcmp(&x, &start.body[f][i], sizeof(T)) != 0) fail("an immovable body was written");
        if (finite_promised && !std::isfinite(x)) fail("a non-finite velocity from moderate input");
      }
    }
    for (std::size_t k = 0; k < raw.contacts; ++k) {
      const bool both_immovable = start.body[0][start.a[k]] == T(0) && start.body[0][start.b[k]] == T(0);
      for (std::size_t f = 0; f < 3; ++f) {
        const T x = first.j[f][k];
        if (both_immovable && x != T(0)) fail("an impulse between two immovable bodies");
        if (finite_promised && !std::isfinite(x)) fail("a non-finite impulse from moderate input");
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const RawScene raw = decode(data, size);
  run<float>(raw);
  run<double>(raw);
  return 0;
}
