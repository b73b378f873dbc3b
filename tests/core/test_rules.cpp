// test_rules.cpp - the input rules of collide/rules.hpp, and that every
// place that takes physical units applies them with the same reason.
//
// What this proves
// ----------------
// * One table row per rule and precision (float and double, with the
//   representability cases each precision has: a mass or a moment whose
//   inverse overflows, a quaternion whose |q|^2 is subnormal or overflows):
//   (a) body_defect / contact_defect name the expected column and give the
//       expected reason, and body_ok / contact_ok say no;
//   (b) the scene reader, given the same value in a file (written by the
//       library's own row writer), throws a SceneError naming that row and
//       column whose message ends with exactly that reason;
//   (c) BodyBuffer / ContactBuffer set() and push_back() throw
//       std::invalid_argument naming the element and the column and ending
//       with exactly that reason, and push_back stores nothing.
//   A contact id at or above the body count is a rule only where the count
//   is known (the reader); the buffers do not know it and take the id.
// * Values at the edges of the rules are accepted by all three (inf mass and
//   moments, an unnormalised quaternion, |n| within 1e-3, e = 0 and 1, -0).
// * On random records made of special values the verdicts agree with the
//   defect finders, and the reader's fast and careful paths accept the same
//   rows and report the same defect.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/rules.hpp"
#include "support/csv_text.hpp"

