// test_lane_isolation.cpp - a contact whose lane holds NaN, inf or subnormal
// values does not change the results of the other lanes (contact_kernel.hpp,
// solve.cpp).
//
// What this proves
// ----------------
// A scene is solved once clean; then one "victim" contact whose two bodies
// belong to no other contact is poisoned - NaN, +inf, -inf, the largest
// finite value, a subnormal or zero in one of its bodies' v, w, p, q or inverse
// mass / moments, or in its c, n, e or mu - and solved again. Every other
// contact's J and every other body's state must be bit for bit the same.
// The victim is placed at the first lane, a middle lane, the last lane of a
// SIMD group and in the scalar tail, in a pairs scene (contiguous loads) and
// in a shared-body scene (gathers), float and double, scalar and SIMD paths,
// on the SoA arrays and on the packed layout (records transposed into lanes),
// with and without friction (the friction block runs only when some lane
// slides, so a poisoned lane must not change what the others compute).
// For subnormal poisons, which are finite, the victim itself must also get
// identical bytes on the scalar and the SIMD path (no flush-to-zero in one of
// them); for NaN and inf the two paths must agree up to the NaN payload.
// (A zero inverse mass makes the victim immovable, which switches the SIMD
// path's pairs layout from an interleaved store to a masked scatter for the
// whole group: the neighbours must not notice.)
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/scene.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

enum class Field { va, wa, pa, qa, inv_mass_a, inv_inertia_a, vb, wb, pb, c, n, e, mu };
const char* name(Field f) {
  static const char* const names[] = {"va", "wa", "pa", "qa", "inv_mass_a", "inv_inertia_a", "vb", "wb",
                                      "pb", "c",  "n",  "e",  "mu"};
  return names[static_cast<int>(f)];
}

template <class T>
std::vector<std::pair<const char*, T>> poisons() {
  using L = std::numeric_limits<T>;
  return {{"zero", T(0)},  // inv_mass 0: the victim becomes immovable
          {"NaN", L::quiet_NaN()},
          {"+inf", L::infinity()},
          {"-inf", -L::infinity()},
          {"max", L::max()},
          {"denorm_min", L::denorm_min()},
          {"-denorm_min", -L::denorm_min()},
          {"largest subnormal", L::min() - L::denorm_min()}};
}

/// Writes `value` into component `comp` of `field` of the victim contact.
template <class T>
void poison(Scene<T>& s, std::size_t victim, Field field, int comp, T value) {
  const BodyView<T> b = s.bodies.view();
  ContactRecord<T> rec = s.contacts.record(victim);
  const std::size_t ia = rec.a, ib = rec.b;
  auto vec = [&](Vec3Array<T> v, std::size_t i) { (comp == 0 ? v.x : comp == 1 ? v.y : v.z)[i] = value; };
  switch (field) {
    case Field::va:
      vec(b.v, ia);
      break;
    case Field::wa:
      vec(b.w, ia);
      break;
    case Field::pa:
      vec(b.p, ia);
      break;
    case Field::qa:
      (comp == 0 ? b.q.w : comp == 1 ? b.q.x : b.q.z)[ia] = value;
      break;
    case Field::inv_mass_a:
      b.inv_mass[ia] = value;
      break;
    case Field::inv_inertia_a:
      vec(b.inv_inertia, ia);
      break;
    case Field::vb:
      vec(b.v, ib);
      break;
    case Field::wb:
      vec(b.w, ib);
      break;
    case Field::pb:
      vec(b.p, ib);
      break;
    case Field::c:
    case Field::n:
    case Field::e:
    case Field::mu: {
      // The contact buffer is written through set(), which renormalises n:
      // poke the stored values through the view's arrays instead.
      ContactView<T> v = s.contacts.view();
      T* target = nullptr;
      if (field == Field::c) target = const_cast<T*>(comp == 0 ? v.c.x : comp == 1 ? v.c.y : v.c.z);
      if (field == Field::n) target = const_cast<T*>(comp == 0 ? v.n.x : comp == 1 ? v.n.y : v.n.z);
      if (field == Field::e) target = const_cast<T*>(v.e);
      if (field == Field::mu) target = const_cast<T*>(v.mu);
      ASSERT_NE(target, nullptr);
      target[victim] = value;
      break;
    }
  }
}

