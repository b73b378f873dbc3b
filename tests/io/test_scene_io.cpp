// test_scene_io.cpp - the scene file reader and writer, driven in process.
//
// The CLI tests cover every bad input end to end; these cover what is awkward
// through a process: the SceneError fields, precision-specific limits,
// multi-chunk (parallel) parsing, exact number round trips, random
// corruption of valid files, and OutputFile's all-or-nothing behaviour.
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene_io.hpp"
#include "support/csv_text.hpp"

namespace fs = std::filesystem;
using collide::BodyTable;
using collide::SceneError;

namespace {

const std::string kHeader = "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n";
const std::string kRow = "2,1,1,1,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n";
const std::string kContactHeader = "a,b,cx,cy,cz,nx,ny,nz,e,mu\n";

template <class F>
SceneError expect_scene_error(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "no SceneError thrown";
  return SceneError("none", "none");
}

TEST(SceneIo, ErrorCarriesFileLineRowColumn) {
  const SceneError e = expect_scene_error([] {
    (void)collide::parse_bodies<double>(kHeader + kRow + kRow + "2,1,1,1,1,0,0,0,0,1,0,0.5,x,0,0,0,1\n", "b.csv");
  });
  EXPECT_EQ(e.file(), "b.csv");
  EXPECT_EQ(e.line(), 4u);
  EXPECT_EQ(e.row(), 2u);
  EXPECT_EQ(e.column(), "vy");
  EXPECT_STREQ(e.what(), "b.csv:4: row 2, column 'vy': not a number: 'x'");
}

// A file the system cannot give is an operating-system error (the shells
// raise OSError / FileNotFoundError from os_error()); a bad content is not.
TEST(SceneIo, MissingFileCarriesTheSystemError) {
  const std::string missing = (fs::temp_directory_path() / "collide-no-such-dir" / "bodies.csv").string();
  const SceneError e = expect_scene_error([&] { (void)collide::read_bodies<double>(missing); });
  EXPECT_EQ(e.os_error(), ENOENT);
  EXPECT_EQ(e.file(), missing);
  const SceneError d =
      expect_scene_error([] { (void)collide::read_bodies<double>(fs::temp_directory_path().string()); });
  EXPECT_EQ(d.os_error(), EISDIR);
  const SceneError c = expect_scene_error([] { (void)collide::parse_bodies<float>("m,Ix\n", "b.csv"); });
  EXPECT_EQ(c.os_error(), 0);
}

TEST(SceneIo, HeaderErrorHasNoRow) {
  const SceneError e = expect_scene_error([] { (void)collide::parse_bodies<float>("m,Ix\n", "b.csv"); });
  EXPECT_EQ(e.line(), 1u);
  EXPECT_EQ(e.row(), SceneError::kNoRow);
  EXPECT_EQ(e.column(), "Iy");
}

TEST(SceneIo, EmptyAndBlankFilesMissHeader) {
  for (const char* text : {"", "\n", "\r\n", "  \n\n"}) {
    const SceneError e = expect_scene_error([&] { (void)collide::parse_contacts<double>(text, "c.csv", 3); });
    EXPECT_EQ(e.column(), "a") << text;
    EXPECT_NE(std::string(e.what()).find("missing header"), std::string::npos) << e.what();
  }
}

TEST(SceneIo, HeaderOnlyIsAnEmptyScene) {
  EXPECT_EQ(collide::parse_bodies<double>(kHeader, "b").size(), 0u);
  EXPECT_EQ(collide::parse_bodies<double>(kHeader.substr(0, kHeader.size() - 1), "b").size(), 0u);
  EXPECT_EQ(collide::parse_contacts<double>(kContactHeader + "\n\n", "c", 0).size(), 0u);
}

TEST(SceneIo, TolerantOfBomBlanksCrlfAndTrailingLines) {
  const std::string text =
      "\xEF\xBB\xBF m , Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\r\n"
      " 2 ,1,1,1,1,0,0,0,0,1,0,\t0.5,-3,0,0,0,+1\r\n\r\n\n";
  const BodyTable<double> t = collide::parse_bodies<double>(text, "b");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t.column[BodyTable<double>::m][0], 2.0);
  EXPECT_EQ(t.column[BodyTable<double>::vx][0], 0.5);
  EXPECT_EQ(t.column[BodyTable<double>::wz][0], 1.0);
}

