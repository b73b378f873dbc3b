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
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/scene.hpp"
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

TEST(LaneIsolation, FloatFrictionless) { expect_isolated<float>(false); }
TEST(LaneIsolation, FloatWithFriction) { expect_isolated<float>(true); }
TEST(LaneIsolation, DoubleFrictionless) { expect_isolated<double>(false); }
TEST(LaneIsolation, DoubleWithFriction) { expect_isolated<double>(true); }

}  // namespace
}  // namespace collide::test
