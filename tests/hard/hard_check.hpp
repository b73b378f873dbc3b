// tests/hard/hard_check.hpp - running a hard-case scene through every model
// that fits it and holding each result to the documented error bound.
//
// What a run proves for one scene (run_scene):
// * the scene really is shaped for the model its family promises
//   (choose_model() says so), and every model that fits it (model_misfit()
//   empty) is run, on the scalar and the SIMD path;
// * the two paths give identical bytes;
// * no NaN or inf in any impulse or velocity;
// * no contact is above kImpulseErrorTargetEps (2) units, the fast mode's
//   target (a family still above it passes the bound as its
//   target and says so), and a fortiori every contact satisfies
//   |J - Jref| <= kImpulseErrorBoundEps * eps(T) *
//   impulse_scale, Jref and impulse_scale from reference_solve<long double>
//   on convert_scene<long double>(scene) - exactly the kernel's inputs; a
//   contact whose impulse_scale is 0 (both bodies immovable) must give J = 0.
// The largest and the 99th-percentile error (in eps * impulse_scale) are
// printed with a "[hard]" tag, so that docs/collision-law.md can quote them.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/hard_scenes.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/solve_helpers.hpp"

namespace collide::hard {

using L = long double;
using V3 = std::array<double, 3>;

/// The long double reference of a scene: solved bodies, impulses, and the
/// per-contact diagnostics (impulse_scale, vn, jn, ...).
struct Reference {
  Scene<L> scene;
  ImpulseBuffer<L> j;
  std::vector<ReferenceContact<L>> diag;
};

template <class T>
Reference reference_of(const Scene<T>& scene) {
  Reference r{convert_scene<L>(scene), {}, {}};
  r.j = test::reference(r.scene.bodies, r.scene.contacts.view(), &r.diag);
  return r;
}

/// A kernel result.
template <class T>
struct Outcome {
  BodyBuffer<T> bodies;
  ImpulseBuffer<T> j;
};

template <class T>
Outcome<T> kernel_result(const Scene<T>& scene, const BodyBuffer<T>& start, Model model, const SolverOptions& options) {
  Outcome<T> out{start, ImpulseBuffer<T>(scene.contacts.size())};
  Schedule schedule;
  schedule.build(scene.contacts.view(), out.bodies.view());
  Solver(options).solve(model, out.bodies.view(), scene.contacts.view(), out.j.view(), schedule);
  return out;
}

/// |J - Jref| / (eps(T) impulse_scale) of contact k; 0 when both are equal,
/// inf when J differs from a reference whose scale is 0.
template <class T>
L normalised_error(const ImpulseBuffer<T>& j, const Reference& ref, std::size_t k) {
  const auto a = j.view();
  const auto r = ref.j.view();
  const L dx = L(a.j.x[k]) - r.j.x[k], dy = L(a.j.y[k]) - r.j.y[k], dz = L(a.j.z[k]) - r.j.z[k];
  const L err = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (err == 0) return 0;
  return normalised_impulse_error<T>(err, ref.diag[k]);
}

struct ErrorStats {
  L max = 0, p99 = 0;
  std::size_t worst = 0, over = 0, acting = 0, count = 0;
};

template <class T>
ErrorStats error_stats(const ImpulseBuffer<T>& j, const Reference& ref) {
  ErrorStats st;
  st.count = j.size();
  std::vector<L> errs(j.size());
  for (std::size_t k = 0; k < j.size(); ++k) {
    errs[k] = normalised_error(j, ref, k);
    st.acting += ref.diag[k].jn > 0;
    st.over += !(errs[k] <= test::kErrorBoundEps);
    if (!(errs[k] <= st.max)) {
      st.max = errs[k];
      st.worst = k;
    }
  }
  if (!errs.empty()) {
    const auto pos = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(errs.size() - 1));
    std::nth_element(errs.begin(), errs.begin() + pos, errs.end());
    st.p99 = errs[static_cast<std::size_t>(pos)];
  }
  return st;
}