TEST(SceneIo, BlankLineInTheMiddleIsAnError) {
  const SceneError e =
      expect_scene_error([] { (void)collide::parse_bodies<double>(kHeader + kRow + "\n" + kRow, "b"); });
  EXPECT_EQ(e.row(), 1u);
  EXPECT_EQ(e.line(), 3u);
}

TEST(SceneIo, InfSpellingsOnlyForMassAndMoments) {
  const BodyTable<float> t =
      collide::parse_bodies<float>(kHeader + "INF,+inf,Infinity,iNfInItY,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n", "b");
  for (std::size_t k = 0; k < 4; ++k) EXPECT_TRUE(std::isinf(t.column[k][0]));
  const collide::BodyBuffer<float> buf = collide::to_body_buffer(t);
  EXPECT_EQ(buf.view().inv_mass[0], 0.0f);
  EXPECT_EQ(buf.view().inv_inertia.x[0], 0.0f);
  // "infin" is not a spelling of infinity.
  const SceneError e = expect_scene_error(
      [] { (void)collide::parse_bodies<float>(kHeader + "infin,1,1,1,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n", "b"); });
  EXPECT_EQ(e.column(), "m");
}

TEST(SceneIo, FloatRangeIsCheckedInFloat) {
  // Fine in double, out of range in float.
  const std::string big = kHeader + "2,1,1,1,1,0,0,0,1e39,1,0,0.5,-3,0,0,0,1\n";
  EXPECT_NO_THROW((void)collide::parse_bodies<double>(big, "b"));
  const SceneError e = expect_scene_error([&] { (void)collide::parse_bodies<float>(big, "b"); });
  EXPECT_EQ(e.column(), "px");
  EXPECT_NE(std::string(e.what()).find("float"), std::string::npos);
  // A mass whose inverse overflows float.
  const SceneError m = expect_scene_error(
      [] { (void)collide::parse_bodies<float>(kHeader + "1e-45,1,1,1,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n", "b"); });
  EXPECT_EQ(m.column(), "m");
  EXPECT_EQ(m.reason(), "mass 1e-45 is too small: its inverse overflows float");
  // A quaternion that cannot be normalised in float.
  const SceneError q = expect_scene_error(
      [] { (void)collide::parse_bodies<float>(kHeader + "2,1,1,1,1e-25,1e-25,0,0,0,1,0,0.5,-3,0,0,0,1\n", "b"); });
  EXPECT_EQ(q.column(), "qw");
  EXPECT_EQ(q.reason(),
            "quaternion cannot be normalised in float: it is too close to zero (qw, qx, qy, qz = 1e-25, 1e-25, 0, 0)");
  EXPECT_NO_THROW((void)collide::parse_bodies<double>(kHeader + "2,1,1,1,1e-25,1e-25,0,0,0,1,0,0.5,-3,0,0,0,1\n", "b"));
}

TEST(SceneIo, UnderflowRoundsLikeStrtod) {
  const BodyTable<float> t =
      collide::parse_bodies<float>(kHeader + "2,1,1,1,1,0,0,0,1e-60,-1e-40,0,0.5,-3,0,0,0,1\n", "b");
  EXPECT_EQ(t.column[BodyTable<float>::px][0], 0.0f);
  EXPECT_EQ(t.column[BodyTable<float>::py][0], std::strtof("-1e-40", nullptr));
}

TEST(SceneIo, ContactChecks) {
  auto contacts = [](const std::string& row) {
    return collide::parse_contacts<double>(kContactHeader + "0,1,0,0,0,0,1,0,0.5,0\n" + row + "\n", "c.csv", 3);
  };
  EXPECT_NO_THROW(contacts("1,2,0,0,0,0,0,1.000999,1,0"));
  EXPECT_NO_THROW(contacts("+2,0,0,0,0,0.6,0.8,0,0,5"));
  const struct {
    const char* row;
    const char* column;
  } cases[] = {
      {"1,3,0,0,0,0,1,0,0.5,0", "b"},
      {"3,1,0,0,0,0,1,0,0.5,0", "a"},
      {"1,1,0,0,0,0,1,0,0.5,0", "b"},
      {"1,2,0,0,0,0,1.0011,0,0.5,0", "nx"},
      {"1,2,0,0,0,0,1,0,1.0000001,0", "e"},
      {"1,2,0,0,0,0,1,0,-0,-1e-300", "mu"},
      {"1,2,0,0,0,0,1,0,0.5", "mu"},
      {"1,2,0,0,0,0,1,0,0.5,0,", "mu"},
      {"99999999999999999999,2,0,0,0,0,1,0,0.5,0", "a"},
  };
  for (const auto& c : cases) {
    const SceneError e = expect_scene_error([&] { (void)contacts(c.row); });
    EXPECT_EQ(e.column(), c.column) << c.row << ": " << e.what();
    EXPECT_EQ(e.row(), 1u) << c.row;
    EXPECT_EQ(e.line(), 3u) << c.row;
  }
}

