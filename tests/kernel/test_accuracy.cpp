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
// applied in input order - and `scale` is:
//   * the reference's ReferenceContact::impulse_scale, for pairs scenes (with
//     and without friction) and frictionless shared scenes;
//   * for shared scenes with friction, impulse_scale with its friction term
//     widened by the conditioning of the friction step (see
//     friction_conditioned_scale below). With the plain impulse_scale the
//     largest error there is ~86 eps (float and double alike, and the
//     world-frame reference evaluated in double is as far off), so the plain
//     bound does not hold for friction with long, anisotropic lever arms; the
//     99th percentile must still be within the plain bound.
// For a contact the reference finds not approaching (possible in shared
// scenes, where earlier contacts change the velocities) the reference reports
// no impulse_scale; its normal scale 2 * speed_scale / K(n) is used instead,
// so a kernel that acts on a rounding-level vn is still held to a
// rounding-level impulse.
// Each run prints (and records as test properties) the largest, 99th
// percentile and median of |J - Jref| / (eps(T) * impulse_scale), so the docs
// can quote the observed error next to the bound.
// FrictionOnLongAnisotropicLeverArm pins one contact (found by scanning 1e6
// random pairs with lever arms up to 20 m) on which the plain bound fails for
// the kernel (87 eps) and for the double world-frame reference (128 eps)
// alike, while the conditioned scale holds with a wide margin.
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

#include "collide/reference.hpp"
#include "collide/scene.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

struct ErrorStats {
  long double max = 0, p99 = 0, median = 0;  // in units of eps * impulse_scale
  long double max_conditioned = 0;           // in units of eps * friction_conditioned_scale
  std::size_t worst = 0, acting = 0;
  std::size_t over = 0;              // contacts over the bound, plain scale
  std::size_t over_conditioned = 0;  // contacts over the bound, conditioned scale
};

/// |W t|, W the contact's compliance matrix (the velocity change of a's point
/// relative to b's per unit impulse): W t = (1/ma + 1/mb) t - ra x Iwa^-1 (ra x t)
/// - rb x Iwb^-1 (rb x t), in long double from the (static) body data.
long double compliance_times(const BodyView<const long double>& b, const ContactView<long double>& c, std::size_t k,
                             const Eigen::Matrix<long double, 3, 1>& t) {
  using V3 = Eigen::Matrix<long double, 3, 1>;
  const V3 cp(c.c.x[k], c.c.y[k], c.c.z[k]);
  V3 out = V3::Zero();
  for (const BodyIndex i : {c.a[k], c.b[k]}) {
    if (b.inv_mass[i] == 0) continue;
    const Eigen::Matrix<long double, 3, 3> r =
        Eigen::Quaternion<long double>(b.q.w[i], b.q.x[i], b.q.y[i], b.q.z[i]).normalized().toRotationMatrix();
    const V3 inv_i(b.inv_inertia.x[i], b.inv_inertia.y[i], b.inv_inertia.z[i]);
    const V3 arm = cp - V3(b.p.x[i], b.p.y[i], b.p.z[i]);
    out += b.inv_mass[i] * t - arm.cross(r * inv_i.asDiagonal() * r.transpose() * arm.cross(t));
  }
  return out.norm();
}

/// The impulse scale with a friction term that accounts for how the friction
/// step amplifies a rounding error du in u' (the relative velocity after the
/// normal impulse, |du| ~ eps * (speed_scale + speed_scale')):
///   * t = ut / |ut| turns by |du| / |ut|, and K(t) = t.W t moves by up to
///     2 |W t| |du| / |ut|, so jt = |ut| / K(t) (sticking) moves by
///     |du| / K(t) * (1 + 2 |W t| / K(t)); sliding (jt = mu jn < |ut| / K(t))
///     is no worse;
///   * u' itself is the sum of terms of size speed_scale (before) and
///     speed_scale' (after the normal impulse), both of which round.
/// So the friction term is (speed_scale + speed_scale') / K(t) * (1 + |W t| / K(t))
/// instead of speed_scale' / K(t). |W t| / K(t) is 1 for an isotropic
/// contact and reaches ~40 for a 20 m lever arm on a body with a small moment;
/// that is where the plain bound fails.
long double friction_conditioned_scale(const ReferenceContact<long double>& d, long double e, long double normal,
                                       const BodyView<const long double>& bodies,
                                       const ContactView<long double>& contacts, std::size_t k,
                                       const ImpulseView<const long double>& jref) {
  if (!(d.jt > 0)) return d.impulse_scale > 0 ? d.impulse_scale : normal;
  using V3 = Eigen::Matrix<long double, 3, 1>;
  const long double speed_after = (d.impulse_scale - (1 + e) * d.speed_scale / d.k_n) * d.k_t;
  const V3 n(contacts.n.x[k], contacts.n.y[k], contacts.n.z[k]);
  const V3 j(jref.j.x[k], jref.j.y[k], jref.j.z[k]);
  const V3 t = ((d.jn * n - j) / d.jt).normalized();  // Jref = jn n - jt t
  const long double wt = compliance_times(bodies, contacts, k, t);
  return normal + (d.speed_scale + speed_after) / d.k_t * (1 + wt / d.k_t);
}

