// test_hard_accurate.cpp - the accurate mode (collide::Accuracy::accurate) on
// every hard family.
//
// What this proves
// ----------------
// For every single-contact family of collide/eval/hard_scenes.hpp (mass ratios 1e+-8,
// immovable bodies, needles with moment ratios 1e-12, levers 1e4, grazing
// vn/|u| down to 1e-7, unit scales, subnormal speeds, separating/resting,
// e = 0 and 1, stick/slip, spin-dominated) and the shared-body scenes
// (cradles, stars, a dense cluster), in float and double, through every
// model that fits:
// * the plain relative error of J is within kAccurateUlps ulps of the exact
//   law on every contact: |J - Jref| <= 8 eps(T) |Jref| + denorm_min(T)
//   (the floor is the spacing of subnormal results; Jref = 0 demands J = 0
//   up to it), Jref from reference_solve in __float128 for double (long
//   double's 64-bit significand is too short: a grazing contact turns its
//   5e-20 into 5e-13) and in long double for float. For shared-body scenes
//   the law is applied to the velocities as stored before each contact
//   (chain_ulp_errors);
// * the SIMD and scalar paths, and 1 and 2 threads with a small block, give
//   identical bytes;
// * the fast mode on the same scene is printed beside it, and for grazing
//   contacts the fast mode really is far outside the target (so the family
//   tests what it claims);
// * the same holds on the caller's own values: families whose normals are
//   unit only within the input tolerance and whose quaternions are not unit
//   at all (off_unit_directions), judged against the exact law on exactly
//   those values, through the library and through `collide solve`; and a
//   normal rounded to unit length in T before the law (what a reader that
//   normalised on storing did) is far outside the target there.
// The "[accurate]" lines are the figures of docs/decisions/0007-the-accurate-mode.md.
#include <cmath>
#include <cstddef>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/check.hpp"
#include "collide/io/scene_io.hpp"
#include "hard/hard_check.hpp"
#if defined(COLLIDE_CLI_PATH)
#include <charconv>
#include <filesystem>

#include "support/run_cli.hpp"
#endif

#if !COLLIDE_HAS_FLOAT128
#error "test_hard_accurate judges double against the __float128 reference (GCC on x86-64)"
#endif