TEST(SceneIo, NormalWithinToleranceIsStoredAsRead) {
  // The law normalises n inside the evaluation; the reader keeps the file's
  // value so that the accurate mode starts from it.
  const auto c = collide::parse_contacts<double>(kContactHeader + "0,1,0,0,0,0,0,1.0005,0.5,0\n", "c", 2);
  EXPECT_EQ(c.view().n.z[0], 1.0005);
  const auto f = collide::parse_contacts<float>(kContactHeader + "0,1,0,0,0,0,0,1.0005,0.5,0\n", "c", 2);
  EXPECT_EQ(f.view().n.z[0], 1.0005f);
}

/// A large file: many chunks are parsed in parallel.
std::string big_bodies(std::size_t rows) {
  std::string text = kHeader;
  for (std::size_t i = 0; i < rows; ++i) {
    collide::BodyRecord<double> r;
    r.m = 1.0 + static_cast<double>(i);
    r.p[0] = static_cast<double>(i) * 0.1;
    r.v[2] = -static_cast<double>(i);
    collide::append_body_row(text, r);
  }
  return text;
}

TEST(SceneIo, LargeFileParsesEveryRowInPlace) {
  const std::size_t rows = 100000;  // several MB: many chunks
  const BodyTable<double> t = collide::parse_bodies<double>(big_bodies(rows), "big");
  ASSERT_EQ(t.size(), rows);
  for (std::size_t i = 0; i < rows; ++i) {
    ASSERT_EQ(t.column[BodyTable<double>::m][i], 1.0 + static_cast<double>(i)) << i;
    ASSERT_EQ(t.column[BodyTable<double>::px][i], static_cast<double>(i) * 0.1) << i;
    ASSERT_EQ(t.column[BodyTable<double>::vz][i], -static_cast<double>(i)) << i;
  }
}

TEST(SceneIo, LargeFileReportsTheFirstBadRow) {
  std::string text = big_bodies(100000);
  // Corrupt rows 70000 and 30000 (in different chunks): row 30000 is reported.
  for (const std::size_t row : {70000u, 30000u}) {
    std::size_t pos = 0;
    for (std::size_t line = 0; line < row + 1; ++line) pos = text.find('\n', pos) + 1;
    text[pos] = '#';
  }
  const SceneError e = expect_scene_error([&] { (void)collide::parse_bodies<double>(text, "big"); });
  EXPECT_EQ(e.row(), 30000u);
  EXPECT_EQ(e.line(), 30002u);
  EXPECT_EQ(e.column(), "m");
}

using collide::test::with_blanks;

TEST(SceneIo, FastAndCarefulPathsAgree) {
  std::string bodies = kHeader, contacts = kContactHeader;
  collide::BodyRecord<double> a, b;
  collide::ContactRecord<double> c;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    collide::draw_pair({k, true}, k, a, b, c);
    collide::append_body_row(bodies, a);
    collide::append_body_row(bodies, b);
    collide::append_contact_row(contacts, c);
  }
  const auto fast_f = collide::parse_bodies<float>(bodies, "b");
  const auto slow_f = collide::parse_bodies<float>(with_blanks(bodies), "b");
  const auto fast_d = collide::parse_bodies<double>(bodies, "b");
  const auto slow_d = collide::parse_bodies<double>(with_blanks(bodies), "b");
  for (std::size_t k = 0; k < 17; ++k) {
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
    EXPECT_EQ(std::memcmp(fast_f.column[k].data(), slow_f.column[k].data(), 4000 * sizeof(float)), 0);
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
    EXPECT_EQ(std::memcmp(fast_d.column[k].data(), slow_d.column[k].data(), 4000 * sizeof(double)), 0);
  }
  const auto fast_c = collide::parse_contacts<float>(contacts, "c", 4000);
  const auto slow_c = collide::parse_contacts<float>(with_blanks(contacts), "c", 4000);
  for (std::size_t k = 0; k < 2000; ++k) {
    const auto x = fast_c.record(k), y = slow_c.record(k);
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
    EXPECT_EQ(std::memcmp(&x, &y, sizeof x), 0) << k;
  }
}

