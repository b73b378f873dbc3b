// test_scene_npz.cpp - the binary scene files in process (collide/io/scene_npz.hpp):
// columns used in place, conversions between precisions and id dtypes, and
// every refusal naming the file, the member (column) and the row.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/rules.hpp"
#include "collide/validate.hpp"

namespace fs = std::filesystem;
using collide::BodyRules;
using collide::NpyType;
using collide::NpzColumn;
using collide::SceneError;
using collide::SceneFormat;
using collide::SolveBodies;

namespace {

class SceneNpzTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / (std::string("collide_scene_npz_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  [[nodiscard]] std::string put(const std::string& name, const std::vector<NpzColumn>& columns) const {
    std::string p = (dir_ / name).string();
    std::ofstream(p, std::ios::binary) << collide::format_npz(columns);
    return p;
  }
  fs::path dir_;
};

/// n bodies whose every column holds a valid value (mass 1 + i, identity q).
template <class T>
struct Bodies {
  std::vector<std::vector<T>> col;
  explicit Bodies(std::size_t n) : col(17, std::vector<T>(n, T(0))) {
    for (std::size_t i = 0; i < n; ++i) {
      col[0][i] = T(1) + T(i);
      col[1][i] = col[2][i] = col[3][i] = T(2);
      col[4][i] = T(1);
      col[8][i] = T(i);
      col[11][i] = T(0.5);
    }
  }
  [[nodiscard]] std::vector<NpzColumn> columns() const {
    std::vector<NpzColumn> c;
    const NpyType t = sizeof(T) == 4 ? NpyType::f4 : NpyType::f8;
    for (std::size_t k = 0; k < 17; ++k) c.push_back({collide::kBodyColumns[k], t, col[k].data(), col[k].size()});
    return c;
  }
};

/// n contacts between bodies k and k + 1, |n| = 1, without friction.
template <class T, class Index = std::uint32_t>
struct Contacts {
  std::vector<Index> a, b;
  std::vector<std::vector<T>> col;
  explicit Contacts(std::size_t n) : a(n), b(n), col(8, std::vector<T>(n, T(0))) {
    for (std::size_t k = 0; k < n; ++k) {
      a[k] = static_cast<Index>(k);
      b[k] = static_cast<Index>(k + 1);
      col[4][k] = T(1);  // ny
      col[6][k] = T(0.5);
    }
  }
  [[nodiscard]] std::vector<NpzColumn> columns(NpyType index_type = NpyType::u4) const {
    std::vector<NpzColumn> c = {{"a", index_type, a.data(), a.size()}, {"b", index_type, b.data(), b.size()}};
    const NpyType t = sizeof(T) == 4 ? NpyType::f4 : NpyType::f8;
    for (std::size_t k = 0; k < 8; ++k) c.push_back({collide::kContactColumns[k + 2], t, col[k].data(), a.size()});
    return c;
  }
};

template <class F>
SceneError scene_error(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "no SceneError";
  return SceneError("none", "none");
}

TEST_F(SceneNpzTest, FormatFromTheName) {
  EXPECT_EQ(collide::scene_format_of("a/b.npz"), SceneFormat::npz);
  EXPECT_EQ(collide::scene_format_of("b.csv"), SceneFormat::csv);
  EXPECT_EQ(collide::scene_format_of("npz"), SceneFormat::csv);
  EXPECT_EQ(collide::parse_scene_format("npz"), SceneFormat::npz);
  EXPECT_THROW((void)collide::parse_scene_format("NPZ"), std::invalid_argument);
}

TEST_F(SceneNpzTest, OwnPrecisionIsUsedInPlace) {
  const Bodies<float> b(1000);
  const Contacts<float> c(999);
  const std::string bp = put("b.npz", b.columns()), cp = put("c.npz", c.columns());
  const auto bodies = collide::load_bodies<float>(bp, SceneFormat::npz);
  EXPECT_TRUE(bodies.mapped());
  ASSERT_EQ(bodies.size(), 1000u);
  for (std::size_t k = 0; k < 17; ++k) {
    for (std::size_t i = 0; i < 1000; ++i) ASSERT_EQ(bodies.columns().column[k][i], b.col[k][i]) << k << " " << i;
  }
  const auto contacts = collide::load_contacts<float>(cp, SceneFormat::npz, 1000);
  EXPECT_TRUE(contacts.mapped());
  EXPECT_EQ(contacts.view().mu, nullptr) << "no friction: the frictionless kernel";
  EXPECT_EQ(contacts.view().b[998], 999u);
  EXPECT_EQ(contacts.view().n.y[5], 1.0f);
}

TEST_F(SceneNpzTest, OtherPrecisionIsConverted) {
  const Bodies<float> b(100);
  const std::string bp = put("b.npz", b.columns());
  const auto wide = collide::load_bodies<double>(bp, SceneFormat::npz);
  EXPECT_FALSE(wide.mapped());
  EXPECT_EQ(wide.columns().column[0][99], 100.0);
  Bodies<double> d(3);
  d.col[8][1] = 0.1;  // rounds in float
  const auto narrow = collide::load_bodies<float>(put("d.npz", d.columns()), SceneFormat::npz);
  EXPECT_EQ(narrow.columns().column[8][1], 0.1f);
}

TEST_F(SceneNpzTest, DoubleBeyondFloatIsRefusedNotMadeImmovable) {
  Bodies<double> d(4);
  d.col[0][2] = 1e300;
  const std::string p = put("d.npz", d.columns());
  const SceneError e = scene_error([&] { (void)collide::load_bodies<float>(p, SceneFormat::npz); });
  EXPECT_EQ(e.row(), 2u);
  EXPECT_EQ(e.column(), "m");
  EXPECT_NE(std::string(e.what()).find("out of the range of float"), std::string::npos) << e.what();
  EXPECT_NO_THROW((void)collide::load_bodies<double>(p, SceneFormat::npz));
}

TEST_F(SceneNpzTest, RulesAreTheCsvRules) {
  Bodies<double> d(4);
  d.col[5][3] = std::numeric_limits<double>::quiet_NaN();  // qx
  const std::string p = put("d.npz", d.columns());
  const SceneError e = scene_error([&] { (void)collide::load_bodies<double>(p, SceneFormat::npz); });
  EXPECT_EQ(e.file(), p);
  EXPECT_EQ(e.row(), 3u);
  EXPECT_EQ(e.column(), "qx");
  EXPECT_EQ(std::string(e.what()).find(p + ": row 3, column 'qx': "), 0u) << e.what();

  Contacts<double> c(3);
  c.col[6][1] = 1.5;  // e
  const std::string cp = put("c.npz", c.columns());
  const SceneError ce = scene_error([&] { (void)collide::load_contacts<double>(cp, SceneFormat::npz, 4); });
  EXPECT_EQ(ce.row(), 1u);
  EXPECT_EQ(ce.column(), "e");
}

TEST_F(SceneNpzTest, SolveArraysCheckTheRulesInTheirOnePass) {
  // Many chunks of the fused pass (8192 bodies each), an immovable body and
  // varied values: the arrays are bit for bit those of the separate passes.
  constexpr std::size_t kN = 70001;
  Bodies<float> b(kN);
  for (std::size_t i = 0; i < kN; ++i) {
    b.col[1][i] = 0.5f + static_cast<float>(i % 7);
    b.col[14][i] = -static_cast<float>(i) / 3.0f;
  }
  b.col[0][12345] = b.col[2][12345] = std::numeric_limits<float>::infinity();
  const auto loaded = collide::load_bodies<float>(put("b.npz", b.columns()), SceneFormat::npz, BodyRules::by_caller);
  const SolveBodies<float> fused(loaded);
  std::vector<float> inverses(4 * kN);
  collide::inverses_of(
      loaded.columns(), inverses.data(),
      collide::Vec3Array<float>{inverses.data() + kN, inverses.data() + 2 * kN, inverses.data() + 3 * kN});
  const auto x = fused.view();
  const auto same = [&](const float* p, const float* q, const char* what) {
    for (std::size_t i = 0; i < kN; ++i) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(p[i]), std::bit_cast<std::uint32_t>(q[i])) << what << " " << i;
    }
  };
  same(x.inv_mass, inverses.data(), "inv_mass");
  same(x.inv_inertia.x, inverses.data() + kN, "1/Ix");
  same(x.inv_inertia.y, inverses.data() + 2 * kN, "1/Iy");
  same(x.inv_inertia.z, inverses.data() + 3 * kN, "1/Iz");
  same(x.v.x, b.col[11].data(), "vx");
  same(x.w.z, b.col[16].data(), "wz");
  EXPECT_EQ(x.inv_mass[12345], 0.0f);
  EXPECT_EQ(x.q.w, loaded.columns().column[4]) << "q in place";

  // Two bad bodies in different chunks: the first row is named, as
  // load_bodies names it, whichever chunk a thread screened first.
  b.col[5][60000] = std::numeric_limits<float>::quiet_NaN();  // qx
  b.col[0][20001] = -1.0f;                                    // m
  const std::string p = put("bad.npz", b.columns());
  const auto unchecked = collide::load_bodies<float>(p, SceneFormat::npz, BodyRules::by_caller);
  const SceneError e = scene_error([&] { const SolveBodies<float> s(unchecked); });
  EXPECT_EQ(e.file(), p);
  EXPECT_EQ(e.row(), 20001u);
  EXPECT_EQ(e.column(), "m");
  const SceneError checked = scene_error([&] { (void)collide::load_bodies<float>(p, SceneFormat::npz); });
  EXPECT_EQ(std::string(checked.what()), std::string(e.what()));
  const SceneError later = scene_error([&] { unchecked.check(); });
  EXPECT_EQ(std::string(later.what()), std::string(e.what()));
  // Columns of no file: the first bad row, as an invalid argument.
  try {
    const SolveBodies<float> s(unchecked.columns());
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& x) {
    EXPECT_NE(std::string(x.what()).find("row 20001, column 'm'"), std::string::npos) << x.what();
  }
}