namespace collide::test {
namespace {

template <class T>
constexpr const char* precision() {
  return std::is_same_v<T, float> ? "float" : "double";
}

template <class T>
struct BodyCase {
  std::string name;
  BodyRecord<T> body;
  std::string column;
  std::string reason;
};

template <class T>
struct ContactCase {
  std::string name;
  ContactRecord<T> contact;
  std::string column;
  std::string reason;
  bool needs_count = false;  // a rule only where the body count is known
};

constexpr std::size_t kBodies = 3;  // the contacts' scene

template <class T>
BodyRecord<T> good_body() {
  BodyRecord<T> b;
  b.m = T(2);
  b.I[0] = T(1), b.I[1] = T(0.5), b.I[2] = T(0.25);
  b.q[0] = T(0.5), b.q[1] = T(0.5), b.q[2] = T(0.5), b.q[3] = T(0.5);
  b.p[0] = T(1), b.p[1] = T(-2), b.p[2] = T(3);
  b.v[0] = T(0.5), b.v[1] = T(-3), b.v[2] = T(0);
  b.w[0] = T(0), b.w[1] = T(1), b.w[2] = T(-1);
  return b;
}

template <class T>
ContactRecord<T> good_contact() {
  ContactRecord<T> c;
  c.a = 0;
  c.b = 2;
  c.c[0] = T(0.5), c.c[1] = T(1), c.c[2] = T(-1);
  c.n[0] = T(0), c.n[1] = T(0.6), c.n[2] = T(0.8);
  c.e = T(0.5);
  c.mu = T(0.25);
  return c;
}

template <class T>
std::vector<BodyCase<T>> body_cases() {
  using L = std::numeric_limits<T>;
  const T nan = L::quiet_NaN(), inf = L::infinity();
  const std::string p = precision<T>();
  const std::string not_inf = "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got ";
  std::vector<BodyCase<T>> cases;
  auto add = [&](std::string name, auto spoil, std::string column, std::string reason) {
    BodyRecord<T> b = good_body<T>();
    spoil(b);
    cases.push_back({std::move(name), b, std::move(column), std::move(reason)});
  };
  // NaN nowhere.
  add(
      "nan_m", [&](BodyRecord<T>& b) { b.m = nan; }, "m", "NaN is not allowed");
  add(
      "nan_Iy", [&](BodyRecord<T>& b) { b.I[1] = nan; }, "Iy", "NaN is not allowed");
  add(
      "nan_qx", [&](BodyRecord<T>& b) { b.q[1] = nan; }, "qx", "NaN is not allowed");
  add(
      "nan_pz", [&](BodyRecord<T>& b) { b.p[2] = nan; }, "pz", "NaN is not allowed");
  add(
      "nan_vy", [&](BodyRecord<T>& b) { b.v[1] = nan; }, "vy", "NaN is not allowed");
  add(
      "nan_wx", [&](BodyRecord<T>& b) { b.w[0] = nan; }, "wx", "NaN is not allowed");
  // inf only in m and I.
  add(
      "inf_qw", [&](BodyRecord<T>& b) { b.q[0] = inf; }, "qw", not_inf + "inf");
  add(
      "inf_px", [&](BodyRecord<T>& b) { b.p[0] = inf; }, "px", not_inf + "inf");
  add(
      "minus_inf_vz", [&](BodyRecord<T>& b) { b.v[2] = -inf; }, "vz", not_inf + "-inf");
  add(
      "inf_wy", [&](BodyRecord<T>& b) { b.w[1] = inf; }, "wy", not_inf + "inf");
  // m > 0 and 1/m finite in T.
  add(
      "zero_m", [&](BodyRecord<T>& b) { b.m = T(0); }, "m", "mass must be > 0, got 0 (an immovable body has m = inf)");
  add(
      "minus_zero_m", [&](BodyRecord<T>& b) { b.m = -T(0); }, "m",
      "mass must be > 0, got -0 (an immovable body has m = inf)");
  add(
      "negative_m", [&](BodyRecord<T>& b) { b.m = T(-1); }, "m", "mass must be > 0, got -1");
  add(
      "minus_inf_m", [&](BodyRecord<T>& b) { b.m = -inf; }, "m", "mass must be > 0, got -inf");
  // The moments likewise.
  add(
      "zero_Ix", [&](BodyRecord<T>& b) { b.I[0] = T(0); }, "Ix",
      "moment of inertia must be > 0, got 0 (a locked axis has moment inf)");
  add(
      "negative_Iz", [&](BodyRecord<T>& b) { b.I[2] = T(-0.5); }, "Iz", "moment of inertia must be > 0, got -0.5");
  add(
      "minus_inf_Iy", [&](BodyRecord<T>& b) { b.I[1] = -inf; }, "Iy", "moment of inertia must be > 0, got -inf");
  // What each precision can represent: an inverse that overflows.
  if constexpr (std::is_same_v<T, float>) {
    add(
        "tiny_m", [&](BodyRecord<T>& b) { b.m = T(1e-45); }, "m",
        "mass 1e-45 is too small: its inverse overflows float");
    add(
        "tiny_Iy", [&](BodyRecord<T>& b) { b.I[1] = T(1e-40); }, "Iy",
        "moment of inertia 1e-40 is too small: its inverse overflows float");
  } else {
    add(
        "tiny_m", [&](BodyRecord<T>& b) { b.m = L::denorm_min(); }, "m",
        "mass 5e-324 is too small: its inverse overflows double");
    add(
        "tiny_Iy", [&](BodyRecord<T>& b) { b.I[1] = T(1e-310); }, "Iy",
        "moment of inertia 1e-310 is too small: its inverse overflows double");
  }
  // A zero quaternion; |q|^2 subnormal (or 0 by underflow) or overflowing in T.
  add(
      "zero_q", [&](BodyRecord<T>& b) { b.q[0] = b.q[1] = b.q[2] = b.q[3] = T(0); }, "qw",
      "zero quaternion (qw, qx, qy, qz are all 0)");
  add(
      "minus_zero_q", [&](BodyRecord<T>& b) { b.q[0] = b.q[1] = b.q[2] = b.q[3] = -T(0); }, "qw",
      "zero quaternion (qw, qx, qy, qz are all 0)");
  const std::string small = "quaternion cannot be normalised in " + p + ": it is too close to zero (qw, qx, qy, qz = ";
  const std::string large = "quaternion cannot be normalised in " + p + ": it is too large (qw, qx, qy, qz = ";
  if constexpr (std::is_same_v<T, float>) {
    add(
        "subnormal_q2", [&](BodyRecord<T>& b) { b.q[0] = T(1e-20), b.q[1] = b.q[2] = b.q[3] = T(0); }, "qw",
        small + "1e-20, 0, 0, 0)");
    add(
        "underflowing_q2", [&](BodyRecord<T>& b) { b.q[0] = b.q[1] = T(1e-25), b.q[2] = b.q[3] = T(0); }, "qw",
        small + "1e-25, 1e-25, 0, 0)");
    add(
        "overflowing_q2", [&](BodyRecord<T>& b) { b.q[0] = T(0), b.q[1] = T(-1e20), b.q[2] = b.q[3] = T(1); }, "qw",
        large + "0, -1e+20, 1, 1)");
  } else {
    add(
        "subnormal_q2", [&](BodyRecord<T>& b) { b.q[0] = T(1e-160), b.q[1] = b.q[2] = b.q[3] = T(0); }, "qw",
        small + "1e-160, 0, 0, 0)");
    add(
        "underflowing_q2", [&](BodyRecord<T>& b) { b.q[0] = b.q[1] = T(1e-170), b.q[2] = b.q[3] = T(0); }, "qw",
        small + "1e-170, 1e-170, 0, 0)");
    add(
        "overflowing_q2", [&](BodyRecord<T>& b) { b.q[0] = T(0), b.q[1] = T(-1e200), b.q[2] = b.q[3] = T(1); }, "qw",
        large + "0, -1e+200, 1, 1)");
  }
  // The first defect in column order; the quaternion after every column.
  add(
      "first_in_column_order",
      [&](BodyRecord<T>& b) {
        b.v[0] = nan;
        b.I[2] = T(-2);
      },
      "Iz", "moment of inertia must be > 0, got -2");
  add(
      "quaternion_after_columns",
      [&](BodyRecord<T>& b) {
        b.q[0] = b.q[1] = b.q[2] = b.q[3] = T(0);
        b.w[2] = -inf;
      },
      "wz", not_inf + "-inf");
  return cases;
}

template <class T>
std::vector<ContactCase<T>> contact_cases() {
  using L = std::numeric_limits<T>;
  const T nan = L::quiet_NaN(), inf = L::infinity();
  const std::string not_inf = "inf is not allowed here (only m, Ix, Iy and Iz may be inf), got ";
  std::vector<ContactCase<T>> cases;
  auto add = [&](std::string name, auto spoil, std::string column, std::string reason, bool needs_count = false) {
    ContactRecord<T> c = good_contact<T>();
    spoil(c);
    cases.push_back({std::move(name), c, std::move(column), std::move(reason), needs_count});
  };
  // Ids below the body count (where it is known), a != b.
  add(
      "a_out_of_range", [](ContactRecord<T>& c) { c.a = 3; }, "a",
      "body id 3 is out of range: the scene has 3 bodies (ids 0 to 2)", true);
  add(
      "b_out_of_range", [](ContactRecord<T>& c) { c.b = 4000000000u; }, "b",
      "body id 4000000000 is out of range: the scene has 3 bodies (ids 0 to 2)", true);
  add(
      "self", [](ContactRecord<T>& c) { c.b = c.a; }, "b", "contact of body 0 with itself (a == b)");
  // NaN nowhere, inf nowhere.
  add(
      "nan_cx", [&](ContactRecord<T>& c) { c.c[0] = nan; }, "cx", "NaN is not allowed");
  add(
      "nan_ny", [&](ContactRecord<T>& c) { c.n[1] = nan; }, "ny", "NaN is not allowed");
  add(
      "nan_e", [&](ContactRecord<T>& c) { c.e = nan; }, "e", "NaN is not allowed");
  add(
      "nan_mu", [&](ContactRecord<T>& c) { c.mu = nan; }, "mu", "NaN is not allowed");
  add(
      "inf_cz", [&](ContactRecord<T>& c) { c.c[2] = inf; }, "cz", not_inf + "inf");
  add(
      "minus_inf_nz", [&](ContactRecord<T>& c) { c.n[2] = -inf; }, "nz", not_inf + "-inf");
  add(
      "inf_mu", [&](ContactRecord<T>& c) { c.mu = inf; }, "mu", not_inf + "inf");
  // e in [0, 1], mu >= 0.
  add(
      "e_above_one", [](ContactRecord<T>& c) { c.e = T(1.5); }, "e", "e must be in [0, 1], got 1.5");
  add(
      "e_negative", [](ContactRecord<T>& c) { c.e = T(-0.125); }, "e", "e must be in [0, 1], got -0.125");
  add(
      "mu_negative", [](ContactRecord<T>& c) { c.mu = T(-0.25); }, "mu", "mu must be >= 0, got -0.25");
  // |n| within 1e-3 of 1 (judged in double, shown with 9 digits).
  add(
      "normal_long", [](ContactRecord<T>& c) { c.n[0] = T(0), c.n[1] = T(0), c.n[2] = T(1.25); }, "nx",
      "normal length 1.25 is not 1 within 1e-3 (nx, ny, nz = 0, 0, 1.25)");
  add(
      "normal_short", [](ContactRecord<T>& c) { c.n[0] = T(-0.5), c.n[1] = T(0), c.n[2] = T(0.5); }, "nx",
      "normal length 0.707106781 is not 1 within 1e-3 (nx, ny, nz = -0.5, 0, 0.5)");
  add(
      "normal_zero", [](ContactRecord<T>& c) { c.n[0] = c.n[1] = c.n[2] = T(0); }, "nx",
      "normal length 0 is not 1 within 1e-3 (nx, ny, nz = 0, 0, 0)");
  add(
      "normal_just_outside", [](ContactRecord<T>& c) { c.n[0] = T(0), c.n[1] = T(0), c.n[2] = T(1.002); }, "nx",
      std::is_same_v<T, float> ? "normal length 1.00199997 is not 1 within 1e-3 (nx, ny, nz = 0, 0, 1.002)"
                               : "normal length 1.002 is not 1 within 1e-3 (nx, ny, nz = 0, 0, 1.002)");
  // The first defect in column order; the normal after every column.
  add(
      "first_in_column_order",
      [&](ContactRecord<T>& c) {
        c.mu = T(-1);
        c.c[1] = nan;
      },
      "cy", "NaN is not allowed");
  add(
      "normal_after_columns",
      [&](ContactRecord<T>& c) {
        c.n[2] = T(3);
        c.e = T(2);
      },
      "e", "e must be in [0, 1], got 2");
  return cases;
}

/// Values at the edges of the rules: accepted everywhere.
template <class T>
std::vector<BodyRecord<T>> good_bodies() {
  const T inf = std::numeric_limits<T>::infinity();
  std::vector<BodyRecord<T>> out;
  BodyRecord<T> b = good_body<T>();
  out.push_back(b);
  b.m = inf;  // immovable
  out.push_back(b);
  b = good_body<T>();
  b.I[0] = b.I[2] = inf;                           // locked axes
  b.q[0] = T(2), b.q[1] = b.q[2] = b.q[3] = T(0);  // not normalised
  b.v[0] = -T(0);
  b.w[2] = std::numeric_limits<T>::denorm_min();  // subnormal, finite
  out.push_back(b);
  b = good_body<T>();
  b.m = std::is_same_v<T, float> ? T(1e-30) : T(1e-300);     // small, and its inverse finite
  b.q[0] = std::is_same_v<T, float> ? T(1e-15) : T(1e-150);  // |q|^2 just normal
  b.q[1] = b.q[2] = b.q[3] = T(0);
  out.push_back(b);
  return out;
}

template <class T>
std::vector<ContactRecord<T>> good_contacts() {
  std::vector<ContactRecord<T>> out;
  ContactRecord<T> c = good_contact<T>();
  out.push_back(c);
  c.e = T(0);
  c.mu = T(0);
  c.n[0] = T(0), c.n[1] = T(0), c.n[2] = T(1.0005);  // within 1e-3
  out.push_back(c);
  c.e = T(1);
  c.mu = T(1e30);
  c.n[2] = T(0.9991);
  c.a = 2;
  c.b = 1;
  out.push_back(c);
  c.e = -T(0);
  c.mu = -T(0);
  c.n[2] = T(-1);
  out.push_back(c);
  return out;
}

template <class T>
std::string body_file(const std::vector<BodyRecord<T>>& rows) {
  std::string text(bodies_header());
  for (const BodyRecord<T>& r : rows) append_body_row(text, r);
  return text;
}

template <class T>
std::string contact_file(const std::vector<ContactRecord<T>>& rows) {
  std::string text(contacts_header());
  for (const ContactRecord<T>& r : rows) append_contact_row(text, r);
  return text;
}

template <class F>
std::optional<SceneError> scene_error(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e;
  }
  return std::nullopt;
}

template <class F>
std::string invalid_argument(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(nothing thrown)";
}

template <class T>
class Rules : public ::testing::Test {};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(Rules, Precisions);

TYPED_TEST(Rules, EveryBodyRuleGivesOneReasonEverywhere) {
  using T = TypeParam;
  for (const BodyCase<T>& c : body_cases<T>()) {
    SCOPED_TRACE(std::string(precision<T>()) + " " + c.name);
    // (a) the rules.
    const std::optional<Defect> d = body_defect(c.body);
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->column, c.column);
    EXPECT_EQ(d->reason, c.reason);
    EXPECT_FALSE(body_ok(c.body));
    // (b) the reader: the bad body is row 1 (line 3), after a good one.
    const std::string text = body_file<T>({good_body<T>(), c.body});
    for (const std::string& t : {text, with_blanks(text)}) {
      const std::optional<SceneError> e = scene_error([&] { (void)parse_bodies<T>(t, "bodies.csv"); });
      ASSERT_TRUE(e.has_value()) << t;
      EXPECT_EQ(e->row(), 1u);
      EXPECT_EQ(e->line(), 3u);
      EXPECT_EQ(e->column(), c.column);
      EXPECT_EQ(e->reason(), c.reason);
      EXPECT_EQ(std::string(e->what()), "bodies.csv:3: row 1, column '" + c.column + "': " + c.reason);
    }
    // (c) the buffers.
    BodyBuffer<T> buffer;
    buffer.push_back(good_body<T>());
    EXPECT_EQ(invalid_argument([&] { buffer.set(0, c.body); }),
              "collide::BodyBuffer::set: body 0, column '" + c.column + "': " + c.reason);
    EXPECT_EQ(invalid_argument([&] { buffer.push_back(c.body); }),
              "collide::BodyBuffer::push_back: body 1, column '" + c.column + "': " + c.reason);
    EXPECT_EQ(buffer.size(), 1u);  // nothing stored
    EXPECT_EQ(buffer.view().inv_mass[0], T(0.5));
  }
}