template <class T>
bool same_or_both_nan(T x, T y) {
  return same_bits(x, y) || (std::isnan(x) && std::isnan(y));
}

struct Layout {
  bool shared;
  std::size_t victim;
};

template <class T>
void expect_isolated(bool friction) {
  const std::size_t W = simd_width<T>();
  SceneOptions o;
  o.seed = 31;
  o.friction = friction;
  // Pairs scene: 3 full groups and a tail of 3; victims in first, middle and
  // last lane of a group and in the tail.
  const std::size_t pairs = 3 * W + 3;
  // Shared scene: a fresh pair spliced into a shared-body scene (its bodies
  // appended, its contact inserted at `at`).
  auto shared_with_victim = [&](std::size_t at) {
    SceneRecords<T> r = shared_records<T>(200, 60, o);
    Rng rng(77);
    const auto base = static_cast<BodyIndex>(r.bodies.size());
    SceneRecords<T> pair = pairs_records<T>(1, SceneOptions{5, friction, -1, 5});
    r.bodies.push_back(pair.bodies[0]);
    r.bodies.push_back(pair.bodies[1]);
    ContactRecord<T> k = pair.contacts[0];
    k.a = base;
    k.b = base + 1;
    // Make sure the victim acts and, with friction, slides.
    if (friction) k.mu = T(0.5);
    r.contacts.insert(r.contacts.begin() + static_cast<std::ptrdiff_t>(at), k);
    return r.scene();
  };
  std::vector<Layout> layouts = {{false, 0}, {false, W / 2}, {false, W - 1}, {false, 3 * W + 1}};
  for (const std::size_t at : {std::size_t(0), std::size_t(77), std::size_t(200)}) layouts.push_back({true, at});

  const Solver scalar(options_for(Path::scalar, 1));
  const Solver simd(options_for(Path::simd, 1));
  // The packed layout (collide/packed.hpp): lanes filled by transposing
  // records, v and w written back with masked row stores.
  SolverOptions packed_options = options_for(Path::simd, 1);
  packed_options.layout = BodyLayout::packed;
  const Solver packed(packed_options);
  for (const Layout& layout : layouts) {
    const Scene<T> clean = layout.shared ? shared_with_victim(layout.victim) : pairs_scene<T>(pairs, o);
    const ContactRecord<T> vrec = clean.contacts.record(layout.victim);
    const auto skip_body = [&](std::size_t i) { return i == vrec.a || i == vrec.b; };
    const auto skip_contact = [&](std::size_t k) { return k == layout.victim; };
    // The victim's bodies are its own.
    for (std::size_t k = 0; k < clean.contacts.size(); ++k) {
      if (k == layout.victim) continue;
      const ContactRecord<T> r = clean.contacts.record(k);
      ASSERT_TRUE(!skip_body(r.a) && !skip_body(r.b));
    }
    for (const Solver* solver : {&scalar, &simd, &packed}) {
      Scene<T> clean_run = clean;
      Schedule schedule;
      schedule.build(clean_run.contacts.view(), clean_run.bodies.view());
      ImpulseBuffer<T> j_clean(clean.contacts.size());
      solver->solve(clean_run.bodies.view(), clean_run.contacts.view(), j_clean.view(), schedule);
      ASSERT_NE(j_clean.view().j.x[layout.victim], T(0));  // the victim acts when clean

      for (const Field field : {Field::va, Field::wa, Field::pa, Field::qa, Field::inv_mass_a, Field::inv_inertia_a,
                                Field::vb, Field::wb, Field::pb, Field::c, Field::n, Field::e, Field::mu}) {
        if (field == Field::mu && !friction) continue;
        for (const auto& [pname, value] : poisons<T>()) {
          for (const int comp : {0, 2}) {
            SCOPED_TRACE(std::string(type_name<T>()) + (layout.shared ? " shared" : " pairs") + " victim " +
                         std::to_string(layout.victim) + " " + to_string(solver->options().path) + " " +
                         to_string(solver->options().layout) + (friction ? " friction " : " frictionless ") +
                         name(field) + "[" + std::to_string(comp) + "] = " + pname);
            Scene<T> dirty = clean;
            poison(dirty, layout.victim, field, comp, value);
            Schedule s2;
            s2.build(dirty.contacts.view(), dirty.bodies.view());
            ImpulseBuffer<T> j(clean.contacts.size());
            solver->solve(dirty.bodies.view(), dirty.contacts.view(), j.view(), s2);
            ASSERT_TRUE(same_bodies(clean_run.bodies, dirty.bodies, skip_body));
            ASSERT_TRUE(same_impulses(j_clean, j, skip_contact));

            if (solver != &scalar) {
              // The victim itself: the scalar path agrees (NaN payloads aside).
              Scene<T> other = clean;
              poison(other, layout.victim, field, comp, value);
              ImpulseBuffer<T> js(clean.contacts.size());
              scalar.solve(other.bodies.view(), other.contacts.view(), js.view(), s2);
              const bool finite = std::isfinite(value);
              const auto x = body_arrays<T>(std::as_const(dirty.bodies).view());
              const auto y = body_arrays<T>(std::as_const(other.bodies).view());
              for (const std::size_t i : {std::size_t(vrec.a), std::size_t(vrec.b)}) {
                for (std::size_t f = 0; f < 17; ++f) {
                  EXPECT_TRUE(finite ? same_bits(x[f][i], y[f][i]) : same_or_both_nan(x[f][i], y[f][i]))
                      << "victim body " << i << " " << kBodyFieldNames[f] << ": " << x[f][i] << " vs " << y[f][i];
                }
              }
              const auto a = j.view();
              const auto b = js.view();
              const std::size_t k = layout.victim;
              for (const auto& [p, q] :
                   {std::pair{a.j.x[k], b.j.x[k]}, std::pair{a.j.y[k], b.j.y[k]}, std::pair{a.j.z[k], b.j.z[k]}}) {
                EXPECT_TRUE(finite ? same_bits(p, q) : same_or_both_nan(p, q)) << "victim J: " << p << " vs " << q;
              }
            }
          }
        }
      }
    }
  }
}