namespace collide::hard {
namespace {

constexpr std::size_t kCount = 1000;
constexpr double kAccurateUlps = kAccurateErrorUlps;
using Q = __float128;

/// The reference precision that can judge T's accurate mode.
template <class T>
using Judge = std::conditional_t<std::is_same_v<T, float>, long double, Q>;

template <class S>
S q_sqrt(S x) {
  if constexpr (std::is_same_v<S, Q>) {
    // Newton on the long double root: 113 bits in two steps.
    S y = static_cast<S>(std::sqrt(static_cast<long double>(x)));
    if (y == 0) return 0;
    y = (y + x / y) / 2;
    return (y + x / y) / 2;
  } else {
    return std::sqrt(x);
  }
}

/// Plain relative error of every contact's J, in ulps of T (eps(T) |Jref|,
/// plus denorm_min(T)).
template <class T>
struct UlpStats {
  double max = 0;
  std::size_t worst = 0;
  std::size_t acting = 0;
};

template <class T>
UlpStats<T> ulp_errors(const ImpulseBuffer<T>& j, const ImpulseBuffer<Judge<T>>& ref) {
  using S = Judge<T>;
  UlpStats<T> st;
  const auto a = j.view();
  const auto r = ref.view();
  for (std::size_t k = 0; k < j.size(); ++k) {
    const S dx = S(a.j.x[k]) - r.j.x[k], dy = S(a.j.y[k]) - r.j.y[k], dz = S(a.j.z[k]) - r.j.z[k];
    const S err = q_sqrt(dx * dx + dy * dy + dz * dz);
    const S mag = q_sqrt(r.j.x[k] * r.j.x[k] + r.j.y[k] * r.j.y[k] + r.j.z[k] * r.j.z[k]);
    st.acting += mag > 0;
    const S unit = S(std::numeric_limits<T>::epsilon()) * mag + S(std::numeric_limits<T>::denorm_min());
    const double ulps = static_cast<double>(err / unit);
    if (!(ulps <= st.max)) {
      st.max = ulps;
      st.worst = k;
    }
  }
  return st;
}

template <class T>
SolverOptions accurate_options(Path path, int threads = 1, std::size_t block = 4096) {
  SolverOptions o = test::options_for(path, threads, block);
  o.accuracy = Accuracy::accurate;
  return o;
}

/// Shared-body scenes: each contact against the exact law applied to the
/// velocities as stored before it. The bodies' state between contacts is
/// stored in T (the law is applied contact by contact to stored velocities),
/// so a chain's later contacts inherit the rounding of that state; the
/// promise is about each contact's own evaluation. The state before contact
/// k is reproduced by solving the contacts one at a time, which must give
/// exactly the bytes of the full solve (a contact's result depends only on
/// its two bodies' stored values).
template <class T>
UlpStats<T> chain_ulp_errors(const Scene<T>& scene, Model model, const Outcome<T>& full) {
  using S = Judge<T>;
  UlpStats<T> st;
  BodyBuffer<T> state = scene.bodies;
  ImpulseBuffer<T> j(scene.contacts.size());
  const Solver solver(accurate_options<T>(Path::scalar));
  const ContactView<T> all = scene.contacts.view();
  for (std::size_t k = 0; k < all.count; ++k) {
    const ContactView<T> one = contact_slice(all, k, 1);
    BodyBuffer<S> ref_bodies = convert_bodies<S>(std::as_const(state).view());
    const ContactBuffer<S> ref_contact = convert_contacts<S>(one);
    const ImpulseBuffer<S> ref = test::reference(ref_bodies, ref_contact.view());
    ImpulseBuffer<T> jk(1);
    Schedule schedule;
    schedule.build(one, state.view());
    solver.solve(model, state.view(), one, jk.view(), schedule);
    const UlpStats<T> e = ulp_errors(jk, ref);
    st.acting += e.acting;
    if (!(e.max <= st.max)) {
      st.max = e.max;
      st.worst = k;
    }
    j.view().j.x[k] = jk.view().j.x[0];
    j.view().j.y[k] = jk.view().j.y[0];
    j.view().j.z[k] = jk.view().j.z[0];
  }
  EXPECT_TRUE(test::same_impulses(j, full.j)) << "contact-by-contact solve differs from the full solve";
  EXPECT_TRUE(test::same_bodies(state, full.bodies));
  return st;
}

/// Runs `scene` in the accurate mode through every model that fits `fit`;
/// returns the fast mode's worst figure (for the caller's own checks).
template <class T>
double run_accurate(const std::string& family, const Scene<T>& scene, Model fit, bool chain = false) {
  const char* precision = test::type_name<T>();
  SCOPED_TRACE(family + " " + precision + " " + to_string(fit));
  Scene<Judge<T>> judge_scene = convert_scene<Judge<T>>(scene);
  const ImpulseBuffer<Judge<T>> ref = test::reference(judge_scene.bodies, judge_scene.contacts.view());
  double fast_worst = 0;
  for (const Model model : models_for(fit)) {
    SCOPED_TRACE(to_string(model));
    const Outcome<T> simd = kernel_result(scene, scene.bodies, model, accurate_options<T>(Path::simd));
    const Outcome<T> scalar = kernel_result(scene, scene.bodies, model, accurate_options<T>(Path::scalar));
    const Outcome<T> threaded = kernel_result(scene, scene.bodies, model, accurate_options<T>(Path::simd, 2, 64));
    EXPECT_TRUE(test::same_bodies(simd.bodies, scalar.bodies));
    EXPECT_TRUE(test::same_impulses(simd.j, scalar.j));
    EXPECT_TRUE(test::same_bodies(simd.bodies, threaded.bodies));
    EXPECT_TRUE(test::same_impulses(simd.j, threaded.j));
    EXPECT_TRUE(all_finite(simd));
    const UlpStats<T> acc = chain ? chain_ulp_errors(scene, model, simd) : ulp_errors(simd.j, ref);
    const Outcome<T> fast = kernel_result(scene, scene.bodies, model, test::options_for(Path::simd));
    const UlpStats<T> fst = ulp_errors(fast.j, ref);
    fast_worst = std::max(fast_worst, fst.max);
    std::ostringstream line;
    line << std::setprecision(3) << "[accurate] " << std::left << std::setw(20) << family << " " << std::setw(6)
         << precision << " " << std::setw(8) << to_string(model) << " accurate max " << std::setw(8) << acc.max
         << " ulps   fast max " << std::setw(10) << fst.max << " ulps (" << acc.acting << "/" << scene.contacts.size()
         << " act)";
    std::cout << line.str() << std::endl;
    EXPECT_LE(acc.max, kAccurateUlps) << "worst contact " << acc.worst;
  }
  return fast_worst;
}

template <class Run>
void each(const std::vector<Model>& fits, const Run& run) {
  for (const Model fit : fits) {
    run(float{}, fit);
    run(double{}, fit);
  }
}

const std::vector<Model> kAllFits = {Model::particle, Model::sphere, Model::rigid};
const std::vector<Model> kRotatingFits = {Model::sphere, Model::rigid};

TEST(HardAccurate, MassRatios) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("mass-ratio", mass_ratio_family<T>(kCount, fit, 11).scene(), fit);
  });
}