template <class T>
ErrorStats measure(const ImpulseBuffer<T>& j, const ImpulseBuffer<long double>& jr,
                   const std::vector<ReferenceContact<long double>>& diag, const Scene<long double>& ref,
                   bool conditioned) {
  const long double eps = std::numeric_limits<T>::epsilon();
  const auto a = j.view();
  const ImpulseView<const long double> r = jr.view();
  const BodyView<const long double> bodies = ref.bodies.view();
  const ContactView<long double> contacts = ref.contacts.view();
  std::vector<long double> errs(j.size());
  ErrorStats st;
  for (std::size_t k = 0; k < j.size(); ++k) {
    const long double dx = a.j.x[k] - r.j.x[k], dy = a.j.y[k] - r.j.y[k], dz = a.j.z[k] - r.j.z[k];
    const long double err = std::sqrt(dx * dx + dy * dy + dz * dz);
    const ReferenceContact<long double>& d = diag[k];
    const long double e = contacts.e ? contacts.e[k] : contacts.uniform_e;
    const long double normal = (1 + e) * d.speed_scale / d.k_n;
    const long double scale = d.impulse_scale > 0 ? d.impulse_scale : 2 * d.speed_scale / d.k_n;
    st.acting += d.jn > 0;
    errs[k] = err == 0 ? 0 : err / (eps * scale);
    if (errs[k] > st.max) {
      st.max = errs[k];
      st.worst = k;
    }
    st.over += errs[k] > kErrorBoundEps;
    if (conditioned && err > 0) {
      const long double wide = friction_conditioned_scale(d, e, normal, bodies, contacts, k, r);
      const long double c = err / (eps * std::max(wide, scale));
      st.max_conditioned = std::max(st.max_conditioned, c);
      st.over_conditioned += c > kErrorBoundEps;
    }
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
  const bool conditioned = shared && friction;

  for (const Path path : {Path::scalar, Path::simd}) {
    const std::string label = std::string(type_name<T>()) + " " + to_string(path) + " " +
                              (shared ? "shared" : "pairs") + (friction ? " friction" : " frictionless");
    SCOPED_TRACE(label);
    BodyBuffer<T> bodies = scene.bodies;
    const ImpulseBuffer<T> j = kernel_solve(bodies, scene.contacts.view(), options_for(path, 2, 512));
    const ErrorStats st = measure(j, jr, diag, ref, conditioned);
    std::ostringstream line;
    line << std::fixed << std::setprecision(2) << "[accuracy] " << std::left << std::setw(30) << label << " max "
         << std::setw(6) << static_cast<double>(st.max) << " p99 " << static_cast<double>(st.p99) << " median "
         << static_cast<double>(st.median) << " eps*impulse_scale";
    if (conditioned) line << "; max " << static_cast<double>(st.max_conditioned) << " eps*conditioned_scale";
    line << " (bound " << static_cast<double>(kErrorBoundEps) << "; " << st.acting << "/" << j.size()
         << " contacts act)";
    std::cout << line.str() << std::endl;
    std::string key = label;
    for (char& c : key) c = c == ' ' ? '_' : c;
    ::testing::Test::RecordProperty(key + "_max", std::to_string(static_cast<double>(st.max)));
    ::testing::Test::RecordProperty(key + "_p99", std::to_string(static_cast<double>(st.p99)));
    if (conditioned) {
      ::testing::Test::RecordProperty(key + "_max_conditioned",
                                      std::to_string(static_cast<double>(st.max_conditioned)));
      EXPECT_EQ(st.over_conditioned, 0u) << "largest " << static_cast<double>(st.max_conditioned) << " eps";
      EXPECT_LE(st.p99, kErrorBoundEps);
    } else {
      EXPECT_EQ(st.over, 0u) << "worst contact " << st.worst << " at " << static_cast<double>(st.max) << " eps";
    }
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
// moments, q and n exactly as the kernel reads them). With the plain
// impulse_scale the double kernel is 87 eps off and the world-frame
// reference evaluated in double 128 eps; with the friction term conditioned
// as above both are well inside the bound.
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
    const long double e = rv.e[0];
    const long double wide = friction_conditioned_scale(diag[0], e, (1 + e) * diag[0].speed_scale / diag[0].k_n,
                                                        std::as_const(ref.bodies).view(), rv, 0, jr.view());
    return std::pair{err / (eps * diag[0].impulse_scale), err / (eps * wide)};
  };
  for (const Path path : {Path::scalar, Path::simd}) {
    BodyBuffer<double> kb = scene.bodies;
    const auto [plain, conditioned] = errors(kernel_solve(kb, cv, options_for(path, 1)));
    std::cout << "[accuracy] long lever arm, kernel " << to_string(path) << ": " << static_cast<double>(plain)
              << " eps*impulse_scale, " << static_cast<double>(conditioned) << " eps*conditioned_scale" << std::endl;
    EXPECT_LE(conditioned, kErrorBoundEps);
  }
  BodyBuffer<double> rb = scene.bodies;
  const auto [plain, conditioned] = errors(reference(rb, cv));
  std::cout << "[accuracy] long lever arm, reference<double>: " << static_cast<double>(plain) << " eps*impulse_scale, "
            << static_cast<double>(conditioned) << " eps*conditioned_scale" << std::endl;
  EXPECT_LE(conditioned, kErrorBoundEps);
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