// A body sliding on an immovable ground whose centre is at the largest
// finite coordinates: the ground's lever arm along the sliding direction
// overflows, times its zeroed inverse moments that is NaN, and K(t) is NaN.
// The friction impulse min(|ut| / K(t), mu jn) must then be the same on
// every path: std::min (the scalar lanes) and minps/minpd (the SIMD lanes)
// disagreed on which operand a NaN gives (lane_min, lanes.hpp). 37 sliders:
// four SIMD groups of 8 float lanes and a tail, or of 16 and a tail.
template <class T>
void expect_same_bits_with_an_overflowing_ground() {
  constexpr T big = std::numeric_limits<T>::max();
  constexpr std::size_t sliders = 37;
  BodyBuffer<T> start(sliders + 1);
  ContactBuffer<T> contacts(sliders);
  BodyRecord<T> ground;
  ground.m = std::numeric_limits<T>::infinity();
  ground.I[0] = ground.I[1] = ground.I[2] = std::numeric_limits<T>::infinity();
  ground.p[0] = big;
  ground.p[1] = -big;
  start.set(sliders, ground);
  for (std::size_t k = 0; k < sliders; ++k) {
    BodyRecord<T> slider;
    slider.v[0] = T(0.6);  // sliding along (0.6, 0.8, 0), falling at 2 m/s
    slider.v[1] = T(0.8);
    slider.v[2] = T(-2);
    start.set(k, slider);
    ContactRecord<T> c;
    c.a = static_cast<BodyIndex>(k);
    c.b = static_cast<BodyIndex>(sliders);
    c.e = T(0.5);
    c.mu = T(0.5);
    contacts.set(k, c);
  }
  BodyBuffer<T> first = start;
  const ImpulseBuffer<T> first_j = kernel_solve(first, contacts.view(), options_for(Path::scalar));
  for (const int threads : {1, 2}) {
    SCOPED_TRACE("SIMD, threads " + std::to_string(threads));
    BodyBuffer<T> bodies = start;
    const ImpulseBuffer<T> j = kernel_solve(bodies, contacts.view(), options_for(Path::simd, threads, 8));
    for (std::size_t k = 0; k < sliders; ++k) {
      const BodyRecord<T> x = bodies.record(k), y = first.record(k);
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
      EXPECT_EQ(std::memcmp(&x, &y, sizeof(x)), 0) << "body " << k;
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
      EXPECT_EQ(std::memcmp(&j.view().j.x[k], &first_j.view().j.x[k], sizeof(T)), 0) << "contact " << k;
    }
  }
  EXPECT_TRUE(std::isnan(first.record(0).v[0]));  // the overflow reached the slider: the case is the one meant
}