template <class T, class Bits>
void expect_round_trip(T value) {
  std::string s;
  collide::append_number(s, value);
  T back;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), back);
  ASSERT_EQ(r.ptr, s.data() + s.size()) << s;
  ASSERT_EQ(std::bit_cast<Bits>(back), std::bit_cast<Bits>(value)) << s;
}

TEST(SceneIo, NumbersRoundTripExactly) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 200000; ++i) {
    const auto d = std::bit_cast<double>(rng());
    if (std::isfinite(d)) expect_round_trip<double, std::uint64_t>(d);
    const auto f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    if (std::isfinite(f)) expect_round_trip<float, std::uint32_t>(f);
  }
  for (const double d : {0.0, -0.0, 0.1, 1e-320, std::numeric_limits<double>::max(),
                         std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::infinity()}) {
    expect_round_trip<double, std::uint64_t>(d);
  }
  std::string s;
  collide::append_number(s, std::numeric_limits<float>::infinity());
  EXPECT_EQ(s, "inf");
}

TEST(SceneIo, WrittenBodiesReadBackBitForBit) {
  const std::string text = kHeader + "inf,3,inf,0.30000000000000004,2,0,0,2,1e10,-0.1,3.3333333333333335,1,2,3,4,5,6\n";
  const BodyTable<double> t = collide::parse_bodies<double>(text, "b");
  collide::BodyBuffer<double> solved = collide::to_body_buffer(t);
  solved.view().v.x[0] = 0.1;  // a "solved" velocity
  const std::string out = collide::format_bodies(t, std::as_const(solved).view());
  const BodyTable<double> back = collide::parse_bodies<double>(out, "out");
  for (std::size_t k = 0; k < 17; ++k) {
    const double expected = k == BodyTable<double>::vx ? 0.1 : t.column[k][0];
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back.column[k][0]), std::bit_cast<std::uint64_t>(expected))
        << collide::kBodyColumns[k];
  }
}

TEST(SceneIo, RandomCorruptionEitherParsesOrThrowsSceneError) {
  const std::string bodies = kHeader + kRow + "inf,inf,inf,inf,0.5,0.5,0.5,0.5,1,2,3,0,0,0,0,0,0\n" + kRow;
  const std::string contacts = kContactHeader + "0,1,0,0,0,0,1,0,0.5,0.25\n2,1,1,1,1,1,0,0,1,0\n";
  const std::string alphabet = "0123456789,.-+eEinfINFaNn \t\r\n#x";
  std::mt19937_64 rng(7);
  int accepted = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    std::string text = iter % 2 ? bodies : contacts;
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int k = 0; k < edits; ++k) {
      const std::size_t pos = rng() % (text.size() + 1);
      const char c = alphabet[rng() % alphabet.size()];
      switch (rng() % 3) {
        case 0:
          text.insert(pos, 1, c);
          break;
        case 1:
          if (pos < text.size()) text.erase(pos, 1);
          break;
        default:
          if (pos < text.size()) text[pos] = c;
      }
    }
    try {
      if (iter % 2) {
        const BodyTable<double> t = collide::parse_bodies<double>(text, "fuzz");
        const collide::BodyBuffer<double> b = collide::to_body_buffer(t);
        for (std::size_t i = 0; i < b.size(); ++i) {
          const auto v = b.view();
          ASSERT_TRUE(std::isfinite(v.inv_mass[i]) && v.inv_mass[i] >= 0) << text;
          ASSERT_TRUE(std::isfinite(v.q.w[i]) && std::isfinite(v.q.x[i])) << text;
          ASSERT_TRUE(std::isfinite(v.v.x[i]) && std::isfinite(v.w.z[i])) << text;
        }
      } else {
        const auto c = collide::parse_contacts<float>(text, "fuzz", 3);
        for (std::size_t i = 0; i < c.size(); ++i) {
          const auto r = c.record(i);
          ASSERT_LT(r.a, 3u);
          ASSERT_LT(r.b, 3u);
          ASSERT_NE(r.a, r.b);
          ASSERT_TRUE(r.e >= 0 && r.e <= 1 && r.mu >= 0) << text;
          ASSERT_NEAR(std::sqrt(r.n[0] * r.n[0] + r.n[1] * r.n[1] + r.n[2] * r.n[2]), 1.0f, 1e-6f) << text;
        }
      }
      ++accepted;
    } catch (const SceneError& e) {
      ASSERT_EQ(e.file(), "fuzz");
      ASSERT_FALSE(e.column().empty()) << e.what();
    }
  }
  EXPECT_GT(accepted, 100);  // some corruptions are harmless (a digit changed)
}

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("collide_output_file_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::size_t entries() const { return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {})); }
  fs::path dir_;
};