TEST_F(SceneNpzTest, SixtyFourBitIdsAsNumPyWritesThem) {
  Contacts<double, std::int64_t> c(5);
  const std::string p = put("c.npz", c.columns(NpyType::i8));
  const auto loaded = collide::load_contacts<double>(p, SceneFormat::npz, 6);
  EXPECT_EQ(loaded.view().a[4], 4u);
  EXPECT_EQ(loaded.view().b[4], 5u);
  c.a[3] = -2;
  const std::string bad = put("bad.npz", c.columns(NpyType::i8));
  const SceneError e = scene_error([&] { (void)collide::load_contacts<double>(bad, SceneFormat::npz, 6); });
  EXPECT_EQ(e.row(), 3u);
  EXPECT_EQ(e.column(), "a");
  EXPECT_NE(std::string(e.what()).find("non-negative integer, got -2"), std::string::npos) << e.what();
  c.a[3] = std::int64_t{1} << 40;
  const std::string big = put("big.npz", c.columns(NpyType::i8));
  const SceneError be = scene_error([&] { (void)collide::load_contacts<double>(big, SceneFormat::npz, 6); });
  EXPECT_EQ(be.row(), 3u);
  EXPECT_NE(std::string(be.what()).find("out of range"), std::string::npos) << be.what();
}