/// Every impulse and every velocity finite.
template <class T>
::testing::AssertionResult all_finite(const Outcome<T>& out) {
  const auto j = out.j.view();
  for (std::size_t k = 0; k < j.count; ++k) {
    for (const T x : {j.j.x[k], j.j.y[k], j.j.z[k]}) {
      if (!std::isfinite(x)) return ::testing::AssertionFailure() << "J of contact " << k << " is " << x;
    }
  }
  const BodyView<const T> b = out.bodies.view();
  for (std::size_t i = 0; i < b.count; ++i) {
    for (const T x : {b.v.x[i], b.v.y[i], b.v.z[i], b.w.x[i], b.w.y[i], b.w.z[i]}) {
      if (!std::isfinite(x)) return ::testing::AssertionFailure() << "v or w of body " << i << " is " << x;
    }
  }
  return ::testing::AssertionSuccess();
}

/// The models that fit a scene shaped for `fit`, cheapest first.
inline std::vector<Model> models_for(Model fit) {
  switch (fit) {
    case Model::particle:
      return {Model::particle, Model::sphere, Model::rigid};
    case Model::sphere:
      return {Model::sphere, Model::rigid};
    case Model::rigid:
      break;
  }
  return {Model::rigid};
}

/// Checks the caller adds for a family: given the input scene, one model's
/// kernel result and the reference.
template <class T>
using ExtraCheck = std::function<void(const Scene<T>&, const Outcome<T>&, const Reference&)>;

/// One row of the figures: family, precision, model, errors.
inline void report(const std::string& family, const char* precision, Model model, const ErrorStats& st) {
  std::ostringstream line;
  line << std::fixed << std::setprecision(2) << "[hard] " << std::left << std::setw(22) << family << " " << std::setw(6)
       << precision << " " << std::setw(8) << to_string(model) << " max " << std::setw(10)
       << static_cast<double>(st.max) << " p99 " << std::setw(8) << static_cast<double>(st.p99) << " (" << st.acting
       << "/" << st.count << " contacts act)";
  std::cout << line.str() << std::endl;
  std::string key = family + "_" + precision + "_" + to_string(model);
  ::testing::Test::RecordProperty(key + "_max", std::to_string(static_cast<double>(st.max)));
}

/// Runs `scene` (shaped for `fit`) through every model that fits it, on both
/// paths, and applies the checks above plus `extra`. `start` is the body
/// state the kernel starts from (normally scene.bodies; a test may have
/// poisoned fields the law says to ignore). `min_acting` is how many
/// contacts must receive an impulse in the reference, so that a family that
/// degenerated into nothing fails.
template <class T>
void run_scene(const std::string& family, const Scene<T>& scene, const BodyBuffer<T>& start, Model fit,
               std::size_t min_acting, const ExtraCheck<T>& extra = nullptr, L target = test::kErrorTargetEps) {
  const char* precision = test::type_name<T>();
  SCOPED_TRACE(family + " " + precision + " " + to_string(fit));
  BodyBuffer<T> probe = start;
  ASSERT_EQ(choose_model(probe.view(), scene.contacts.view()), fit) << "the scene is not shaped for its fit";

  Scene<T> ref_input{start, scene.contacts};
  const Reference ref = reference_of(ref_input);
  for (const Model model : models_for(fit)) {
    SCOPED_TRACE(to_string(model));
    ASSERT_EQ(model_misfit(model, probe.view(), scene.contacts.view()), "");
    const Outcome<T> simd = kernel_result(scene, start, model, test::options_for(Path::simd));
    const Outcome<T> scalar = kernel_result(scene, start, model, test::options_for(Path::scalar));
    EXPECT_TRUE(test::same_bodies(simd.bodies, scalar.bodies));
    EXPECT_TRUE(test::same_impulses(simd.j, scalar.j));
    EXPECT_TRUE(all_finite(simd));
    const ErrorStats st = error_stats(simd.j, ref);
    report(family, precision, model, st);
    EXPECT_EQ(st.over, 0u) << st.over << " contacts over the bound; worst contact " << st.worst << " at "
                           << static_cast<double>(st.max) << " eps * impulse_scale";
    // The fast mode's target, tighter than the bound (collide/eval/error_bound.hpp).
    EXPECT_LE(st.max, target) << "worst contact " << st.worst << " at " << static_cast<double>(st.max)
                              << " eps * impulse_scale, above the target";
    EXPECT_GE(st.acting, min_acting) << "too few contacts act: the family degenerated";
    if (extra) extra(scene, simd, ref);
  }
}