TYPED_TEST(Rules, EveryContactRuleGivesOneReasonEverywhere) {
  using T = TypeParam;
  for (const ContactCase<T>& c : contact_cases<T>()) {
    SCOPED_TRACE(std::string(precision<T>()) + " " + c.name);
    // (a) the rules; a body count only matters for the id rules.
    const std::optional<Defect> d = contact_defect(c.contact, kBodies);
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->column, c.column);
    EXPECT_EQ(d->reason, c.reason);
    EXPECT_FALSE(contact_ok(c.contact, kBodies));
    EXPECT_EQ(contact_defect(c.contact).has_value(), !c.needs_count);
    EXPECT_EQ(contact_ok(c.contact), c.needs_count);
    // (b) the reader.
    const std::string text = contact_file<T>({good_contact<T>(), c.contact});
    for (const std::string& t : {text, with_blanks(text)}) {
      const std::optional<SceneError> e = scene_error([&] { (void)parse_contacts<T>(t, "contacts.csv", kBodies); });
      ASSERT_TRUE(e.has_value()) << t;
      EXPECT_EQ(e->row(), 1u);
      EXPECT_EQ(e->line(), 3u);
      EXPECT_EQ(e->column(), c.column);
      EXPECT_EQ(e->reason(), c.reason);
      EXPECT_EQ(std::string(e->what()), "contacts.csv:3: row 1, column '" + c.column + "': " + c.reason);
    }
    // (c) the buffers (which know no body count).
    ContactBuffer<T> buffer;
    buffer.push_back(good_contact<T>());
    if (c.needs_count) {
      EXPECT_NO_THROW(buffer.set(0, c.contact));
      continue;
    }
    EXPECT_EQ(invalid_argument([&] { buffer.set(0, c.contact); }),
              "collide::ContactBuffer::set: contact 0, column '" + c.column + "': " + c.reason);
    EXPECT_EQ(invalid_argument([&] { buffer.push_back(c.contact); }),
              "collide::ContactBuffer::push_back: contact 1, column '" + c.column + "': " + c.reason);
    EXPECT_EQ(buffer.size(), 1u);
    EXPECT_EQ(buffer.record(0).b, 2u);
  }
}