TEST_F(SceneNpzTest, MembersMustBeTheTablesColumns) {
  Bodies<double> d(2);
  auto cols = d.columns();
  // Missing.
  auto missing = cols;
  missing.erase(missing.begin() + 5);
  const SceneError m =
      scene_error([&] { (void)collide::load_bodies<double>(put("m.npz", missing), SceneFormat::npz); });
  EXPECT_EQ(m.column(), "qx");
  EXPECT_NE(std::string(m.what()).find("missing"), std::string::npos) << m.what();
  // Extra.
  auto extra = cols;
  extra.push_back({"colour", NpyType::f8, d.col[0].data(), 2});
  const SceneError x = scene_error([&] { (void)collide::load_bodies<double>(put("x.npz", extra), SceneFormat::npz); });
  EXPECT_EQ(x.column(), "colour");
  // A different length.
  auto shorter = cols;
  shorter[9].count = 1;
  const SceneError s =
      scene_error([&] { (void)collide::load_bodies<double>(put("s.npz", shorter), SceneFormat::npz); });
  EXPECT_EQ(s.column(), "py");
  // Two precisions in one file.
  const std::vector<float> f(2, 1.0f);
  auto mixed = cols;
  mixed[10] = {"pz", NpyType::f4, f.data(), 2};
  const SceneError p = scene_error([&] { (void)collide::load_bodies<double>(put("p.npz", mixed), SceneFormat::npz); });
  EXPECT_NE(std::string(p.what()).find("one precision"), std::string::npos) << p.what();
  // Integers in a real column.
  const std::vector<std::int64_t> ints(2, 1);
  auto integer = cols;
  integer[0] = {"m", NpyType::i8, ints.data(), 2};
  const SceneError i =
      scene_error([&] { (void)collide::load_bodies<double>(put("i.npz", integer), SceneFormat::npz); });
  EXPECT_EQ(i.column(), "m");
}