TEST(HardAccurate, Immovable) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("immovable", immovable_family<T>(kCount, fit, 12).scene(), fit);
  });
}

TEST(HardAccurate, Needles) {
  run_accurate<float>("needle", needle_family<float>(kCount, 13).scene(), Model::rigid);
  run_accurate<double>("needle", needle_family<double>(kCount, 13).scene(), Model::rigid);
}

TEST(HardAccurate, LongLevers) {
  each(kRotatingFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("long-lever", long_lever_family<T>(kCount, fit, 14).scene(), fit);
  });
}

TEST(HardAccurate, Grazing) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    const double fast = run_accurate<T>("grazing", grazing_family<T>(kCount, fit, 15).scene(), fit);
    // The family is what the accurate mode is for: the fast mode's plain
    // relative error there is orders of magnitude above the target.
    EXPECT_GT(fast, 1000 * kAccurateUlps);
  });
}

TEST(HardAccurate, UnitScales) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("unit-scales", unit_scale_family<T>(kCount, fit, 16).scene(), fit);
  });
}

TEST(HardAccurate, SubnormalSpeedsInFloat) {
  for (const Model fit : kAllFits) {
    run_accurate<float>("subnormal", subnormal_family<float>(kCount, fit, 17).scene(), fit);
  }
}

TEST(HardAccurate, SeparatingRestingRestitutionStickSlipSpin) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("separating-resting", separating_resting_family<T>(kCount, fit, 18).scene(), fit);
    run_accurate<T>("e-0-and-1", restitution_family<T>(kCount, fit, 19).scene(), fit);
    run_accurate<T>("stick-slip", stick_slip_family<T>(kCount, fit, 20).scene(), fit);
  });
  each(kRotatingFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    run_accurate<T>("spin-dominated", spin_family<T>(kCount, fit, 21).scene(), fit);
  });
}

TEST(HardAccurate, SharedBodies) {
  auto run = [](auto zero) {
    using T = decltype(zero);
    const V3 axis = {1, 0, 0};
    run_accurate<T>("cradle", cradle_scene<T>(20, axis, true, true, false, 32).scene(), Model::particle, true);
    run_accurate<T>("cradle-mixed", cradle_scene<T>(20, axis, false, false, true, 33).scene(), Model::particle, true);
    for (const Model fit : kAllFits) {
      run_accurate<T>("star", star_scene<T>(1000, false, fit, 34).scene(), fit, true);
      run_accurate<T>("cluster", cluster_scene<T>(80, 1.0, fit, 35).scene(), fit, true);
    }
  };
  run(float{});
  run(double{});
}