TYPED_TEST(Rules, EdgesOfTheRulesAreAccepted) {
  using T = TypeParam;
  const std::vector<BodyRecord<T>> bodies = good_bodies<T>();
  for (const BodyRecord<T>& b : bodies) {
    EXPECT_FALSE(body_defect(b).has_value()) << body_defect(b)->reason;
    EXPECT_TRUE(body_ok(b));
  }
  EXPECT_EQ(parse_bodies<T>(body_file(bodies), "b").size(), bodies.size());
  EXPECT_EQ(parse_bodies<T>(with_blanks(body_file(bodies)), "b").size(), bodies.size());
  BodyBuffer<T> bb;
  for (const BodyRecord<T>& b : bodies) EXPECT_NO_THROW(bb.push_back(b));

  const std::vector<ContactRecord<T>> contacts = good_contacts<T>();
  for (const ContactRecord<T>& c : contacts) {
    EXPECT_FALSE(contact_defect(c, kBodies).has_value()) << contact_defect(c, kBodies)->reason;
    EXPECT_TRUE(contact_ok(c, kBodies));
  }
  EXPECT_EQ(parse_contacts<T>(contact_file(contacts), "c", kBodies).size(), contacts.size());
  EXPECT_EQ(parse_contacts<T>(with_blanks(contact_file(contacts)), "c", kBodies).size(), contacts.size());
  ContactBuffer<T> cb;
  for (const ContactRecord<T>& c : contacts) EXPECT_NO_THROW(cb.push_back(c));
  // The id rule's edge: the last body.
  ContactRecord<T> last = good_contact<T>();
  last.a = kBodies - 1;
  last.b = 0;
  EXPECT_TRUE(contact_ok(last, kBodies));
  EXPECT_FALSE(contact_ok(last, kBodies - 1));
}