TEST_F(SceneNpzTest, FrictionIsKeptWhenAnyMuIsNonZero) {
  Contacts<float> c(10);
  c.col[7][9] = 0.25f;
  const auto loaded = collide::load_contacts<float>(put("c.npz", c.columns()), SceneFormat::npz, 11);
  ASSERT_NE(loaded.view().mu, nullptr);
  EXPECT_EQ(loaded.view().mu[9], 0.25f);
}

TEST_F(SceneNpzTest, WrittenColumnsReadBackExactly) {
  Bodies<double> d(50);
  d.col[12][7] = -0.1;
  const std::string p = put("d.npz", d.columns());
  const auto loaded = collide::load_bodies<double>(p, SceneFormat::npz);
  {
    collide::OutputFile out((dir_ / "again.npz").string());
    collide::write_body_table_npz(out, loaded.columns());
    out.commit();
  }
  std::ifstream a(p, std::ios::binary), b(dir_ / "again.npz", std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(a)), {}), sb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(sa, sb);
}

}  // namespace

namespace {

/// Values at and past every bound of the rules, in T.
template <class T>
std::vector<T> edge_values() {
  using L = std::numeric_limits<T>;
  std::vector<T> values{T(0),           -T(0),           T(1),     -T(1),    L::infinity(), -L::infinity(),
                        L::quiet_NaN(), L::denorm_min(), L::min(), L::max(), T(1e-20),      T(1e20),
                        T(0.5),         T(1.0005),       T(1.002), T(0.9985)};
  // Where 1/x overflows (a subnormal near 1/max): the values around it,
  // which the columnar screen compares with a threshold instead of dividing.
  T below = T(1) / L::max(), above = below;
  for (int step = 0; step < 4; ++step) {
    values.push_back(below = std::nextafter(below, T(0)));
    values.push_back(above = std::nextafter(above, L::max()));
  }
  values.push_back(T(1) / L::max());
  return values;
}

/// Rows of the screen tests: whole SIMD blocks and a tail.
constexpr std::size_t kRows = 67;

template <class T>
void columnar_body_screen_is_body_ok() {
  // Every column of one valid body set to every edge value: the columnar
  // verdict (bodies_ok) is the row verdict (body_ok).
  for (std::size_t k = 0; k < 17; ++k) {
    for (const T x : edge_values<T>()) {
      Bodies<T> b(kRows);
      std::fill(b.col[k].begin(), b.col[k].end(), x);
      collide::BodyColumns<T> c;
      c.count = kRows;
      for (std::size_t j = 0; j < 17; ++j) c.column[j] = b.col[j].data();
      bool rows_ok = true;
      for (std::size_t i = 0; i < kRows; ++i) rows_ok &= collide::body_ok(c.record(i));
      EXPECT_EQ(collide::bodies_ok(c, 0, kRows), rows_ok) << "column " << k << " = " << x;
    }
  }
  // The quaternion as a whole: all zero, too small, too large.
  for (const T x : {T(0), T(1e-25), T(1e-30), T(3e19), std::numeric_limits<T>::max() / 2}) {
    Bodies<T> b(kRows);
    for (std::size_t k = 4; k < 8; ++k) std::fill(b.col[k].begin(), b.col[k].end(), x);
    collide::BodyColumns<T> c;
    c.count = kRows;
    for (std::size_t j = 0; j < 17; ++j) c.column[j] = b.col[j].data();
    EXPECT_EQ(collide::bodies_ok(c, 0, kRows), collide::body_ok(c.record(kRows - 1))) << "q = " << x;
  }
}

TEST(SceneNpzRules, ColumnarBodyScreenIsBodyOk) {
  columnar_body_screen_is_body_ok<float>();
  columnar_body_screen_is_body_ok<double>();
}

template <class T>
void contact_screen_clears_only_valid_contacts() {
  // contacts_pass_screen is a sufficient test: it never clears a contact
  // that contact_ok refuses (and clears a plainly valid one).
  for (std::size_t k = 0; k < 8; ++k) {
    for (const T x : edge_values<T>()) {
      Contacts<T> c(kRows);
      std::fill(c.col[k].begin(), c.col[k].end(), x);
      collide::ContactView<T> v;
      v.count = kRows;
      v.a = c.a.data();
      v.b = c.b.data();
      v.c = {c.col[0].data(), c.col[1].data(), c.col[2].data()};
      v.n = {c.col[3].data(), c.col[4].data(), c.col[5].data()};
      v.e = c.col[6].data();
      v.mu = c.col[7].data();
      bool rows_ok = true;
      for (std::size_t i = 0; i < kRows; ++i) {
        collide::ContactRecord<T> r;
        r.a = c.a[i];
        r.b = c.b[i];
        for (int j = 0; j < 3; ++j) {
          r.c[j] = c.col[j][i];
          r.n[j] = c.col[3 + j][i];
        }
        r.e = c.col[6][i];
        r.mu = c.col[7][i];
        rows_ok &= collide::contact_ok(r, kRows + 1);
      }
      if (collide::contacts_pass_screen(v, kRows + 1)) {
        EXPECT_TRUE(rows_ok) << "column " << k << " = " << x;
      }
      if (k == 0 && x == T(0)) {
        EXPECT_TRUE(collide::contacts_pass_screen(v, kRows + 1));
      }
    }
  }
}

TEST(SceneNpzRules, ContactScreenClearsOnlyValidContacts) {
  contact_screen_clears_only_valid_contacts<float>();
  contact_screen_clears_only_valid_contacts<double>();
}

TEST(SceneNpzRules, FirstBodyDefectIsTheFirstRowWithItsReason) {
  // Past the screen's grain, so it runs in chunks: the first row that
  // breaks a rule is named whatever the chunking, with body_defect's column
  // and reason, even when a later row breaks a rule of an earlier column.
  constexpr std::size_t kN = 200000;
  Bodies<float> b(kN);
  collide::BodyColumns<float> c;
  c.count = kN;
  for (std::size_t j = 0; j < 17; ++j) c.column[j] = b.col[j].data();
  EXPECT_FALSE(collide::first_body_defect(c).has_value());
  b.col[0][kN - 5] = -1;                                        // m, a late row
  b.col[13][kN - 9] = std::numeric_limits<float>::quiet_NaN();  // vz, an earlier row
  const std::optional<collide::RowDefect> d = collide::first_body_defect(c);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->row, kN - 9);
  EXPECT_EQ(d->defect.column, "vz");
  EXPECT_EQ(d->defect.reason, "NaN is not allowed");
  b.col[13][kN - 9] = 0;
  const std::optional<collide::RowDefect> m = collide::first_body_defect(c);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->row, kN - 5);
  EXPECT_EQ(m->defect.column, "m");
  EXPECT_EQ(m->defect.reason, "mass must be > 0, got -1");
}

