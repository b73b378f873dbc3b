// test_accuracy.cpp - the local-frame kernel against the world-frame
// reference (contact_kernel.hpp vs reference.cpp), and the numbers the
// documentation quotes.
//
// What this proves
// ----------------
// For float and double, scalar and SIMD paths, on pairs scenes (100k
// independent contacts) and shared-body scenes (40k contacts over 20k bodies
// plus an immovable ground, contacts chained through shared bodies), with and
// without friction, e uniform in [0, 1], every contact satisfies
//     |J - Jref| <= kImpulseErrorBoundEps * eps(T) * scale
// where Jref is collide::reference_solve<long double> on
// convert_scene<long double>(scene) - an exact copy of the kernel's inputs,
// applied in input order - and `scale` is the reference's
// ReferenceContact::impulse_scale (defined for every contact with a movable
// body, approaching or not, so a kernel that acts on a rounding-level vn is
// still held to a rounding-level impulse).
// Each run prints (and records as test properties) the largest, 99th
// percentile and median of |J - Jref| / (eps(T) * impulse_scale), so the docs
// can quote the observed error next to the bound.
// FrictionOnLongAnisotropicLeverArm pins one contact (found by scanning 1e6
// random pairs with lever arms up to 20 m) on which a friction scale without
// the conditioning factor (1 + |W t| / K(t)) of reference.hpp was exceeded by
// the kernel (87 eps) and by the world-frame reference evaluated in double
// (128 eps) alike: it guards that factor.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

struct ErrorStats {
  long double max = 0, p99 = 0, median = 0;  // in units of eps * impulse_scale
  std::size_t worst = 0, acting = 0;
  std::size_t over = 0;  // contacts over the bound
};

template <class T>
ErrorStats measure(const ImpulseBuffer<T>& j, const ImpulseBuffer<long double>& jr,
                   const std::vector<ReferenceContact<long double>>& diag) {
  const long double eps = std::numeric_limits<T>::epsilon();
  const auto a = j.view();
  const ImpulseView<const long double> r = jr.view();
  std::vector<long double> errs(j.size());
  ErrorStats st;
  for (std::size_t k = 0; k < j.size(); ++k) {
    const long double dx = a.j.x[k] - r.j.x[k], dy = a.j.y[k] - r.j.y[k], dz = a.j.z[k] - r.j.z[k];
    const long double err = std::sqrt(dx * dx + dy * dy + dz * dz);
    const ReferenceContact<long double>& d = diag[k];
    st.acting += d.jn > 0;
    errs[k] = err == 0 ? 0 : err / (eps * d.impulse_scale);
    if (errs[k] > st.max) {
      st.max = errs[k];
      st.worst = k;
    }
    st.over += errs[k] > kErrorBoundEps;
  }
  auto nth = [&](double q) {
    const auto pos = static_cast<std::ptrdiff_t>(q * static_cast<double>(errs.size() - 1));
    std::nth_element(errs.begin(), errs.begin() + pos, errs.end());
    return errs[static_cast<std::size_t>(pos)];
  };
  st.p99 = nth(0.99);
  st.median = nth(0.5);
  return st;
}

template <class T>
void check_accuracy(bool shared, bool friction) {
  SceneOptions o;
  o.seed = shared ? 4242 : 2424;
  o.friction = friction;
  const Scene<T> scene = shared ? shared_scene<T>(40000, 20000, o) : pairs_scene<T>(100000, o);
  Scene<long double> ref = convert_scene<long double>(scene);
  std::vector<ReferenceContact<long double>> diag;
  const ImpulseBuffer<long double> jr = reference(ref.bodies, ref.contacts.view(), &diag);

  for (const Path path : {Path::scalar, Path::simd}) {
    const std::string label = std::string(type_name<T>()) + " " + to_string(path) + " " +
                              (shared ? "shared" : "pairs") + (friction ? " friction" : " frictionless");
    SCOPED_TRACE(label);
    BodyBuffer<T> bodies = scene.bodies;
    const ImpulseBuffer<T> j = kernel_solve(bodies, scene.contacts.view(), options_for(path, 2, 512));
    const ErrorStats st = measure(j, jr, diag);
    std::ostringstream line;
    line << std::fixed << std::setprecision(2) << "[accuracy] " << std::left << std::setw(30) << label << " max "
         << std::setw(6) << static_cast<double>(st.max) << " p99 " << static_cast<double>(st.p99) << " median "
         << static_cast<double>(st.median) << " eps*impulse_scale";
    line << " (bound " << static_cast<double>(kErrorBoundEps) << "; " << st.acting << "/" << j.size()
         << " contacts act)";
    std::cout << line.str() << std::endl;
    std::string key = label;
    for (char& c : key) c = c == ' ' ? '_' : c;
    ::testing::Test::RecordProperty(key + "_max", std::to_string(static_cast<double>(st.max)));
    ::testing::Test::RecordProperty(key + "_p99", std::to_string(static_cast<double>(st.p99)));
    EXPECT_EQ(st.over, 0u) << "worst contact " << st.worst << " at " << static_cast<double>(st.max) << " eps";
    // The scenes are not degenerate: most contacts act.
    EXPECT_GT(st.acting, j.size() / 2);
    // The bound is not vacuous either: the kernel does round.
    EXPECT_GT(st.max, 0.01L);
  }
}