template <class T>
void run_scene(const std::string& family, const Scene<T>& scene, Model fit, std::size_t min_acting,
               const ExtraCheck<T>& extra = nullptr, L target = test::kErrorTargetEps) {
  run_scene(family, scene, scene.bodies, fit, min_acting, extra, target);
}

// ---------------------------------------------------------------------------
// Mechanics in long double from stored values, for the invariants.
// ---------------------------------------------------------------------------

/// Kinetic energy of body i: (m v.v + w . R diag(I) R^T w) / 2, with m = 1/inv_mass
/// and I = 1/inv_inertia; an axis with inverse moment 0 contributes nothing
/// (its w component is 0 in every scene that has one: particle bodies).
template <class T>
L kinetic_energy(const BodyView<const T>& b, std::size_t i) {
  if (b.inv_mass[i] == T(0)) return 0;
  const L v2 = L(b.v.x[i]) * b.v.x[i] + L(b.v.y[i]) * b.v.y[i] + L(b.v.z[i]) * b.v.z[i];
  L e = v2 / L(b.inv_mass[i]);
  const L qw = b.q.w[i], qx = b.q.x[i], qy = b.q.y[i], qz = b.q.z[i];
  const L s = 2 / (qw * qw + qx * qx + qy * qy + qz * qz);
  const L r[3][3] = {{1 - s * (qy * qy + qz * qz), s * (qx * qy - qw * qz), s * (qx * qz + qw * qy)},
                     {s * (qx * qy + qw * qz), 1 - s * (qx * qx + qz * qz), s * (qy * qz - qw * qx)},
                     {s * (qx * qz - qw * qy), s * (qy * qz + qw * qx), 1 - s * (qx * qx + qy * qy)}};
  const L w[3] = {b.w.x[i], b.w.y[i], b.w.z[i]};
  const T inv[3] = {b.inv_inertia.x[i], b.inv_inertia.y[i], b.inv_inertia.z[i]};
  for (int a = 0; a < 3; ++a) {
    const L wb = r[0][a] * w[0] + r[1][a] * w[1] + r[2][a] * w[2];  // body-frame component
    if (inv[a] != T(0)) e += wb * wb / L(inv[a]);
  }
  return e / 2;
}

/// Momentum m v of body i (0 for an immovable body).
template <class T>
std::array<L, 3> momentum(const BodyView<const T>& b, std::size_t i) {
  if (b.inv_mass[i] == T(0)) return {0, 0, 0};
  const L m = 1 / L(b.inv_mass[i]);
  return {m * b.v.x[i], m * b.v.y[i], m * b.v.z[i]};
}

/// |v| + |w| |r| of a body at contact point c: its share of the speed scale.
template <class T>
L speed_share(const BodyView<const T>& b, std::size_t i, const ContactView<T>& c, std::size_t k) {
  const L r[3] = {L(c.c.x[k]) - b.p.x[i], L(c.c.y[k]) - b.p.y[i], L(c.c.z[k]) - b.p.z[i]};
  const L v = std::sqrt(L(b.v.x[i]) * b.v.x[i] + L(b.v.y[i]) * b.v.y[i] + L(b.v.z[i]) * b.v.z[i]);
  const L w = std::sqrt(L(b.w.x[i]) * b.w.x[i] + L(b.w.y[i]) * b.w.y[i] + L(b.w.z[i]) * b.w.z[i]);
  return v + w * std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
}