TEST_F(SceneNpzTest, DefectFoundInALargeFileAtItsRow) {
  // Past the parallel screens' grain, so they run in chunks; each defect is
  // reported at its row and column whatever the chunking.
  constexpr std::size_t kN = 200000;
  const struct {
    std::size_t column;
    double value;
    const char* named;
  } cases[] = {{0, -1, "m"},
               {2, 0, "Iy"},
               {8, std::numeric_limits<double>::infinity(), "px"},
               {12, std::nan(""), "vy"},
               {16, -std::numeric_limits<double>::infinity(), "wz"}};
  for (const auto& c : cases) {
    Bodies<double> d(kN);
    d.col[c.column][kN - 7] = c.value;
    d.col[c.column][kN - 3] = c.value;
    const std::string p = put("big.npz", d.columns());
    const SceneError e = scene_error([&] { (void)collide::load_bodies<double>(p, SceneFormat::npz); });
    EXPECT_EQ(e.row(), kN - 7) << c.named;
    EXPECT_EQ(e.column(), c.named);
  }
  Contacts<float> ct(kN);
  ct.col[3][kN - 11] = 0.5f;  // |n| off unit
  const std::string cp = put("bigc.npz", ct.columns());
  const SceneError e = scene_error([&] { (void)collide::load_contacts<float>(cp, SceneFormat::npz, kN + 1); });
  EXPECT_EQ(e.row(), kN - 11);
  EXPECT_EQ(e.column(), "nx");
}

}  // namespace
