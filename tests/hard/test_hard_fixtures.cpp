// test_hard_fixtures.cpp - `collide solve`, the real executable, on the
// data/hard/ fixtures, in float and double.
//
// What this proves
// ----------------
// For every fixture directory (at least eight; see make_fixtures.cpp) and
// both precisions, the CLI exits 0 and:
// * writes no NaN or inf: the impulses are finite, and its bodies file reads
//   back through the strict scene reader (which rejects NaN everywhere and
//   inf outside m and I);
// * copies every body column other than v and w unchanged;
// * writes impulses within the documented bound of the long double
//   reference of the scene as the run read it (the fixture parsed in T, as
//   the CLI parses it, solved by reference_solve<long double>): |J - Jref|
//   <= kImpulseErrorBoundEps * impulse_error_unit<T> on every contact
//   (eps(T) * impulse_scale plus the underflow floor);
// * agrees with the committed expected_impulses.csv within that same bound
//   (the expected files are the double reading's reference; the fixtures'
//   numbers are float values, so a float run reads the same scene);
// * writes velocities within the bound the impulses imply (below).
// In the double run it also checks that the committed expected files are
// current: within an ulp of what the reference gives today.
#include <sys/wait.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "support/error_bound.hpp"

namespace collide {
namespace {

namespace fs = std::filesystem;
using L = long double;

/// Reads an impulses file (header jx,jy,jz) into long double triples.
/// Numbers that do not parse fail the test; inf and NaN parse and are
/// caught by the caller's finiteness check.
template <class T>
std::vector<std::array<L, 3>> read_impulses(const std::string& path) {
  const std::string text = read_file(path);
  std::vector<std::array<L, 3>> rows;
  std::size_t pos = text.find('\n');
  EXPECT_EQ(text.substr(0, pos + 1), impulses_header()) << path;
  while (pos != std::string::npos && pos + 1 < text.size()) {
    const std::size_t end = text.find('\n', pos + 1);
    const std::string line = text.substr(pos + 1, end - pos - 1);
    std::array<L, 3> row{};
    const char* p = line.data();
    const char* const last = line.data() + line.size();
    for (int c = 0; c < 3; ++c) {
      T value{};
      const auto r = std::from_chars(p, last, value);
      EXPECT_EQ(r.ec, std::errc()) << path << ": '" << line << "'";
      row[c] = value;
      p = r.ptr + (c < 2 ? 1 : 0);
    }
    EXPECT_EQ(p, last) << path << ": '" << line << "'";
    rows.push_back(row);
    pos = end;
  }
  return rows;
}

L distance(const std::array<L, 3>& a, const std::array<L, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
L length(const std::array<L, 3>& a) { return distance(a, {0, 0, 0}); }

/// The scene as a `collide solve --precision T` run reads it, and its
/// long double reference.
template <class T>
struct Read {
  BodyTable<T> table;
  BodyBuffer<T> bodies;
  ContactBuffer<T> contacts;
  BodyBuffer<L> ref_bodies;
  ImpulseBuffer<L> ref_j;
  std::vector<ReferenceContact<L>> diag;

  explicit Read(const fs::path& dir)
      : table(read_bodies<T>((dir / "bodies.csv").string())),
        bodies(to_body_buffer(table)),
        contacts(read_contacts<T>((dir / "contacts.csv").string(), table.size())),
        ref_bodies(convert_bodies<L>(std::as_const(bodies).view())),
        ref_j(contacts.size()),
        diag(contacts.size()) {
    const ContactBuffer<L> c = convert_contacts<L>(contacts.view());
    reference_solve<L>(ref_bodies.view(), c.view(), ref_j.view(), diag.data());
  }
  [[nodiscard]] std::array<L, 3> ref(std::size_t k) const {
    const auto v = ref_j.view();
    return {v.j.x[k], v.j.y[k], v.j.z[k]};
  }
};

int run_cli(const std::string& args) {
  const std::string cmd = std::string(COLLIDE_CLI_PATH) + " " + args;
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<fs::path> fixture_dirs() {
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(fs::path(COLLIDE_DATA_DIR) / "hard")) {
    if (entry.is_directory()) dirs.push_back(entry.path());
  }
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

template <class T>
void check_fixture(const fs::path& dir) {
  const char* precision = sizeof(T) == sizeof(float) ? "float" : "double";
  const std::string name = dir.filename().string();
  SCOPED_TRACE(name + " " + precision);
  const fs::path out = fs::path(COLLIDE_TEST_TMP) / (name + "-" + precision);
  fs::create_directories(out);
  const std::string out_bodies = (out / "bodies.csv").string();
  const std::string out_impulses = (out / "impulses.csv").string();
  ASSERT_EQ(
      run_cli("solve --bodies " + (dir / "bodies.csv").string() + " --contacts " + (dir / "contacts.csv").string() +
              " --out-bodies " + out_bodies + " --out-impulses " + out_impulses + " --precision " + precision),
      0);

  const Read<T> in(dir);
  const std::size_t n = in.contacts.size();
  const auto j = read_impulses<T>(out_impulses);
  const auto expected = read_impulses<double>((dir / "expected_impulses.csv").string());
  ASSERT_EQ(j.size(), n);
  ASSERT_EQ(expected.size(), n);

  // Impulses: finite, within the bound of this run's reference and of the
  // committed expectation. The unit is the library's: eps(T) *
  // impulse_scale plus the underflow floor (collide/eval/error_bound.hpp).
  L worst = 0, worst_expected = 0, input_rounding = 0;
  for (std::size_t k = 0; k < n; ++k) {
    for (const L x : j[k]) ASSERT_TRUE(std::isfinite(x)) << "contact " << k;
    const L unit = impulse_error_unit<T>(in.diag[k]);
    const L bound = test::kErrorBoundEps * unit;
    const L err = distance(j[k], in.ref(k));
    const L err_expected = distance(j[k], expected[k]);
    EXPECT_LE(err, bound) << "contact " << k;
    // The expectation is rounded to double: half an ulp of its own.
    EXPECT_LE(err_expected, bound + L(std::numeric_limits<double>::epsilon()) * length(expected[k]))
        << "contact " << k << " vs expected_impulses.csv";
    if (unit > 0) {
      worst = std::max(worst, err / unit);
      worst_expected = std::max(worst_expected, err_expected / unit);
      input_rounding = std::max(input_rounding, distance(in.ref(k), expected[k]) / unit);
    }
    if constexpr (sizeof(T) == sizeof(double)) {
      // The committed expectation is today's reference, to an ulp.
      EXPECT_LE(distance(expected[k], in.ref(k)), L(std::numeric_limits<double>::epsilon()) * length(expected[k]))
          << "contact " << k << ": data/hard/" << name << " is stale; rerun make_fixtures";
    }
  }
  std::cout << "[fixture] " << name << " " << precision << ": max " << static_cast<double>(worst)
            << " (units of the bound) vs its reference, " << static_cast<double>(worst_expected)
            << " vs expected_impulses.csv (this run's reference vs the expected file: "
            << static_cast<double>(input_rounding) << ")" << std::endl;

  // Bodies: the strict reader accepts the output (no NaN, no inf outside m
  // and I), every column but v and w is the input's, and v, w are within
  // what the impulses' bound implies. A body's velocity is its start value
  // plus its contacts' impulses times 1/m (for w: times the inverse inertia
  // and the lever arm, at most max(1/I) |r|), each impulse within
  // C eps s_k, and each of its n_i additions rounds once more:
  //   |v - v_ref| <= (C + n_i + 4) eps (|v_0| + |v| + sum_k s_k / m)
  //   |w - w_ref| <= (C + n_i + 4) eps (|w_0| + |w| + sum_k s_k max(1/I) |r_k|).
  BodyTable<T> solved;
  ASSERT_NO_THROW(solved = read_bodies<T>(out_bodies));
  ASSERT_EQ(solved.size(), in.table.size());
  for (std::size_t c = 0; c < BodyTable<T>::kCount; ++c) {
    const bool velocity = c >= BodyTable<T>::vx;
    if (velocity) continue;
    for (std::size_t i = 0; i < solved.size(); ++i) {
      ASSERT_EQ(solved.column[c][i], in.table.column[c][i]) << "body " << i << " column " << kBodyColumns[c];
    }
  }
  const BodyView<const T> b0 = in.bodies.view();
  const BodyView<const L> ref = std::as_const(in.ref_bodies).view();
  const ContactView<T> cv = in.contacts.view();
  std::vector<L> v_budget(b0.count, 0), w_budget(b0.count, 0), uses(b0.count, 0);
  for (std::size_t k = 0; k < n; ++k) {
    for (const BodyIndex i : {cv.a[k], cv.b[k]}) {
      const L r = length({L(cv.c.x[k]) - b0.p.x[i], L(cv.c.y[k]) - b0.p.y[i], L(cv.c.z[k]) - b0.p.z[i]});
      const L inv_i = std::max({L(b0.inv_inertia.x[i]), L(b0.inv_inertia.y[i]), L(b0.inv_inertia.z[i])});
      v_budget[i] += in.diag[k].impulse_scale * L(b0.inv_mass[i]);
      w_budget[i] += in.diag[k].impulse_scale * inv_i * r;
      uses[i] += 1;
    }
  }
  using C = BodyTable<T>;
  for (std::size_t i = 0; i < solved.size(); ++i) {
    const std::array<L, 3> v{solved.column[C::vx][i], solved.column[C::vy][i], solved.column[C::vz][i]};
    const std::array<L, 3> w{solved.column[C::wx][i], solved.column[C::wy][i], solved.column[C::wz][i]};
    const std::array<L, 3> v0{b0.v.x[i], b0.v.y[i], b0.v.z[i]}, w0{b0.w.x[i], b0.w.y[i], b0.w.z[i]};
    const std::array<L, 3> vr{ref.v.x[i], ref.v.y[i], ref.v.z[i]}, wr{ref.w.x[i], ref.w.y[i], ref.w.z[i]};
    const L c = (test::kErrorBoundEps + uses[i] + 4) * L(std::numeric_limits<T>::epsilon());
    EXPECT_LE(distance(v, vr), c * (length(v0) + length(v) + v_budget[i])) << "v of body " << i;
    EXPECT_LE(distance(w, wr), c * (length(w0) + length(w) + w_budget[i])) << "w of body " << i;
  }
}

TEST(HardFixtures, CliSolvesEveryFixtureWithinTheBound) {
  const std::vector<fs::path> dirs = fixture_dirs();
  ASSERT_GE(dirs.size(), 8u) << "data/hard/ lost its fixtures";
  for (const fs::path& dir : dirs) {
    for (const char* file : {"bodies.csv", "contacts.csv", "expected_bodies.csv", "expected_impulses.csv"}) {
      ASSERT_TRUE(fs::exists(dir / file)) << dir / file;
    }
    check_fixture<float>(dir);
    check_fixture<double>(dir);
  }
}

TEST(HardFixtures, ExpectedBodiesAreTheReferenceState) {
  // expected_bodies.csv is the double reading's reference state, rounded to
  // double: it reads back through the strict reader, and its v and w are
  // today's reference to an ulp (the other columns are checked against the
  // CLI's output above).
  for (const fs::path& dir : fixture_dirs()) {
    SCOPED_TRACE(dir.filename().string());
    const Read<double> in(dir);
    BodyTable<double> expected;
    ASSERT_NO_THROW(expected = read_bodies<double>((dir / "expected_bodies.csv").string()));
    ASSERT_EQ(expected.size(), in.table.size());
    const BodyView<const L> ref = std::as_const(in.ref_bodies).view();
    using C = BodyTable<double>;
    const L* fields[6] = {ref.v.x, ref.v.y, ref.v.z, ref.w.x, ref.w.y, ref.w.z};
    for (std::size_t f = 0; f < 6; ++f) {
      for (std::size_t i = 0; i < expected.size(); ++i) {
        const L e = expected.column[C::vx + f][i];
        EXPECT_LE(std::abs(e - fields[f][i]), L(std::numeric_limits<double>::epsilon()) * std::abs(e))
            << "body " << i << ": data/hard/" << dir.filename().string() << " is stale; rerun make_fixtures";
      }
    }
  }
}

}  // namespace
}  // namespace collide