TEST(LaneIsolation, OverflowingGroundGivesTheSameBitsOnEveryPath) {
  expect_same_bits_with_an_overflowing_ground<float>();
  expect_same_bits_with_an_overflowing_ground<double>();
}

// A scene the fuzzer drew (fuzz/corpus/entry/nan-sign-scalar-against-simd):
// bodies at coordinates near FLT_MAX, an inverse mass of DBL_MAX, eleven
// repeated contacts of two bodies. The law overflows, and inf - inf gives
// x86's default NaN (-NaN) in some operations while others pass on a +NaN;
// which one an operation on two NaNs returns depends on the order of its
// operands, which the compiler chose differently for the scalar and the
// vector lanes of the sanitizer build (the sphere model, double, accurate
// mode: -NaN on the scalar path, +NaN on the SIMD one). So every NaN the law
// writes is one NaN, the positive quiet one (canonical_nan, lanes.hpp;
// docs/decisions/0030-one-nan-on-every-path.md).
struct DrawnBody {
  double x[17];  // inv_mass, inverse moments (3), q (4), p, v, w
};
struct DrawnContact {
  BodyIndex a, b;
  double x[8];  // c, n, e, mu
};
const DrawnBody kOverflowBodies[] = {
    {0x1.88p-1, 0x1.b4p+0, 0x1.fp-1, 0x1.fp-2, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, -0x1.93e5939a08ceap+99, 0x1.74p+0,
     0x1.fffffep+127, 0x1.f8p+0, 0x1.93e5939a08ceap+99, 0x1.e8p-1, 0x1p+0, 0x1.4p-1, 0x1.79ca10c924223p-67},
    {0x1p-6, 0x1.0000a7c5ac472p+0, 0x1.8p+0, 0x1.2cp+0, 0x1.69333862fbcbbp-1, 0x1.bb4a7f623505ap-2,
     0x1.83a9d75f7647bp-67, 0x1.1f51787d484acp-1, 0x1.cp-2, 0x1.01p+4, 0x1.b8p-1, 0x1.e8p+0, -0x1.1004p+8, -0x1.b4p+8,
     0x1.8ff8p+7, -0x1.e808p+7, -0x1.fp+6},
    {0x1.ep+5, 0x1.801p+7, 0x1.7fcp+4, 0x1.d404p+8, -0x1.23a482e952fc1p-1, 0x1.0f44db2959a12p-1, -0x1.96f1752dc1302p-3,
     0x1.313517e250e41p-1, 0x1.bp+7, 0x1.f8p+7, 0x1.b038p+7, 0x1.cp+4, -0x1.f8p+8, 0x1.3p+8, -0x1.d804p+8, 0x0p+0,
     0x1.dp+6},
    {0x1.2p+5, 0x1.4p+6, 0x1.c02p+5, 0x1.7f8p+3, 0x1.4de3fba79d982p-1, 0x1.9de7dd41d2105p-2, 0x1.21bfc4b0b269fp-1,
     0x1.350b4cee5e4b8p-2, -0x1.301p+6, -0x1.7p+7, 0x1p+3, 0x1.919p+7, 0x1.919p+7, 0x1.919p+7, 0x1.919p+7, 0x1.919p+7,
     0x1.919p+7},
    {0x1.919p+7, 0x1.919p+7, 0x1.919p+7, 0x1.919p+7, 0x1p-1, 0x1p-1, 0x1p-1, 0x1p-1, 0x1.9018p+7, 0x1p-6, 0x1.6cp+0,
     -0x0p+0, 0x1.18p-1, 0x1.fffffep+127, 0x1.48p-1, 0x1.48p-1, 0x1.fffffffffffffp+1023},
    {0x1.fffffffffffffp+1023, 0x1.c8p-1, 0x1p-4, 0x1.804p+4, 0x0p+0, 0x1.583c480e90fd6p-2, 0x1.4db9623278e72p-1,
     0x1.5c100feed9ad3p-1, 0x1.e184p+8, 0x1.89a4p+8, 0x1.d8c4p+8, 0x1.918p+7, 0x1.7d7cp+8, 0x1.cda4p+8, 0x1.7d8cp+8,
     0x1.b184p+8, 0x1.cdccp+8},
    {0x1.7ddp+8, 0x1.e5cp+8, 0x1.957cp+8, 0x1.a5b8p+8, -0x1.15ecdeba2775dp-1, -0x1.4723a2ee6892p-1,
     0x1.bdd2006ff377cp-2, 0x1.4fd00da0cb56ep-2, 0x1.a8p+7, 0x1p+7, 0x1.8p+4, 0x1.802p+7, 0x1.ffcp+4, 0x1.9bfcp+8,
     0x1.98p+8, 0x1.8ffcp+8, -0x1.2808p+7},
    {0x1.601p+6, 0x1.4p+5, 0x1p+2, 0x1.004p+6, 0x0p+0, 0x1.676c8ae6f87dp-1, -0x1.abf064b5f2884p-2,
     -0x1.27413f10c32c1p-1, 0x1.d8p+7, 0x0p+0, 0x1.68p+7, 0x1.4p+7, 0x1.03p+3, 0x1.fep+1, -0x1.8p+6, 0x1.a7fcp+8,
     -0x1.d8p+7}};
