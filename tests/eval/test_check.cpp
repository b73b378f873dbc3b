// test_check.cpp - collide/eval/check.hpp (what `solve --check` and `--stats`
// compute, shared with the Python module) and validate_indices().
//
//   * impulse_errors_eps: 0 for the reference itself, exactly |dJ| / unit for
//     a perturbed impulse, NaN for a NaN impulse; check_impulses summarises
//     the same numbers (max, worst contact, NaN counts as the worst);
//   * count_impacts counts non-zero impulses;
//   * solve_record has the --stats keys in order; to_json prints null for inf;
//   * validate_indices names the first bad index like validate().
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/check.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/io/scene.hpp"
#include "collide/validate.hpp"
#include "support/scenes.hpp"

namespace collide::test {
namespace {

using L = long double;

struct Solved {
  ImpulseBuffer<L> ref;
  std::vector<ReferenceContact<L>> diag;
  ImpulseBuffer<float> j;  // the reference rounded to float
};

Solved solved_scene() {
  SceneOptions o;
  o.seed = 5;
  o.friction = true;
  Scene<float> s = shared_scene<float>(64, 20, o);
  Scene<L> ls = convert_scene<L>(s);
  Solved r;
  r.ref.resize(ls.contacts.size());
  r.diag.resize(ls.contacts.size());
  reference_solve<L>(ls.bodies.view(), ls.contacts.view(), r.ref.view(), r.diag.data());
  r.j.resize(ls.contacts.size());
  for (std::size_t k = 0; k < r.j.size(); ++k) {
    r.j.view().j.x[k] = static_cast<float>(r.ref.view().j.x[k]);
    r.j.view().j.y[k] = static_cast<float>(r.ref.view().j.y[k]);
    r.j.view().j.z[k] = static_cast<float>(r.ref.view().j.z[k]);
  }
  return r;
}

TEST(Check, ErrorsPerContactAndSummaryAgree) {
  Solved s = solved_scene();
  const ImpulseView<const L> ref = std::as_const(s.ref).view();
  std::vector<double> err = impulse_errors_eps<float>(std::as_const(s.j).view(), ref, s.diag);
  ASSERT_EQ(err.size(), s.j.size());
  for (const double e : err) EXPECT_LE(e, 0.5 + 1e-9);  // rounding to float: at most half an eps of |J|

  // Perturb contact 9 by 100 error units: its error is exactly that.
  const std::size_t k = 9;
  const L unit = impulse_error_unit<float>(s.diag[k]);
  const float moved = static_cast<float>(L(s.j.view().j.x[k]) + 100 * unit);
  const L dj_expected = std::fabs(L(moved) - s.ref.view().j.x[k]);
  s.j.view().j.x[k] = moved;
  err = impulse_errors_eps<float>(std::as_const(s.j).view(), ref, s.diag);
  const L dy = L(s.j.view().j.y[k]) - s.ref.view().j.y[k], dz = L(s.j.view().j.z[k]) - s.ref.view().j.z[k];
  const L dj = std::sqrt(dj_expected * dj_expected + dy * dy + dz * dz);
  EXPECT_DOUBLE_EQ(err[k], static_cast<double>(dj / unit));
  EXPECT_GT(err[k], 90);
  ImpulseCheck c = check_impulses<float>(std::as_const(s.j).view(), ref, s.diag);
  EXPECT_EQ(c.worst_contact, k);
  EXPECT_DOUBLE_EQ(c.max_error_eps, err[k]);
  EXPECT_EQ(c.passed, err[k] <= kImpulseErrorBoundEps);

  // A NaN impulse is the worst error.
  s.j.view().j.z[3] = std::numeric_limits<float>::quiet_NaN();
  err = impulse_errors_eps<float>(std::as_const(s.j).view(), ref, s.diag);
  EXPECT_TRUE(std::isnan(err[3]));
  c = check_impulses<float>(std::as_const(s.j).view(), ref, s.diag);
  EXPECT_EQ(c.worst_contact, 3U);
  EXPECT_FALSE(c.passed);
}

TEST(Check, ImpactsAndRecord) {
  ImpulseBuffer<double> j(4);
  j.view().j.x[1] = 1;
  j.view().j.z[3] = -2;
  EXPECT_EQ(count_impacts<double>(std::as_const(j).view()), 2U);
  SolveStats st;
  st.contacts = 4;
  st.lanes = 4;
  st.isa = Isa::avx2;
  StatRecord r = solve_record<double>(st, std::as_const(j).view(), 8, 0.0, 0.5);
  std::vector<std::string> keys;
  for (const auto& kv : r) keys.push_back(kv.first);
  const std::vector<std::string> expected = {"collisions",
                                             "impacts",
                                             "bodies",
                                             "kernel_seconds",
                                             "collisions_per_second",
                                             "precision",
                                             "threads",
                                             "model",
                                             "path",
                                             "isa",
                                             "isa_choice",
                                             "layout",
                                             "accuracy",
                                             "lanes",
                                             "order",
                                             "passes",
                                             "iteration",
                                             "warm_start",
                                             "residual",
                                             "batches",
                                             "largest_batch",
                                             "colours",
                                             "overflow_contacts",
                                             "schedule_seconds",
                                             "isa_calibration_seconds",
                                             "allocate_seconds"};
  EXPECT_EQ(keys, expected);
  add_check(r, ImpulseCheck{}, 0.25);
  const std::string json = to_json(r);
  EXPECT_NE(json.find("\"impacts\": 2"), std::string::npos) << json;
  EXPECT_NE(json.find("\"collisions_per_second\": null"), std::string::npos) << json;  // 0 s: inf
  EXPECT_NE(json.find("\"precision\": \"double\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"isa\": \"avx2\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"isa_choice\": \"forced\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"check_passed\": true"), std::string::npos) << json;

  // A solve that measured the ISAs reports that time apart from the kernel's.
  st.isa_choice = IsaChoice::measured;
  st.isa_calibration_seconds = 0.25;
  const StatRecord m = solve_record<double>(st, std::as_const(j).view(), 8, 1.0, 0.5);
  const auto value = [&](const char* key) {
    for (const auto& [k, v] : m) {
      if (k == key) return v;
    }
    return StatValue{};
  };
  EXPECT_EQ(std::get<double>(value("kernel_seconds")), 0.75);
  EXPECT_EQ(std::get<double>(value("isa_calibration_seconds")), 0.25);
  EXPECT_EQ(std::get<std::string>(value("isa_choice")), "measured");

  // So does one that grew its buffers (the allocate phase).
  st.allocate_seconds = 0.125;
  const StatRecord a = solve_record<double>(st, std::as_const(j).view(), 8, 1.0, 0.5);
  const auto of_a = [&](const char* key) {
    for (const auto& [k, v] : a) {
      if (k == key) return v;
    }
    return StatValue{};
  };
  EXPECT_EQ(std::get<double>(of_a("kernel_seconds")), 0.625);
  EXPECT_EQ(std::get<double>(of_a("allocate_seconds")), 0.125);
}

TEST(ValidateIndices, NamesTheFirstBadIndex) {
  const BodyIndex a[] = {0, 2, 4, 1};
  BodyIndex b[] = {1, 3, 5, 0};
  EXPECT_TRUE(validate_indices(a, b, 4, 6));
  Validation v = validate_indices(a, b, 4, 5);
  EXPECT_FALSE(v);
  EXPECT_EQ(v.message, "contacts.b[2] = 5: out of range (5 bodies)");
  b[1] = 2;
  v = validate_indices(a, b, 4, 6);
  EXPECT_EQ(v.message, "contacts.b[1] = 2: a contact of a body with itself");
  v = validate_indices(a, b, 4, 3);
  EXPECT_EQ(v.message, "contacts.b[1] = 2: a contact of a body with itself");
  v = validate_indices(a, b, 4, 2);
  EXPECT_EQ(v.message, "contacts.a[1] = 2: out of range (2 bodies)");
}

}  // namespace
}  // namespace collide::test