// ---------------------------------------------------------------------------
// The caller's own values: n unit only within tolerance, q not unit.
// ---------------------------------------------------------------------------

/// The single-contact families of the target, as a caller might hand them
/// over (off_unit_directions), for `fit`.
template <class T>
std::vector<std::pair<std::string, SceneRecords<T>>> off_unit_families(Model fit) {
  std::vector<std::pair<std::string, SceneRecords<T>>> f;
  f.emplace_back("grazing", off_unit_directions(grazing_family<T>(kCount, fit, 15), 41));
  f.emplace_back("mass-ratio", off_unit_directions(mass_ratio_family<T>(kCount, fit, 11), 42));
  f.emplace_back("unit-scales", off_unit_directions(unit_scale_family<T>(kCount, fit, 16), 43));
  f.emplace_back("stick-slip", off_unit_directions(stick_slip_family<T>(kCount, fit, 20), 44));
  if (fit != Model::particle) {
    f.emplace_back("long-lever", off_unit_directions(long_lever_family<T>(kCount, fit, 14), 45));
  }
  if (fit == Model::rigid) f.emplace_back("needle", off_unit_directions(needle_family<T>(kCount, 13), 46));
  return f;
}

/// Largest | |n| - 1 | and | |q| - 1 | of a scene, in long double.
template <class T>
std::pair<long double, long double> off_unit_extent(const SceneRecords<T>& r) {
  long double n_off = 0, q_off = 0;
  for (const ContactRecord<T>& c : r.contacts) {
    const long double x = c.n[0], y = c.n[1], z = c.n[2];
    n_off = std::max(n_off, std::fabs(std::sqrt(x * x + y * y + z * z) - 1));
  }
  for (const BodyRecord<T>& b : r.bodies) {
    const long double w = b.q[0], x = b.q[1], y = b.q[2], z = b.q[3];
    q_off = std::max(q_off, std::fabs(std::sqrt(w * w + x * x + y * y + z * z) - 1));
  }
  return {n_off, q_off};
}

/// The scene with every normal rounded to unit length in T before the law
/// sees it: what the accurate mode got when the reader normalised n on
/// storing it.
template <class T>
Scene<T> with_normals_rounded(const SceneRecords<T>& r) {
  SceneRecords<T> rounded = r;
  for (ContactRecord<T>& c : rounded.contacts) {
    const T len = std::sqrt(c.n[0] * c.n[0] + c.n[1] * c.n[1] + c.n[2] * c.n[2]);
    for (T& x : c.n) x /= len;
  }
  return rounded.scene();
}

TEST(HardAccurate, CallersValuesOffUnit) {
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    for (const auto& [family, records] : off_unit_families<T>(fit)) {
      const auto [n_off, q_off] = off_unit_extent(records);
      // The scene is what it claims: normals off by up to the tolerance,
      // quaternions far from unit.
      EXPECT_GT(n_off, 5e-4L) << family;
      EXPECT_LE(n_off, 1e-3L) << family;
      EXPECT_GT(q_off, 0.4L) << family;
      run_accurate<T>(family + "-off-unit", records.scene(), fit);
      if (family == "grazing") {
        // Rounding n to unit length in T first moves vn by |u| eps, orders
        // of magnitude beyond the target on the flattest contacts.
        const Scene<T> rounded = with_normals_rounded(records);
        Scene<Judge<T>> exact = convert_scene<Judge<T>>(records.scene());
        const ImpulseBuffer<Judge<T>> ref = test::reference(exact.bodies, exact.contacts.view());
        const Outcome<T> off = kernel_result(rounded, rounded.bodies, fit, accurate_options<T>(Path::simd));
        EXPECT_GT(ulp_errors(off.j, ref).max, 1000 * kAccurateUlps);
      }
    }
  });
}