/// Conservation over a group of bodies that only meet each other (no
/// immovable body among their contacts): total momentum unchanged and
/// kinetic energy not increased (or unchanged, `elastic`), within rounding.
///
/// Tolerance. Each contact rounds each velocity it writes (a few eps of the
/// body's speeds) and carries an impulse error of at most C eps s_k (the
/// bound), which moves the momentum by at most twice that and the energy by
/// at most that times the relative speed it acts against (<= S + S'). So,
/// with n_i the contacts of body i:
///   |dP| <= 8 eps sum_i n_i m_i (|v_i| + |v_i'|) + 2 C eps sum_k s_k
///   dE   <= 8 eps sum_i n_i (E_i + E_i') + C eps sum_k s_k (S_k + S_k')
template <class T>
void expect_conserved(const Scene<T>& in, const Outcome<T>& out, const Reference& ref,
                      const std::vector<std::size_t>& bodies, const std::vector<std::size_t>& contacts, bool elastic) {
  const L eps = std::numeric_limits<T>::epsilon();
  const L c_bound = test::kErrorBoundEps;
  const BodyView<const T> b0 = in.bodies.view();
  const BodyView<const T> b1 = out.bodies.view();
  const ContactView<T> c = in.contacts.view();
  std::vector<std::size_t> uses(b0.count, 0);
  L impulse_part = 0, energy_part = 0;
  for (const std::size_t k : contacts) {
    ++uses[c.a[k]];
    ++uses[c.b[k]];
    const L s = ref.diag[k].impulse_scale;
    impulse_part += 2 * c_bound * eps * s;
    const L speeds = speed_share(b0, c.a[k], c, k) + speed_share(b0, c.b[k], c, k) + speed_share(b1, c.a[k], c, k) +
                     speed_share(b1, c.b[k], c, k);
    energy_part += c_bound * eps * s * speeds;
  }
  std::array<L, 3> p0{}, p1{};
  L e0 = 0, e1 = 0, p_scale = 0, e_scale = 0;
  for (const std::size_t i : bodies) {
    const auto m0 = momentum(b0, i), m1 = momentum(b1, i);
    for (int x = 0; x < 3; ++x) {
      p0[x] += m0[x];
      p1[x] += m1[x];
    }
    const L k0 = kinetic_energy(b0, i), k1 = kinetic_energy(b1, i);
    e0 += k0;
    e1 += k1;
    const L n = static_cast<L>(uses[i]);
    p_scale += n * (std::sqrt(m0[0] * m0[0] + m0[1] * m0[1] + m0[2] * m0[2]) +
                    std::sqrt(m1[0] * m1[0] + m1[1] * m1[1] + m1[2] * m1[2]));
    e_scale += n * (k0 + k1);
  }
  const L dp = std::sqrt((p1[0] - p0[0]) * (p1[0] - p0[0]) + (p1[1] - p0[1]) * (p1[1] - p0[1]) +
                         (p1[2] - p0[2]) * (p1[2] - p0[2]));
  const L p_tol = 8 * eps * p_scale + impulse_part;
  const L e_tol = 8 * eps * e_scale + energy_part;
  EXPECT_LE(dp, p_tol) << "momentum changed by " << static_cast<double>(dp);
  EXPECT_LE(e1 - e0, e_tol) << "energy grew from " << static_cast<double>(e0) << " to " << static_cast<double>(e1);
  if (elastic) {
    EXPECT_LE(std::abs(e1 - e0), e_tol) << "elastic contacts changed the energy from " << static_cast<double>(e0)
                                        << " to " << static_cast<double>(e1);
  }
}

}  // namespace collide::hard