// A single contact found by scanning 1e6 random pairs with lever arms up to
// 20 m: body b is 22 m from the contact point with a small moment about one
// axis, so K(n) = 187 while K(t) = 15 and the friction step sticks
// (jt = |ut| / K(t)). The values are the stored ones (inverse mass and
// moments, q and n exactly as the kernel reads them). Without the
// conditioning factor of the friction scale the double kernel was 87 eps off
// and the world-frame reference evaluated in double 128 eps; with it both
// must be well inside the bound.
TEST(Accuracy, FrictionOnLongAnisotropicLeverArm) {
  const double bodies[2][17] = {
      {0.12258610978758541, 0.063971991685586427, 0.091517927502098945, 0.08918727220685578, -0.76978406383912934,
       0.24285227984456831, 0.58240479827812686, -0.096228458245080153, 4.3975258672415958, -4.8520969052734184,
       2.8330270951486685, 0.34707955952302427, -3.7241053356185061, 1.7998962066793069, 1.3881903396020103,
       -4.6634667178907856, -0.42646928178137777},
      {0.56796567300129208, 0.38329201153922859, 5.5711018750018368, 0.72576927967618521, -0.34934011709518142,
       -0.63637127440302999, -0.59721426225901075, -0.34106921388042966, 4.0779520986969686, -0.67192347138159203,
       21.500947367818199, -2.076798019030373, 3.2433576190505775, 3.3080799018303058, -3.705008169388484,
       -1.0221211753649651, -1.8580626927425321}};
  // c, n, e, mu as stored.
  const double contact[8] = {4.5857019284124849,   -4.3553122442937493, 2.4149403327681416,  0.87020099725176314,
                             -0.45775760125772946, 0.18223117974925873, 0.84605700747727375, 0.82144756473549507};
  Scene<double> scene;
  scene.bodies.resize(2);
  const BodyView<double> bv = scene.bodies.view();
  double* fields[17] = {bv.inv_mass, bv.inv_inertia.x, bv.inv_inertia.y, bv.inv_inertia.z, bv.q.w, bv.q.x,
                        bv.q.y,      bv.q.z,           bv.p.x,           bv.p.y,           bv.p.z, bv.v.x,
                        bv.v.y,      bv.v.z,           bv.w.x,           bv.w.y,           bv.w.z};
  for (int i = 0; i < 2; ++i) {
    for (int f = 0; f < 17; ++f) fields[f][i] = bodies[i][f];
  }
  ContactRecord<double> r;
  r.a = 0;
  r.b = 1;
  r.mu = contact[7];
  scene.contacts.push_back(r);
  const ContactView<double> cv = scene.contacts.view();
  const double* targets[7] = {cv.c.x, cv.c.y, cv.c.z, cv.n.x, cv.n.y, cv.n.z, cv.e};
  for (int f = 0; f < 7; ++f) const_cast<double*>(targets[f])[0] = contact[f];  // bypass renormalisation
  ASSERT_NE(cv.mu, nullptr);

  Scene<long double> ref = convert_scene<long double>(scene);
  const ContactView<long double> rv = ref.contacts.view();
  std::vector<ReferenceContact<long double>> diag;
  const ImpulseBuffer<long double> jr = reference(ref.bodies, rv, &diag);
  ASSERT_GT(diag[0].jt, 0);
  ASSERT_LT(diag[0].jt, contact[7] * diag[0].jn);  // sticking
  const long double eps = std::numeric_limits<double>::epsilon();
  auto errors = [&](const ImpulseBuffer<double>& j) {
    const long double dx = j.view().j.x[0] - jr.view().j.x[0], dy = j.view().j.y[0] - jr.view().j.y[0],
                      dz = j.view().j.z[0] - jr.view().j.z[0];
    const long double err = std::sqrt(dx * dx + dy * dy + dz * dz);
    return err / (eps * diag[0].impulse_scale);
  };
  for (const Path path : {Path::scalar, Path::simd}) {
    BodyBuffer<double> kb = scene.bodies;
    const long double err = errors(kernel_solve(kb, cv, options_for(path, 1)));
    std::cout << "[accuracy] long lever arm, kernel " << to_string(path) << ": " << static_cast<double>(err)
              << " eps*impulse_scale" << std::endl;
    EXPECT_LE(err, kErrorBoundEps);
  }
  BodyBuffer<double> rb = scene.bodies;
  const long double err = errors(reference(rb, cv));
  std::cout << "[accuracy] long lever arm, reference<double>: " << static_cast<double>(err) << " eps*impulse_scale"
            << std::endl;
  EXPECT_LE(err, kErrorBoundEps);
}

TEST(Accuracy, FloatPairs) { check_accuracy<float>(false, false); }
TEST(Accuracy, FloatPairsFriction) { check_accuracy<float>(false, true); }
TEST(Accuracy, FloatShared) { check_accuracy<float>(true, false); }
TEST(Accuracy, FloatSharedFriction) { check_accuracy<float>(true, true); }
TEST(Accuracy, DoublePairs) { check_accuracy<double>(false, false); }
TEST(Accuracy, DoublePairsFriction) { check_accuracy<double>(false, true); }
TEST(Accuracy, DoubleShared) { check_accuracy<double>(true, false); }
TEST(Accuracy, DoubleSharedFriction) { check_accuracy<double>(true, true); }

}  // namespace
}  // namespace collide::test