/// A value drawn from the special values every rule has an edge at.
template <class T>
T special(std::mt19937_64& rng) {
  using L = std::numeric_limits<T>;
  const T values[] = {T(1),           T(-1),    T(0),     -T(0),           T(0.5),
                      T(2),           T(1e-3),  L::min(), L::denorm_min(), -L::denorm_min(),
                      L::max(),       T(1e-20), T(1e20),  L::infinity(),   -L::infinity(),
                      L::quiet_NaN(), T(0.6),   T(0.8)};
  return values[rng() % (sizeof values / sizeof values[0])];
}

TYPED_TEST(Rules, VerdictsAndBothReaderPathsAgree) {
  using T = TypeParam;
  std::mt19937_64 rng(11);
  int rejected = 0, accepted = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    BodyRecord<T> b = good_body<T>();
    ContactRecord<T> c = good_contact<T>();
    // Spoil a few fields (most records then break a rule, some do not).
    T* body_fields[] = {&b.m,    &b.I[0], &b.I[1], &b.I[2], &b.q[0], &b.q[1], &b.q[2], &b.q[3], &b.p[0],
                        &b.p[1], &b.p[2], &b.v[0], &b.v[1], &b.v[2], &b.w[0], &b.w[1], &b.w[2]};
    T* contact_fields[] = {&c.c[0], &c.c[1], &c.c[2], &c.n[0], &c.n[1], &c.n[2], &c.e, &c.mu};
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < edits; ++k) {
      *body_fields[rng() % 17] = special<T>(rng);
      *contact_fields[rng() % 8] = special<T>(rng);
    }
    if (rng() % 8 == 0) c.b = static_cast<BodyIndex>(rng() % 5);
    const std::optional<Defect> bd = body_defect(b);
    const std::optional<Defect> cd = contact_defect(c, kBodies);
    ASSERT_EQ(body_ok(b), !bd.has_value());
    ASSERT_EQ(contact_ok(c, kBodies), !cd.has_value());
    (bd ? rejected : accepted) += 1;

    const std::string bodies = body_file<T>({b});
    const std::string contacts = contact_file<T>({c});
    for (const std::string& t : {bodies, with_blanks(bodies)}) {
      const std::optional<SceneError> e = scene_error([&] { (void)parse_bodies<T>(t, "b"); });
      ASSERT_EQ(e.has_value(), bd.has_value()) << t;
      if (e) {
        ASSERT_EQ(e->reason(), bd->reason) << t;
      }
    }
    for (const std::string& t : {contacts, with_blanks(contacts)}) {
      const std::optional<SceneError> e = scene_error([&] { (void)parse_contacts<T>(t, "c", kBodies); });
      ASSERT_EQ(e.has_value(), cd.has_value()) << t;
      if (e) {
        ASSERT_EQ(e->reason(), cd->reason) << t;
      }
    }
  }
  EXPECT_GT(rejected, 100);
  EXPECT_GT(accepted, 100);
}

// The buffers of long double (the reference's) apply the same rules.
TEST(Rules, LongDoubleBuffersCheckToo) {
  BodyBuffer<long double> b;
  BodyRecord<long double> r;
  r.v[1] = std::numeric_limits<long double>::quiet_NaN();
  EXPECT_EQ(invalid_argument([&] { b.push_back(r); }),
            "collide::BodyBuffer::push_back: body 0, column 'vy': NaN is not allowed");
  ContactBuffer<long double> c;
  ContactRecord<long double> k;
  k.b = 1;
  k.e = 2;
  EXPECT_EQ(invalid_argument([&] { c.push_back(k); }),
            "collide::ContactBuffer::push_back: contact 0, column 'e': e must be in [0, 1], got 2");
}

}  // namespace
}  // namespace collide::test