const DrawnContact kOverflowContacts[] = {
    {2, 0, {0x1.4p+4, -0x1.6p+8, 0x1.9bfcp+8, 0x0p+0, 0x1.fadbc940dbe4fp-1, 0x1.2181fb657d997p-3, 0x0p+0, 0x1.5p+6}},
    {6,
     7,
     {0x1.ffp+2, -0x1.ep+6, 0x1.c7f8p+7, -0x1.c3a228d7b086dp-1, -0x1.c3ab915bb2452p-2, -0x1.52b2903ec3166p-3, 0x0p+0,
      0x1.6p+5}},
    {7,
     3,
     {0x1.ffcp+4, 0x1.c4p+8, 0x1.2p+7, 0x1.8745ae9677307p-1, 0x1.2c11fcda1410ap-3, -0x1.4197f53206c92p-1, 0x0p+0,
      0x1.08p+7}},
    {0,
     7,
     {0x1.7fcp+4, -0x1.f804p+8, -0x1.8p+6, 0x1.d1314a3786525p-1, 0x1.85bcb939f2706p-4, -0x1.a07e213f4fdc1p-2, 0x0p+0,
      0x1.c8p+7}},
    {7,
     3,
     {0x1.3fcp+4, -0x1.3p+8, 0x1.38p+8, -0x1.caf7038318639p-1, -0x1.40ebd6c41e13dp-2, -0x1.40ebd6c41e13dp-2, 0x0p+0,
      0x1.5p+6}},
    {1,
     2,
     {0x1.ff8p+3, -0x1.0404p+8, -0x1.dcp+8, -0x1.8fe41f0bf7d3p-1, 0x1.44319d62cf88bp-2, -0x1.1399c25ebc185p-1, 0x0p+0,
      0x1.cp+4}},
    {1,
     2,
     {0x1p+4, 0x1.6bfcp+8, -0x1.801p+6, -0x1.d30aed9f95ba7p-1, 0x1.2f50d73eb7b37p-3, -0x1.873ab5b7ae171p-2, 0x0p+0,
      0x1.9p+6}},
    {2, 6, {0x1.8p+4, 0x1.28p+8, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x1.ap+6}},
    {7,
     6,
     {0x1.8p+4, -0x1.ecp+8, 0x1p+8, 0x1.827d21d1ec9dbp-1, 0x1.3a6e7af8e3368p-1, 0x1.d7a5b87554d1cp-3, 0x0p+0,
      0x1.ep+5}},
    {4,
     1,
     {0x1.ffcp+4, -0x1.901p+6, -0x1.7p+8, 0x1.912efb15dd0e2p-1, 0x1.0ee8a5a11d4fdp-1, -0x1.4d7defd63350bp-2, 0x0p+0,
      0x1.7p+7}},
    {2,
     6,
     {0x1.ffcp+4, -0x1.1p+6, 0x1.7ff8p+7, -0x1.0175e7c921457p-1, 0x1.43aa2ab3b4cc5p-2, 0x1.9be87e1deda8ap-1, 0x0p+0,
      0x1.5p+7}},
    {2,
     6,
     {0x0p+0, 0x1.fcp+8, -0x1.8804p+8, 0x1.d3368c46f32e2p-1, -0x1.1151f0d50f2bdp-2, -0x1.3d5d2d71d423cp-2, 0x0p+0,
      0x1.e8p+7}},
    {5, 0, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}},
    {0, 1, {0x0p+0, 0x0p+0, 0x0p+0, 0x1p+0, 0x0p+0, 0x0p+0, 0x0p+0, 0x0p+0}}};

