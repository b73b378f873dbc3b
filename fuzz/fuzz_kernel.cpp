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
// w) and per contact two index bytes and 8 values (c, n, e, mu). Values are
// read as fuzz_scene.hpp says.
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
#include "fuzz_scene.hpp"

namespace {

using namespace collide;
using fuzz::Arrays;
using fuzz::fail;
using fuzz::RawScene;

RawScene decode(const std::uint8_t* data, std::size_t size) {
  fuzz::Reader in(data, size);
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
      fuzz::normalise(&b[4], 4);
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
      fuzz::normalise(&c[3], 3);
      c[6] = std::isfinite(c[6]) ? std::fmod(std::abs(c[6]), 1.0) : 0.5;
      c[7] = std::isfinite(c[7]) ? std::abs(c[7]) : 0.5;
    }
    s.contact.push_back(c);
  }
  return s;
}

/// One solver per path and thread count (blocks of 8 contacts, so a batch of
/// 16 or more splits across threads).
const Solver& solver(Path path, int threads) {
  SolverOptions o;
  o.path = path;
  o.threads = threads;
  o.block = 8;
  return fuzz::cached_solver(o);
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
  const bool finite_promised = fuzz::moderate(raw);
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