TEST_F(OutputFileTest, NothingWithoutCommit) {
  {
    collide::OutputFile f((dir_ / "out.csv").string());
    f.write("partial");
    EXPECT_EQ(entries(), 1u);  // the temporary
  }
  EXPECT_EQ(entries(), 0u);
}

TEST_F(OutputFileTest, CommitReplacesAtomically) {
  { std::ofstream(dir_ / "out.csv") << "old"; }
  {
    collide::OutputFile f((dir_ / "out.csv").string());
    f.write("new");
    EXPECT_EQ(collide::read_file((dir_ / "out.csv").string()), "old");
    f.commit();
  }
  EXPECT_EQ(collide::read_file((dir_ / "out.csv").string()), "new");
  EXPECT_EQ(entries(), 1u);
}

// The scene writers (write_body_table, write_contacts) format rows in
// parallel blocks: their bytes are those of the one-row formatters
// (append_body_row, append_contact_row) over the whole scene, across more
// than one block, and the file is the in-memory text.
template <class T>
void expect_writers_match_row_formatters(const fs::path& dir) {
  collide::GenerateOptions o;
  o.friction = true;
  const collide::Scene<T> s = collide::generate_debris<T>(40000, o);  // 40000 contacts, 20001 bodies: 3 and 2 blocks
  const auto bodies = std::as_const(s.bodies).view();
  const collide::ContactView<T> contacts = s.contacts.view();
  ASSERT_GT(bodies.count, 16384u);

  std::string expected_bodies(collide::bodies_header());
  for (std::size_t i = 0; i < s.bodies.size(); ++i) collide::append_body_row(expected_bodies, s.bodies.record(i));
  std::string expected_contacts(collide::contacts_header());
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    collide::append_contact_row(expected_contacts, s.contacts.record(k));
  }
  const BodyTable<T> table = collide::to_body_table(bodies);
  EXPECT_EQ(collide::format_body_table(table), expected_bodies);
  EXPECT_EQ(collide::format_contacts(contacts), expected_contacts);

  const std::string b = (dir / "bodies.csv").string(), c = (dir / "contacts.csv").string();
  {
    collide::OutputFile ob(b), oc(c);
    collide::write_body_table(ob, table);
    collide::write_contacts(oc, contacts);
    ob.commit();
    oc.commit();
  }
  EXPECT_EQ(collide::read_file(b), expected_bodies);
  EXPECT_EQ(collide::read_file(c), expected_contacts);

  // Without per-contact e and mu: uniform_e and 0 in every row.
  collide::ContactView<T> plain = contacts;
  plain.e = nullptr;
  plain.uniform_e = T(0.25);
  plain.mu = nullptr;
  std::string expected_plain(collide::contacts_header());
  for (std::size_t k = 0; k < s.contacts.size(); ++k) {
    collide::ContactRecord<T> r = s.contacts.record(k);
    r.e = T(0.25);
    r.mu = T(0);
    collide::append_contact_row(expected_plain, r);
  }
  EXPECT_EQ(collide::format_contacts(plain), expected_plain);
}

TEST_F(OutputFileTest, SceneWritersMatchTheRowFormatters) {
  expect_writers_match_row_formatters<float>(dir_);
  expect_writers_match_row_formatters<double>(dir_);
}

// Every writer creates the folders its path names (docs/cli.md); a path that
// is a folder, or runs through a file, is refused.
TEST_F(OutputFileTest, MissingFoldersAreCreatedAndAFolderOrAFileInTheWayIsASceneError) {
  EXPECT_NO_THROW(collide::OutputFile((dir_ / "no" / "out.csv").string()));
  EXPECT_TRUE(std::filesystem::is_directory(dir_ / "no"));
  EXPECT_THROW(collide::OutputFile(dir_.string()), SceneError);
  std::ofstream(dir_ / "file") << "x";
  EXPECT_THROW(collide::OutputFile((dir_ / "file" / "out.csv").string()), SceneError);
}

}  // namespace