/// The drawn scene's bodies, solved with `options` in the sphere model.
std::pair<BodyBuffer<double>, ImpulseBuffer<double>> solve_overflowing(const SolverOptions& options) {
  constexpr std::size_t n = std::size(kOverflowBodies), m = std::size(kOverflowContacts);
  BodyBuffer<double> bodies(n);
  const BodyView<double> v = bodies.view();
  double* const fields[17] = {v.inv_mass, v.inv_inertia.x, v.inv_inertia.y, v.inv_inertia.z, v.q.w, v.q.x,
                              v.q.y,      v.q.z,           v.p.x,           v.p.y,           v.p.z, v.v.x,
                              v.v.y,      v.v.z,           v.w.x,           v.w.y,           v.w.z};
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t f = 0; f < 17; ++f) fields[f][i] = kOverflowBodies[i].x[f];
  }
  std::vector<BodyIndex> a(m), b(m);
  std::array<std::vector<double>, 8> x;
  for (std::size_t k = 0; k < m; ++k) {
    a[k] = kOverflowContacts[k].a;
    b[k] = kOverflowContacts[k].b;
    for (std::size_t f = 0; f < 8; ++f) x[f].push_back(kOverflowContacts[k].x[f]);
  }
  ContactView<double> c;
  c.count = m;
  c.a = a.data();
  c.b = b.data();
  c.c = {x[0].data(), x[1].data(), x[2].data()};
  c.n = {x[3].data(), x[4].data(), x[5].data()};
  c.e = x[6].data();
  c.mu = x[7].data();
  ImpulseBuffer<double> j(m);
  Schedule schedule;
  schedule.build(c, bodies.view());
  Solver(options).solve(sphere_view(bodies.view()), c, j.view(), schedule);
  return {std::move(bodies), std::move(j)};
}

TEST(LaneIsolation, AnOverflowingSceneWritesOneNaNOnEveryPath) {
  for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
    SolverOptions o = options_for(Path::scalar, 1, 8);
    o.accuracy = accuracy;
    const auto [first, first_j] = solve_overflowing(o);
    // The case is the one meant: the law overflowed into NaN, and every NaN
    // it wrote is the one NaN.
    const auto fields = body_arrays<double>(first.view());
    std::size_t nans = 0;
    const double canonical = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t f = 11; f < 17; ++f) {
      for (std::size_t i = 0; i < first.size(); ++i) {
        if (std::isnan(fields[f][i])) {
          ++nans;
          EXPECT_TRUE(same_bits(fields[f][i], canonical)) << kBodyFieldNames[f] << " of body " << i;
        }
      }
    }
    if (accuracy == Accuracy::accurate) {
      EXPECT_GT(nans, 0u);  // the fast mode stays finite on this scene
    }
    for (const Path path : {Path::scalar, Path::simd}) {
      for (const BodyLayout layout : {BodyLayout::soa, BodyLayout::packed}) {
        for (const int threads : {1, 2}) {
          SolverOptions p = options_for(path, threads, 8);
          p.accuracy = accuracy;
          p.layout = layout;
          const auto [bodies, j] = solve_overflowing(p);
          EXPECT_TRUE(same_bodies(bodies, first));
          EXPECT_TRUE(same_impulses(j, first_j));
        }
      }
    }
  }
}

TEST(LaneIsolation, FloatFrictionless) { expect_isolated<float>(false); }
TEST(LaneIsolation, FloatWithFriction) { expect_isolated<float>(true); }
TEST(LaneIsolation, DoubleFrictionless) { expect_isolated<double>(false); }
TEST(LaneIsolation, DoubleWithFriction) { expect_isolated<double>(true); }

}  // namespace
}  // namespace collide::test