#if defined(COLLIDE_CLI_PATH)
/// Reads an impulses file into T triples (the header checked).
template <class T>
std::vector<std::array<T, 3>> read_impulse_rows(const std::string& path) {
  const std::string text = read_file(path);
  std::vector<std::array<T, 3>> rows;
  std::size_t pos = text.find('\n');
  EXPECT_EQ(text.substr(0, pos + 1), impulses_header());
  while (pos != std::string::npos && pos + 1 < text.size()) {
    std::array<T, 3> row{};
    const char* p = text.data() + pos + 1;
    const char* end = text.data() + text.size();
    for (int k = 0; k < 3; ++k) {
      const auto [ptr, ec] = std::from_chars(p, end, row[k]);
      EXPECT_EQ(ec, std::errc()) << "row " << rows.size();
      p = ptr + 1;  // past ',' or '\n'
    }
    rows.push_back(row);
    pos = static_cast<std::size_t>(p - text.data()) - 1;
  }
  return rows;
}

/// `collide solve --accuracy accurate` on the off-unit families written as
/// scene files (shortest round-trip text, so the file holds exactly the
/// records' values): J within the target of the exact law on those values.
TEST(HardAccurate, CliOnCallersValuesOffUnit) {
  namespace fs = std::filesystem;
  each(kAllFits, [](auto zero, Model fit) {
    using T = decltype(zero);
    for (const auto& [family, records] : off_unit_families<T>(fit)) {
      const std::string precision = test::type_name<T>();
      SCOPED_TRACE(std::string(family).append(" ").append(precision).append(" ").append(to_string(fit)));
      const fs::path dir =
          fs::path(COLLIDE_TEST_TMP) /
          std::string("off-unit-").append(family).append("-").append(precision).append("-").append(to_string(fit));
      fs::create_directories(dir);
      BodyTable<T> table;
      for (const BodyRecord<T>& b : records.bodies) table.push_back(b);
      {
        OutputFile out((dir / "bodies.csv").string());
        write_body_table(out, table);
        out.commit();
      }
      std::string contacts(contacts_header());
      for (const ContactRecord<T>& c : records.contacts) append_contact_row(contacts, c);
      {
        OutputFile out((dir / "contacts.csv").string());
        out.write(contacts);
        out.commit();
      }
      const test::RunResult r = test::run_program(
          COLLIDE_CLI_PATH, dir,
          {"solve", "--bodies", (dir / "bodies.csv").string(), "--contacts", (dir / "contacts.csv").string(),
           "--out-bodies", (dir / "out-bodies.csv").string(), "--out-impulses", (dir / "out-impulses.csv").string(),
           "--precision", precision, "--accuracy", "accurate"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const auto rows = read_impulse_rows<T>((dir / "out-impulses.csv").string());
      ASSERT_EQ(rows.size(), records.contacts.size());
      ImpulseBuffer<T> j(rows.size());
      for (std::size_t k = 0; k < rows.size(); ++k) {
        j.view().j.x[k] = rows[k][0];
        j.view().j.y[k] = rows[k][1];
        j.view().j.z[k] = rows[k][2];
      }
      Scene<Judge<T>> exact = convert_scene<Judge<T>>(records.scene());
      const ImpulseBuffer<Judge<T>> ref = test::reference(exact.bodies, exact.contacts.view());
      const UlpStats<T> st = ulp_errors(j, ref);
      std::cout << "[accurate-cli] " << family << " " << precision << " " << to_string(fit) << " max " << st.max
                << " ulps" << std::endl;
      EXPECT_LE(st.max, kAccurateUlps) << "worst contact " << st.worst;
      fs::remove_all(dir);
    }
  });
}
#endif

}  // namespace
}  // namespace collide::hard
