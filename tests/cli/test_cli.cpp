// test_cli.cpp - the `collide` executable as a user sees it.
//
// Every test runs the real binary (COLLIDE_CLI_PATH) in its own directory
// under the build tree and checks exit codes, messages and files:
//   * every bad input of docs/collision-law.md: exit 1, a message naming the file, the row
//     and the column, and no output file (a pre-existing one untouched);
//   * gen: same seed, same bytes (whatever the thread count); other seed,
//     other bytes; the pile is the library's pile, its shuffle a permutation
//     of its contact rows;
//   * gen + solve --check round trips, both precisions and both paths;
//   * the written numbers read back to the values the library computes;
//   * inf of immovable bodies and all unchanged columns survive a solve;
//   * usage errors: exit 2, one line saying what is wrong and "see 'collide
//     <command> --help'" (not the help itself); every count states its range
//     (gen's scenes from 1, --passes from 1 to 1000000, --threads from 0 to
//     4096), a misspelt order is named;
//   * every output's missing directory is created.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"

#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::test::RunResult;
using collide::test::slurp;

void spit(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

const char* const kBodies =
    "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
    "2,0.8,0.8,0.8,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n"
    "1.5,0.2,0.6,0.6,0.9238795325112867,0,0,0.3826834323650898,0.8,2.2,0,-0.5,-4,0,0,0,-2\n"
    "4,2,1,2,1,0,0,0,-2,0.8,0,2,-1,0,0,1,0\n"
    "inf,inf,inf,inf,1,0,0,0,0,-5,0,0,0,0,0,0,0\n";

const char* const kContacts =
    "a,b,cx,cy,cz,nx,ny,nz,e,mu\n"
    "0,3,0,0,0,0,1,0,0.5,0.4\n"
    "1,0,0.4,1.6,0,0,1,0,0.8,0\n"
    "2,0,-1,0.9,0,-1,0,0,1,0.2\n"
    "2,3,-2,0,0,0,1,0,0.3,0.6\n";

/// Replaces line `line` (0 = header) of `text` with `replacement`.
std::string replace_line(const std::string& text, std::size_t line, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, l;
  for (std::size_t i = 0; std::getline(in, l); ++i) out += (i == line ? replacement : l) + "\n";
  return out;
}

/// A usage error as the tool reports it: exit 2 and two lines on stderr,
/// "collide <command>: what is wrong" and where the options are, not the help.
void expect_one_usage_line(const RunResult& r, const std::string& command, const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << what << "\n" << r.err;
  const std::string prefix = "collide " + command + ": ";
  const std::string see = "\nsee 'collide " + command + " --help'\n";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0U) << what << "\n" << r.err;
  ASSERT_GE(r.err.size(), see.size()) << what << "\n" << r.err;
  EXPECT_EQ(r.err.substr(r.err.size() - see.size()), see) << what << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << what << "\n" << r.err;
  EXPECT_EQ(r.err.find("usage:"), std::string::npos) << what << "\n" << r.err;
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    dir_ = fs::path(COLLIDE_TEST_TMP) / name;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  fs::path path(const std::string& name) const { return dir_ / name; }

  RunResult run(const std::vector<std::string>& args) const {
    return collide::test::run_program(COLLIDE_CLI_PATH, dir_, args);
  }

  /// The arguments of solve on the scene files of solve() with `extra` options.
  std::vector<std::string> solve_args(const std::vector<std::string>& extra = {}) const {
    std::vector<std::string> args = {"solve",
                                     "--bodies",
                                     path("bodies.csv").string(),
                                     "--contacts",
                                     path("contacts.csv").string(),
                                     "--out-bodies",
                                     path("ob.csv").string(),
                                     "--out-impulses",
                                     path("oj.csv").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }

  /// Writes the scene files and runs solve on them with `extra` options.
  RunResult solve(const std::string& bodies, const std::string& contacts,
                  const std::vector<std::string>& extra = {}) const {
    spit(path("bodies.csv"), bodies);
    spit(path("contacts.csv"), contacts);
    return run(solve_args(extra));
  }

  /// Files in the test directory other than the inputs (outputs, temporaries).
  std::vector<std::string> stray_files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n != "bodies.csv" && n != "contacts.csv") names.push_back(n);
    }
    return names;
  }

  fs::path dir_;
};

// ---------------------------------------------------------------------------
// Bad input: every case of docs/collision-law.md, "Bad input".
// ---------------------------------------------------------------------------

struct BadCase {
  const char* name;
  bool in_bodies;      // the defect is in bodies.csv (else contacts.csv)
  std::size_t line;    // line to replace (0 = header)
  const char* text;    // replacement line
  const char* row;     // expected "row R" or "header"
  const char* column;  // expected column name
};

const BadCase kBadCases[] = {
    // bodies.csv
    {"body_missing_column", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0", "row 1", "wz"},
    {"body_extra_column", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2,7", "row 1", "wz"},
    {"body_bad_header", true, 0, "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wq", "header", "wz"},
    {"body_header_missing_column", true, 0, "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy", "header", "wz"},
    {"body_header_extra_column", true, 0, "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz,extra", "header", "wz"},
    {"body_not_a_number", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,1.2.3,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "px"},
    {"body_empty_value", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,,-0.5,-4,0,0,0,-2", "row 1", "pz"},
    {"body_nan", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,nan,0,0,0,-2", "row 1", "vy"},
    {"body_nan_in_mass", true, 2, "NaN,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "m"},
    {"body_inf_position", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,inf,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "px"},
    {"body_inf_velocity", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,-Infinity,-2", "row 1", "wy"},
    {"body_inf_quaternion", true, 2, "1.5,0.2,0.6,0.6,inf,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "qw"},
    {"body_zero_mass", true, 2, "0,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "m"},
    {"body_negative_mass", true, 2, "-1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "m"},
    {"body_negative_inf_mass", true, 2, "-inf,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "m"},
    {"body_zero_moment", true, 2, "1.5,0.2,0,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "Iy"},
    {"body_negative_moment", true, 2, "1.5,0.2,0.6,-0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "Iz"},
    {"body_zero_quaternion", true, 2, "1.5,0.2,0.6,0.6,0,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "qw"},
    {"body_overflow", true, 2, "1.5,0.2,0.6,0.6,1,0,0,0,1e999,2.2,0,-0.5,-4,0,0,0,-2", "row 1", "px"},
    {"body_empty_line", true, 2, "", "row 1", "m"},
    // contacts.csv
    {"contact_missing_column", false, 3, "2,0,-1,0.9,0,-1,0,0,1", "row 2", "mu"},
    {"contact_extra_column", false, 3, "2,0,-1,0.9,0,-1,0,0,1,0.2,0", "row 2", "mu"},
    {"contact_bad_header", false, 0, "a,b,cx,cy,cz,nx,ny,nz,mu,e", "header", "e"},
    {"contact_not_a_number", false, 3, "2,0,-1,0.9,zero,-1,0,0,1,0.2", "row 2", "cz"},
    {"contact_nan", false, 3, "2,0,-1,nan,0,-1,0,0,1,0.2", "row 2", "cy"},
    {"contact_inf_point", false, 3, "2,0,inf,0.9,0,-1,0,0,1,0.2", "row 2", "cx"},
    {"contact_inf_mu", false, 3, "2,0,-1,0.9,0,-1,0,0,1,inf", "row 2", "mu"},
    {"contact_normal_too_long", false, 3, "2,0,-1,0.9,0,-1.01,0,0,1,0.2", "row 2", "nx"},
    {"contact_normal_too_short", false, 3, "2,0,-1,0.9,0,0,0.99,0,1,0.2", "row 2", "nx"},
    {"contact_normal_zero", false, 3, "2,0,-1,0.9,0,0,0,0,1,0.2", "row 2", "nx"},
    {"contact_e_above_one", false, 3, "2,0,-1,0.9,0,-1,0,0,1.5,0.2", "row 2", "e"},
    {"contact_e_negative", false, 3, "2,0,-1,0.9,0,-1,0,0,-0.1,0.2", "row 2", "e"},
    {"contact_mu_negative", false, 3, "2,0,-1,0.9,0,-1,0,0,1,-0.2", "row 2", "mu"},
    {"contact_a_out_of_range", false, 3, "4,0,-1,0.9,0,-1,0,0,1,0.2", "row 2", "a"},
    {"contact_b_out_of_range", false, 3, "2,99,-1,0.9,0,-1,0,0,1,0.2", "row 2", "b"},
    {"contact_b_negative", false, 3, "2,-1,-1,0.9,0,-1,0,0,1,0.2", "row 2", "b"},
    {"contact_a_not_integer", false, 3, "1.5,0,-1,0.9,0,-1,0,0,1,0.2", "row 2", "a"},
    {"contact_self", false, 3, "2,2,-1,0.9,0,-1,0,0,1,0.2", "row 2", "b"},
};

class BadInputTest : public CliTest, public ::testing::WithParamInterface<BadCase> {};

TEST_P(BadInputTest, RejectedWithLocatedMessageAndNoOutput) {
  const BadCase& c = GetParam();
  const std::string bodies = c.in_bodies ? replace_line(kBodies, c.line, c.text) : kBodies;
  const std::string contacts = c.in_bodies ? kContacts : replace_line(kContacts, c.line, c.text);
  const RunResult r = solve(bodies, contacts);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string file = path(c.in_bodies ? "bodies.csv" : "contacts.csv").string();
  EXPECT_EQ(r.err.rfind("collide: " + file + ":", 0), 0u) << r.err;
  std::string line = ":";
  line.append(std::to_string(c.line + 1)).append(": ");
  EXPECT_NE(r.err.find(line), std::string::npos) << "expected line " << line << " in: " << r.err;
  // "row 1, column 'px': ..." or "header, column 'wz': ...".
  const std::string located = std::string(c.row) + ", column '" + c.column + "': ";
  EXPECT_NE(r.err.find(located), std::string::npos) << "expected \"" << located << "\" in: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  EXPECT_TRUE(stray_files().empty()) << "output written: " << stray_files().front();
}

TEST_P(BadInputTest, PreExistingOutputsUntouched) {
  const BadCase& c = GetParam();
  const std::string bodies = c.in_bodies ? replace_line(kBodies, c.line, c.text) : kBodies;
  const std::string contacts = c.in_bodies ? kContacts : replace_line(kContacts, c.line, c.text);
  spit(path("ob.csv"), "old bodies\n");
  spit(path("oj.csv"), "old impulses\n");
  const RunResult r = solve(bodies, contacts);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(slurp(path("ob.csv")), "old bodies\n");
  EXPECT_EQ(slurp(path("oj.csv")), "old impulses\n");
  EXPECT_EQ(stray_files().size(), 2u) << "a temporary file was left behind";
}

INSTANTIATE_TEST_SUITE_P(Spec, BadInputTest, ::testing::ValuesIn(kBadCases),
                         [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.name); });

TEST_F(CliTest, EmptyBodiesFileIsMissingHeader) {
  const RunResult r = solve("", kContacts);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(path("bodies.csv").string() + ":1: header, column 'm': missing header"), std::string::npos)
      << r.err;
  EXPECT_TRUE(stray_files().empty());
}

TEST_F(CliTest, EmptyContactsFileIsMissingHeader) {
  const RunResult r = solve(kBodies, "");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(path("contacts.csv").string() + ":1: header, column 'a': missing header"), std::string::npos)
      << r.err;
  EXPECT_TRUE(stray_files().empty());
}

TEST_F(CliTest, MissingInputFile) {
  const RunResult r = run({"solve", "--bodies", path("nope.csv").string(), "--contacts", path("nope2.csv").string(),
                           "--out-bodies", path("ob.csv").string(), "--out-impulses", path("oj.csv").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nope.csv"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("ob.csv")));
}

TEST_F(CliTest, FirstErrorInFileOrderIsReported) {
  // Two bad rows: the earlier one is reported, whatever the thread count.
  std::string bodies = replace_line(kBodies, 2, "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,oops");
  bodies = replace_line(bodies, 3, "-4,2,1,2,1,0,0,0,-2,0.8,0,2,-1,0,0,1,0");
  for (const char* threads : {"1", "2"}) {
    const RunResult r = solve(bodies, kContacts, {"--threads", threads});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(":3: row 1, column 'wz'"), std::string::npos) << r.err;
  }
}

// ---------------------------------------------------------------------------
// Accepted input variants.
// ---------------------------------------------------------------------------

TEST_F(CliTest, AcceptsInfSpellingsCrlfAndNoTrailingNewline) {
  ASSERT_EQ(solve(kBodies, kContacts).exit_code, 0);
  const std::string reference = slurp(path("oj.csv"));
  std::string bodies = replace_line(kBodies, 4, "+inf,Infinity,INF,+Infinity,1,0,0,0,0,-5,0,0,0,0,0,0,0");
  std::string crlf;
  for (const char c : bodies) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  std::string contacts = kContacts;
  contacts.pop_back();  // no newline at the end
  const RunResult r = solve(crlf, contacts);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(path("oj.csv")), reference);
}

TEST_F(CliTest, NormalWithinToleranceIsNormalised) {
  ASSERT_EQ(solve(kBodies, kContacts).exit_code, 0);
  const std::string reference = slurp(path("oj.csv"));
  // |n| = 1.0009: accepted and normalised to the unit normal of the reference.
  const RunResult r = solve(kBodies, replace_line(kContacts, 1, "0,3,0,0,0,0,1.0009,0,0.5,0.4"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(path("oj.csv")), reference);
}

TEST_F(CliTest, EmptySceneWritesHeadersOnly) {
  const RunResult r = solve("m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n", "a,b,cx,cy,cz,nx,ny,nz,e,mu\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(path("ob.csv")), "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n");
  EXPECT_EQ(slurp(path("oj.csv")), "jx,jy,jz\n");
}

// ---------------------------------------------------------------------------
// Results.
// ---------------------------------------------------------------------------

/// The in-process result of the library on the same files, for comparison.
template <class T>
struct LibraryResult {
  collide::BodyTable<T> table;
  collide::BodyBuffer<T> bodies;
  collide::ImpulseBuffer<T> impulses;
};

template <class T>
LibraryResult<T> solve_in_process(const fs::path& bodies_file, const fs::path& contacts_file) {
  LibraryResult<T> r;
  r.table = collide::read_bodies<T>(bodies_file.string());
  const auto contacts = collide::read_contacts<T>(contacts_file.string(), r.table.size());
  r.bodies = collide::to_body_buffer(r.table);
  r.impulses = collide::ImpulseBuffer<T>(contacts.size());
  collide::solve(r.bodies.view(), contacts.view(), r.impulses.view());
  return r;
}

template <class T>
void expect_outputs_match_library(const fs::path& bodies, const fs::path& contacts, const fs::path& out_bodies,
                                  const fs::path& out_impulses) {
  const LibraryResult<T> lib = solve_in_process<T>(bodies, contacts);
  const collide::BodyTable<T> out = collide::read_bodies<T>(out_bodies.string());
  const std::string impulses_text = collide::read_file(out_impulses.string());
  ASSERT_EQ(out.size(), lib.table.size());
  const collide::BodyView<const T> v = std::as_const(lib.bodies).view();
  for (std::size_t i = 0; i < out.size(); ++i) {
    using Table = collide::BodyTable<T>;
    // Unchanged columns: bit for bit the input values (inf included).
    for (std::size_t k = 0; k < Table::vx; ++k) {
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
      ASSERT_EQ(std::memcmp(&out.column[k][i], &lib.table.column[k][i], sizeof(T)), 0)
          << "body " << i << " column " << collide::kBodyColumns[k];
    }
    const T expected[6] = {v.v.x[i], v.v.y[i], v.v.z[i], v.w.x[i], v.w.y[i], v.w.z[i]};
    for (std::size_t k = 0; k < 6; ++k) {
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): the bits are the point
      ASSERT_EQ(std::memcmp(&out.column[Table::vx + k][i], &expected[k], sizeof(T)), 0)
          << "body " << i << " column " << collide::kBodyColumns[Table::vx + k];
    }
  }
  // Impulses: read back as T, bit for bit.
  std::istringstream in(impulses_text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "jx,jy,jz");
  const collide::ImpulseView<const T> j = std::as_const(lib.impulses).view();
  for (std::size_t k = 0; k < j.count; ++k) {
    ASSERT_TRUE(std::getline(in, line));
    T x, y, z;
    const char* p = line.data();
    const char* e = p + line.size();
    auto r1 = std::from_chars(p, e, x);
    auto r2 = std::from_chars(r1.ptr + 1, e, y);
    auto r3 = std::from_chars(r2.ptr + 1, e, z);
    ASSERT_EQ(r3.ptr, e) << line;
    EXPECT_EQ(x, j.j.x[k]);
    EXPECT_EQ(y, j.j.y[k]);
    EXPECT_EQ(z, j.j.z[k]);
  }
  EXPECT_FALSE(std::getline(in, line)) << "extra impulse rows";
}

TEST_F(CliTest, DoubleOutputReadsBackToLibraryValues) {
  ASSERT_EQ(solve(kBodies, kContacts, {"--precision", "double"}).exit_code, 0);
  expect_outputs_match_library<double>(path("bodies.csv"), path("contacts.csv"), path("ob.csv"), path("oj.csv"));
}

TEST_F(CliTest, FloatOutputReadsBackToLibraryValues) {
  ASSERT_EQ(solve(kBodies, kContacts, {"--precision", "float"}).exit_code, 0);
  expect_outputs_match_library<float>(path("bodies.csv"), path("contacts.csv"), path("ob.csv"), path("oj.csv"));
}

TEST_F(CliTest, ImmovableBodyKeepsInfAndIsNotMoved) {
  ASSERT_EQ(solve(kBodies, kContacts).exit_code, 0);
  const std::string out = slurp(path("ob.csv"));
  // The ground row is copied through exactly: inf stays "inf", v and w stay 0.
  EXPECT_NE(out.find("\ninf,inf,inf,inf,1,0,0,0,0,-5,0,0,0,0,0,0,0\n"), std::string::npos) << out;
}

TEST_F(CliTest, OtherColumnsCopiedUnchanged) {
  // Values with many digits, an unnormalised quaternion and a partly locked
  // body: every column but v and w comes out as it went in.
  const std::string bodies =
      "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
      "1.2345678901234567,0.30000000000000004,inf,7e-3,2,0,0,2,1e10,-0.1,3.3333333333333335,1,2,3,4,5,6\n"
      "inf,1,1,1,0.5,0.5,0.5,0.5,0,0,0,0,0,0,0,0,0\n";
  const std::string contacts = "a,b,cx,cy,cz,nx,ny,nz,e,mu\n0,1,1e10,-0.5,3,0,-1,0,0.5,0.1\n";
  ASSERT_EQ(solve(bodies, contacts).exit_code, 0);
  const collide::BodyTable<double> in = collide::parse_bodies<double>(bodies, "in");
  const collide::BodyTable<double> out = collide::read_bodies<double>(path("ob.csv").string());
  for (std::size_t i = 0; i < 2; ++i) {
    for (std::size_t k = 0; k < collide::BodyTable<double>::vx; ++k) {
      EXPECT_EQ(out.column[k][i], in.column[k][i]) << "body " << i << " column " << collide::kBodyColumns[k];
    }
  }
  EXPECT_NE(out.column[collide::BodyTable<double>::vy][0], 2.0) << "body 0 should have been moved";
}

TEST_F(CliTest, PathsAndThreadsGiveIdenticalBytes) {
  ASSERT_EQ(run({"gen", "--debris", "3000", "--out", dir_.string(), "--friction"}).exit_code, 0);
  std::string reference_bodies, reference_impulses;
  for (const char* precision : {"float", "double"}) {
    bool first = true;
    for (const char* p : {"simd", "scalar"}) {
      for (const char* threads : {"1", "2", "0"}) {
        const RunResult r =
            run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
                 "--out-bodies", path("ob.csv").string(), "--out-impulses", path("oj.csv").string(), "--precision",
                 precision, "--path", p, "--threads", threads});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        if (first) {
          reference_bodies = slurp(path("ob.csv"));
          reference_impulses = slurp(path("oj.csv"));
          first = false;
        } else {
          EXPECT_EQ(slurp(path("ob.csv")), reference_bodies) << precision << " " << p << " " << threads;
          EXPECT_EQ(slurp(path("oj.csv")), reference_impulses) << precision << " " << p << " " << threads;
        }
      }
    }
  }
}

TEST_F(CliTest, SuccessfulSolveReplacesExistingOutputs) {
  spit(path("ob.csv"), "old\n");
  spit(path("oj.csv"), "old\n");
  ASSERT_EQ(solve(kBodies, kContacts).exit_code, 0);
  EXPECT_EQ(slurp(path("oj.csv")).rfind("jx,jy,jz\n", 0), 0u);
  EXPECT_EQ(slurp(path("ob.csv")).rfind("m,Ix,", 0), 0u);
  EXPECT_EQ(stray_files().size(), 2u) << "temporary files left behind";
}

TEST_F(CliTest, OutputMayReplaceTheInput) {
  ASSERT_EQ(solve(kBodies, kContacts).exit_code, 0);
  const std::string expected = slurp(path("ob.csv"));
  const RunResult r =
      run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
           "--out-bodies", path("bodies.csv").string(), "--out-impulses", path("oj.csv").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(path("bodies.csv")), expected);
}

TEST_F(CliTest, UnwritableOutputWritesNothing) {
  spit(path("bodies.csv"), kBodies);
  spit(path("contacts.csv"), kContacts);
  // A missing directory is created (OutputsCreateMissingDirectories); one a
  // file stands in the way of cannot be.
  spit(path("blocker"), "a file, not a directory");
  const RunResult r =
      run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
           "--out-bodies", path("ob.csv").string(), "--out-impulses", path("blocker/oj.csv").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("blocker/oj.csv"), std::string::npos) << r.err;
  EXPECT_EQ(stray_files(), std::vector<std::string>{"blocker"});
}

TEST_F(CliTest, ExampleSceneSolvesAndChecks) {
  const fs::path data = fs::path(COLLIDE_DATA_DIR) / "example";
  const RunResult r =
      run({"solve", "--bodies", (data / "bodies.csv").string(), "--contacts", (data / "contacts.csv").string(),
           "--out-bodies", path("ob.csv").string(), "--out-impulses", path("oj.csv").string(), "--check", "--stats"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
}

// ---------------------------------------------------------------------------
// --stats and --check.
// ---------------------------------------------------------------------------

TEST_F(CliTest, StatsIsOneJsonObjectWithTheDocumentedFields) {
  const RunResult r = solve(kBodies, kContacts, {"--stats", "--precision", "float", "--path", "scalar"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(r.err.front(), '{');
  EXPECT_EQ(r.err.substr(r.err.size() - 2), "}\n");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  for (const char* field :
       {"\"collisions\": 4", "\"kernel_seconds\"", "\"collisions_per_second\"", "\"precision\": \"float\"",
        "\"threads\"", "\"model\": \"rigid\"", "\"path\": \"scalar\"", "\"lanes\": 1", "\"batches\"",
        "\"schedule_seconds\"", "\"isa_choice\": \"baseline\"", "\"allocate_seconds\""}) {
    EXPECT_NE(r.err.find(field), std::string::npos) << field << " missing in " << r.err;
  }
  EXPECT_EQ(r.err.find("check"), std::string::npos) << "no check fields without --check";
}

/// The number after "key": in a one-line JSON object (NaN when absent).
double stats_number(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

TEST_F(CliTest, StatsSaysHowMuchIsFileIo) {
  const RunResult r = solve(kBodies, kContacts, {"--stats"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double read = stats_number(r.err, "read_seconds");
  const double write = stats_number(r.err, "write_seconds");
  const double io = stats_number(r.err, "io_seconds");
  const double fraction = stats_number(r.err, "io_fraction");
  // The solve: its schedule, its allocate phase and its kernels.
  const double rest = stats_number(r.err, "schedule_seconds") + stats_number(r.err, "allocate_seconds") +
                      stats_number(r.err, "kernel_seconds");
  ASSERT_TRUE(std::isfinite(io)) << r.err;
  // Printed with 9 significant digits: equal to that precision.
  EXPECT_NEAR(io, read + write, 1e-8 * io + 1e-12) << r.err;
  EXPECT_NEAR(fraction, io / (io + rest), 1e-6) << r.err;
  EXPECT_GT(fraction, 0);
  EXPECT_LE(fraction, 1);
}

TEST_F(CliTest, StatsReportsTheAllocatePhaseApartFromTheKernel) {
  // A pile in the colour order: the solve copies its contacts into the
  // solver's arrays, which a one-shot solve allocates and touches first.
  ASSERT_EQ(run({"gen", "--pile", "20", "--out", dir_.string()}).exit_code, 0);
  for (const char* order : {"input", "colour"}) {
    const RunResult r = run({"solve", "--bodies", path("bodies.csv").string(), "--contacts",
                             path("contacts.csv").string(), "--out-bodies", path("ob.csv").string(), "--out-impulses",
                             path("oj.csv").string(), "--order", order, "--stats"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const double allocate = stats_number(r.err, "allocate_seconds");
    const double kernel = stats_number(r.err, "kernel_seconds");
    EXPECT_TRUE(std::isfinite(allocate)) << r.err;
    EXPECT_GE(allocate, 0) << r.err;
    EXPECT_TRUE(std::isfinite(kernel)) << r.err;
    EXPECT_GE(kernel, 0) << r.err;
    if (std::string(order) == "colour") {
      EXPECT_GT(allocate, 0) << r.err;
    }
  }
}

TEST_F(CliTest, StatsReportsCheck) {
  const RunResult r = solve(kBodies, kContacts, {"--stats", "--check"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* field :
       {"\"max_impulse_error_eps\"", "\"max_relative_error\"", "\"error_bound_eps\": 64", "\"check_passed\": true"}) {
    EXPECT_NE(r.err.find(field), std::string::npos) << field << " missing in " << r.err;
  }
}

TEST_F(CliTest, WithoutStatsNothingIsPrinted) {
  const RunResult r = solve(kBodies, kContacts, {"--check"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// ---------------------------------------------------------------------------
// --model.
// ---------------------------------------------------------------------------

TEST_F(CliTest, ModelThatDoesNotFitIsRejectedAndWritesNothing) {
  const RunResult r = solve(kBodies, kContacts, {"--model", "sphere"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--model sphere does not fit"), std::string::npos) << r.err;
  EXPECT_TRUE(stray_files().empty());
}

TEST_F(CliTest, SmallerModelsOnScenesThatFitThem) {
  // Equal moments everywhere: the sphere model is the law.
  const std::string bodies =
      "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
      "2,0.8,0.8,0.8,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n"
      "1.5,0.6,0.6,0.6,0.9238795325112867,0,0,0.3826834323650898,0.8,2.2,0,-0.5,-4,0,0,0,-2\n"
      "4,2,2,2,1,0,0,0,-2,0.8,0,2,-1,0,0,1,0\n"
      "inf,inf,inf,inf,1,0,0,0,0,-5,0,0,0,0,0,0,0\n";
  for (const char* model : {"sphere", "auto"}) {
    const RunResult r = solve(bodies, kContacts, {"--model", model, "--stats", "--check"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("\"model\": \"sphere\""), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
  }
}

/// A chain of three touching spheres (radius 0.5) with unequal moments and
/// spin, centred at `offset`, written as a broadphase in float writes it: n
/// the centre difference normalised in float, c = pb + 0.5 n in float, every
/// number printed to round trip. Returns {bodies, contacts}.
std::pair<std::string, std::string> broadphase_chain(float offset) {
  const float p[3][3] = {{offset + 0.1F, offset + 0.2F, offset + 0.3F},
                         {offset + 0.1F + 0.577F, offset + 0.2F + 0.577F, offset + 0.3F + 0.576F},
                         {offset + 0.1F + 0.577F + 0.8F, offset + 0.2F + 0.577F - 0.599F, offset + 0.3F + 0.576F}};
  auto num = [](float x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(x));
    return std::string(buf);
  };
  std::string bodies = "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n";
  const char* const rest[3] = {",0.1,0.2,0.3,0.5,0.5,0.5,0.5,", ",0.3,0.15,0.2,0.9238795,0,0,0.38268343,",
                               ",0.12,0.25,0.2,1,0,0,0,"};
  const char* const motion[3] = {",1,0.5,0.7,3,-2,1\n", ",-0.5,0.2,0,0,4,-1\n", ",-1.5,1,0.2,-2,0,5\n"};
  for (int i = 0; i < 3; ++i) {
    bodies +=
        std::string(i == 1 ? "2" : "1") + rest[i] + num(p[i][0]) + "," + num(p[i][1]) + "," + num(p[i][2]) + motion[i];
  }
  std::string contacts = "a,b,cx,cy,cz,nx,ny,nz,e,mu\n";
  for (int b = 0; b < 2; ++b) {
    const int a = b + 1;
    float d[3], n[3], c[3];
    for (int i = 0; i < 3; ++i) d[i] = p[a][i] - p[b][i];
    const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; ++i) n[i] = d[i] / len;
    for (int i = 0; i < 3; ++i) c[i] = p[b][i] + 0.5F * n[i];
    contacts += std::to_string(a) + "," + std::to_string(b) + "," + num(c[0]) + "," + num(c[1]) + "," + num(c[2]) +
                "," + num(n[0]) + "," + num(n[1]) + "," + num(n[2]) + ",0.7,0\n";
  }
  return {bodies, contacts};
}

TEST_F(CliTest, AutoPicksParticleForABroadphaseScene) {
  // Normals through both centres up to float rounding, bodies with moments
  // and spin: the particle model is within the bound, and --check agrees.
  const auto [bodies, contacts] = broadphase_chain(0.0F);
  for (const char* model : {"auto", "particle"}) {
    const RunResult r = solve(bodies, contacts, {"--precision", "float", "--model", model, "--stats", "--check"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("\"model\": \"particle\""), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
  }
}

TEST_F(CliTest, ForcedParticleRefusedWhereTheRotationMatters) {
  // The same chain 2000 radii from the origin: its float contact points miss
  // the centres by over 300 eps (computed for this offset; how far depends on
  // where the rounding of c falls); auto runs rigid, --model particle is
  // refused naming the contact, and nothing is written.
  const auto [bodies, contacts] = broadphase_chain(1000.0F);
  const RunResult r = solve(bodies, contacts, {"--precision", "float", "--stats", "--check"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("\"model\": \"rigid\""), std::string::npos) << r.err;
  fs::remove(path("ob.csv"));
  fs::remove(path("oj.csv"));
  const RunResult f = solve(bodies, contacts, {"--precision", "float", "--model", "particle"});
  EXPECT_EQ(f.exit_code, 1);
  EXPECT_NE(f.err.find("--model particle does not fit the scene"), std::string::npos) << f.err;
  EXPECT_NE(f.err.find("contact 0: the normal does not pass through the centre of body"), std::string::npos) << f.err;
  EXPECT_TRUE(stray_files().empty());
}

// ---------------------------------------------------------------------------
// gen.
// ---------------------------------------------------------------------------

TEST_F(CliTest, GenSameSeedSameBytesDifferentSeedDifferentBytes) {
  for (const auto& [kind, n] : std::vector<std::pair<std::string, std::string>>{
           {"--pairs", "20000"}, {"--debris", "20000"}, {"--pile", "20"}, {"--chain", "20000"}}) {
    ASSERT_EQ(run({"gen", kind, n, "--out", path("a").string(), "--seed", "7", "--threads", "1"}).exit_code, 0);
    ASSERT_EQ(run({"gen", kind, n, "--out", path("b").string(), "--seed", "7"}).exit_code, 0);
    ASSERT_EQ(run({"gen", kind, n, "--out", path("c").string(), "--seed", "8"}).exit_code, 0);
    for (const char* f : {"bodies.csv", "contacts.csv"}) {
      const std::string a = slurp(path("a") / f);
      EXPECT_EQ(a, slurp(path("b") / f)) << kind << " " << f;
      EXPECT_NE(a, slurp(path("c") / f)) << kind << " " << f;
    }
    fs::remove_all(path("a"));
    fs::remove_all(path("b"));
    fs::remove_all(path("c"));
  }
}

TEST_F(CliTest, GenPairsIsAPrefixOfALargerScene) {
  // Pair k depends on (seed, k) only: the first 100 pairs of 1000 are 100 pairs.
  ASSERT_EQ(run({"gen", "--pairs", "100", "--out", path("small").string()}).exit_code, 0);
  ASSERT_EQ(run({"gen", "--pairs", "1000", "--out", path("large").string()}).exit_code, 0);
  for (const char* f : {"bodies.csv", "contacts.csv"}) {
    const std::string small = slurp(path("small") / f);
    const std::string large = slurp(path("large") / f);
    EXPECT_EQ(large.substr(0, small.size()), small) << f;
  }
}

TEST_F(CliTest, GenFrictionDrawsMu) {
  ASSERT_EQ(run({"gen", "--pairs", "50", "--out", path("f").string(), "--friction"}).exit_code, 0);
  ASSERT_EQ(run({"gen", "--pairs", "50", "--out", path("n").string()}).exit_code, 0);
  const auto with = collide::read_contacts<double>((path("f") / "contacts.csv").string(), 100);
  const auto without = collide::read_contacts<double>((path("n") / "contacts.csv").string(), 100);
  int positive = 0;
  for (std::size_t k = 0; k < 50; ++k) {
    positive += with.record(k).mu > 0 ? 1 : 0;
    EXPECT_EQ(without.record(k).mu, 0.0);
    EXPECT_EQ(with.record(k).e, without.record(k).e) << "friction changes only mu";
  }
  EXPECT_GT(positive, 40);
}

TEST_F(CliTest, GenDebrisHasGroundLast) {
  ASSERT_EQ(run({"gen", "--debris", "400", "--out", dir_.string()}).exit_code, 0);
  const auto table = collide::read_bodies<double>(path("bodies.csv").string());
  ASSERT_EQ(table.size(), 201u);
  EXPECT_TRUE(std::isinf(table.column[0][200]));
  const auto contacts = collide::read_contacts<double>(path("contacts.csv").string(), table.size());
  std::size_t ground = 0;
  for (std::size_t k = 0; k < contacts.size(); ++k) ground += contacts.record(k).b == 200 ? 1 : 0;
  EXPECT_EQ(ground, 100u);
  EXPECT_NE(slurp(path("bodies.csv")).find("\ninf,inf,inf,inf,1,0,0,0,"), std::string::npos);
}

/// The lines of a text after its first (the header), sorted.
std::vector<std::string> sorted_rows(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) rows.push_back(line);
  std::sort(rows.begin(), rows.end());
  return rows;
}

/// Every body of a bodies file `collide gen` wrote, value for value, against
/// the library's own drawing of it: draw(i, record) fills body i.
template <class Table, class Draw>
void expect_drawn_bodies(const Table& table, const Draw& draw) {
  for (std::size_t i = 0; i < table.size(); ++i) {
    collide::BodyRecord<double> body;
    draw(i, body);
    const double expected[17] = {body.m,    body.I[0], body.I[1], body.I[2], body.q[0], body.q[1],
                                 body.q[2], body.q[3], body.p[0], body.p[1], body.p[2], body.v[0],
                                 body.v[1], body.v[2], body.w[0], body.w[1], body.w[2]};
    for (std::size_t k = 0; k < 17; ++k) ASSERT_EQ(table.column[k][i], expected[k]) << "body " << i << " column " << k;
  }
}

/// The same for every contact of a contacts file: draw(k, record) fills contact k.
template <class Contacts, class Draw>
void expect_drawn_contacts(const Contacts& contacts, const Draw& draw) {
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    collide::ContactRecord<double> c;
    draw(k, c);
    const auto got = contacts.record(k);
    ASSERT_EQ(got.a, c.a) << k;
    ASSERT_EQ(got.b, c.b) << k;
    for (int j = 0; j < 3; ++j) {
      ASSERT_EQ(got.c[j], c.c[j]) << k;
      ASSERT_EQ(got.n[j], c.n[j]) << k;
    }
    ASSERT_EQ(got.e, c.e) << k;
    ASSERT_EQ(got.mu, c.mu) << k;
  }
}

TEST_F(CliTest, GenChainWritesTheLibrarysChain) {
  // --chain N: N contacts over N + 1 boxes, the values of generate.hpp's
  // chain exactly, each contact sharing a box with the one before.
  const std::size_t n = 300;
  const RunResult r = run({"gen", "--chain", "300", "--out", dir_.string(), "--seed", "5", "--friction"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = collide::read_bodies<double>(path("bodies.csv").string());
  ASSERT_EQ(table.size(), collide::chain_body_count(n));
  ASSERT_EQ(table.size(), n + 1);
  const auto contacts = collide::read_contacts<double>(path("contacts.csv").string(), table.size());
  ASSERT_EQ(contacts.size(), n);
  collide::GenerateOptions options;
  options.seed = 5;
  options.friction = true;
  expect_drawn_bodies(
      table, [&](std::size_t i, collide::BodyRecord<double>& body) { collide::draw_chain_body(options, n, i, body); });
  expect_drawn_contacts(contacts, [&](std::size_t k, collide::ContactRecord<double>& c) {
    collide::draw_chain_contact(options, n, k, c);
  });
  for (std::size_t k = 0; k < n; ++k) {
    ASSERT_EQ(contacts.record(k).a, k);
    ASSERT_EQ(contacts.record(k).b, k + 1);
  }
}

TEST_F(CliTest, GenPileWritesTheLibrarysPile) {
  // --pile S: S boxes per side, the values of generate.hpp's pile exactly
  // (the shortest text of each double reads back to it).
  const std::size_t side = 6;
  const RunResult r = run({"gen", "--pile", "6", "--out", dir_.string(), "--seed", "4", "--friction"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = collide::read_bodies<double>(path("bodies.csv").string());
  ASSERT_EQ(table.size(), collide::pile_body_count(side));
  ASSERT_EQ(table.size(), 217U);
  const auto contacts = collide::read_contacts<double>(path("contacts.csv").string(), table.size());
  ASSERT_EQ(contacts.size(), collide::pile_contact_count(side));
  ASSERT_EQ(contacts.size(), 576U);  // 3 * 36 * 5 + 36
  collide::GenerateOptions options;
  options.seed = 4;
  options.friction = true;
  expect_drawn_bodies(table, [&](std::size_t i, collide::BodyRecord<double>& body) {
    collide::draw_pile_body(options, side, i, body);
  });
  EXPECT_TRUE(std::isinf(table.column[0][216])) << "the ground is last and immovable";
  expect_drawn_contacts(contacts, [&](std::size_t k, collide::ContactRecord<double>& c) {
    collide::draw_pile_contact(options, side, k, c);
  });
  // Cell order: the first cell's +x, +y, +z neighbours, then the ground.
  EXPECT_EQ(contacts.record(0).b, 1U);
  EXPECT_EQ(contacts.record(1).b, 6U);
  EXPECT_EQ(contacts.record(2).b, 36U);
  EXPECT_EQ(contacts.record(3).b, 216U);
}

TEST_F(CliTest, GenPileShuffleIsAPermutationOfTheRows) {
  ASSERT_EQ(run({"gen", "--pile", "9", "--out", path("o").string(), "--seed", "3"}).exit_code, 0);
  ASSERT_EQ(
      run({"gen", "--pile", "9", "--out", path("s").string(), "--seed", "3", "--shuffle", "--threads", "1"}).exit_code,
      0);
  ASSERT_EQ(run({"gen", "--pile", "9", "--out", path("t").string(), "--seed", "3", "--shuffle"}).exit_code, 0);
  // The bodies are the same; the contact rows are the same rows in another
  // order, the same order whatever the thread count.
  EXPECT_EQ(slurp(path("s") / "bodies.csv"), slurp(path("o") / "bodies.csv"));
  const std::string ordered = slurp(path("o") / "contacts.csv");
  const std::string shuffled = slurp(path("s") / "contacts.csv");
  EXPECT_NE(shuffled, ordered);
  EXPECT_EQ(shuffled, slurp(path("t") / "contacts.csv"));
  EXPECT_EQ(sorted_rows(shuffled), sorted_rows(ordered));
  EXPECT_EQ(sorted_rows(ordered).size(), collide::pile_contact_count(9));
}

TEST_F(CliTest, GenPileUsageErrorsSayWhy) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"gen", "--pile", "1626", "--out", path("g").string()}, "--pile must be an integer from 1 to 1625, got '1626'"},
      {{"gen", "--pile", "-3", "--out", path("g").string()}, "--pile must be an integer from 1 to 1625, got '-3'"},
      {{"gen", "--pile", "many", "--out", path("g").string()}, "--pile must be an integer from 1 to 1625, got 'many'"},
      {{"gen", "--pile", "--out", path("g").string()}, "option '--pile' needs a value"},
      {{"gen", "--pile", "3", "--debris", "10", "--out", path("g").string()},
       "give exactly one of --pairs N, --debris N, --pile S and --chain N"},
      {{"gen", "--chain", "10", "--shuffle", "--out", path("g").string()}, "--shuffle is for --pile"},
      {{"gen", "--pairs", "10", "--shuffle", "--out", path("g").string()}, "--shuffle is for --pile"},
      {{"gen", "--debris", "10", "--shuffle", "--out", path("g").string()}, "--shuffle is for --pile"},
      {{"gen", "--pile", "3", "--shuffle=yes", "--out", path("g").string()}, "takes no value"},
      {{"gen", "--pile", "3"}, "missing required option '--out'"},
  };
  for (const auto& [args, message] : cases) {
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    const RunResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << joined << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << joined << "\n" << r.err;
    expect_one_usage_line(r, "gen", joined);
    EXPECT_FALSE(fs::exists(path("g"))) << joined;
  }
  // The help says what S is.
  const RunResult help = run({"gen", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--pile S       a pile of S x S x S boxes, S boxes per side"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--shuffle"), std::string::npos) << help.out;
}

TEST_F(CliTest, GenThenSolveChecksInBothPrecisionsAndPaths) {
  // The pile: 12^3 boxes, 4896 contacts, in cell order and shuffled.
  const std::vector<std::vector<std::string>> scenes = {
      {"--pairs", "2000"}, {"--debris", "2000"}, {"--pile", "12"}, {"--pile", "12", "--shuffle"}};
  for (const auto& scene : scenes) {
    const std::string kind = scene[0] + (scene.size() > 2 ? " --shuffle" : "");
    std::vector<std::string> args = {"gen", "--out", dir_.string(), "--seed", "11", "--friction"};
    args.insert(args.end(), scene.begin(), scene.end());
    ASSERT_EQ(run(args).exit_code, 0);
    for (const char* precision : {"float", "double"}) {
      for (const char* p : {"simd", "scalar"}) {
        const RunResult r =
            run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
                 "--out-bodies", path("ob.csv").string(), "--out-impulses", path("oj.csv").string(), "--precision",
                 precision, "--path", p, "--check", "--stats"});
        EXPECT_EQ(r.exit_code, 0) << kind << " " << precision << " " << p << ": " << r.err;
        EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
      }
    }
  }
}

TEST_F(CliTest, GenWritesNothingOnUsageError) {
  const RunResult r = run({"gen", "--pairs", "ten", "--out", path("x").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(path("x")));
}

// ---------------------------------------------------------------------------
// Usage.
// ---------------------------------------------------------------------------

TEST_F(CliTest, Help) {
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"--help"}, {"solve", "--help"}, {"gen", "--help"}, {"help"}}) {
    const RunResult r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args[0];
    EXPECT_NE(r.out.find("usage: collide"), std::string::npos) << r.out;
  }
}

TEST_F(CliTest, MainHelpNamesEveryScene) {
  const RunResult r = run({"--help"});
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("(pairs, debris, pile or chain)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bodies, contacts or impulses file"), std::string::npos) << r.out;
}

TEST_F(CliTest, UsageErrorsExitTwo) {
  spit(path("bodies.csv"), kBodies);
  spit(path("contacts.csv"), kContacts);
  const std::string b = path("bodies.csv").string();
  const std::string c = path("contacts.csv").string();
  const std::string ob = path("ob.csv").string();
  const std::string oj = path("oj.csv").string();
  const std::vector<std::vector<std::string>> cases = {
      {},
      {"frobnicate"},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob},                                  // missing option
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses"},                // missing value
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj, "--fast"},  // unknown
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj, "--precision", "half"},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj, "--path", "gpu"},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj, "--model", "soft"},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj, "--threads", "-1"},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", ob},
      {"solve", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", (dir_ / "." / "ob.csv").string()},
      {"solve", "--bodies", b, "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj},
      {"solve", "stray", "--bodies", b, "--contacts", c, "--out-bodies", ob, "--out-impulses", oj},
      {"gen", "--out", path("g").string()},
      {"gen", "--pairs", "1", "--debris", "1", "--out", path("g").string()},
      {"gen", "--pairs", "1"},
      {"gen", "--pairs", "1", "--out", path("g").string(), "--seed", "x"},
  };
  for (const auto& args : cases) {
    const RunResult r = run(args);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_EQ(r.exit_code, 2) << joined << "\n" << r.err;
    if (args.empty()) {
      EXPECT_NE(r.err.find("usage: collide"), std::string::npos) << r.err;  // no command: the commands
    } else if (args[0] == "frobnicate") {
      EXPECT_EQ(r.err,
                "collide: unknown command 'frobnicate' (the commands: solve, gen, convert, report)\n"
                "see 'collide --help'\n");
    } else {
      expect_one_usage_line(r, args[0], joined);
    }
  }
  EXPECT_FALSE(fs::exists(ob));
  EXPECT_FALSE(fs::exists(oj));
  EXPECT_FALSE(fs::exists(path("g")));
}

// A count says its range, whichever way it is wrong: negative, zero, too
// large or not a number.
TEST_F(CliTest, CountsStateTheirRange) {
  spit(path("bodies.csv"), kBodies);
  spit(path("contacts.csv"), kContacts);
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {solve_args({"--passes", "-1"}), "collide solve: --passes must be an integer from 1 to 1000000, got '-1'\n"},
      {solve_args({"--passes", "0"}), "collide solve: --passes must be an integer from 1 to 1000000, got '0'\n"},
      {solve_args({"--passes", "1000001"}),
       "collide solve: --passes must be an integer from 1 to 1000000, got '1000001'\n"},
      {solve_args({"--passes", "2.5"}), "collide solve: --passes must be an integer from 1 to 1000000, got '2.5'\n"},
      {solve_args({"--threads", "-1"}), "collide solve: --threads must be an integer from 0 to 4096, got '-1'\n"},
      {solve_args({"--threads", "4097"}), "collide solve: --threads must be an integer from 0 to 4096, got '4097'\n"},
      {solve_args({"--order", "color"}),
       "collide solve: --order: unknown order 'color' (expected input or colour): did you mean 'colour'?\n"},
      {solve_args({"--iteration", "sum"}),
       "collide solve: --iteration: unknown iteration 'sum' (expected repeat or accumulate)\n"},
      {solve_args({"--iteration", "accumulate", "--accuracy", "accurate"}),
       "collide solve: --iteration accumulate runs in the fast mode: it takes --accuracy fast\n"},
      {{"gen", "--pairs", "0", "--out", path("g").string()},
       "collide gen: --pairs must be an integer from 1 to 2147483647, got '0'\n"},
      {{"gen", "--debris", "0", "--out", path("g").string()},
       "collide gen: --debris must be an integer from 1 to 4294967295, got '0'\n"},
      {{"gen", "--pile", "0", "--out", path("g").string()},
       "collide gen: --pile must be an integer from 1 to 1625, got '0'\n"},
      {{"gen", "--chain", "0", "--out", path("g").string()},
       "collide gen: --chain must be an integer from 1 to 4294967294, got '0'\n"},
      {{"gen", "--pairs", "2147483648", "--out", path("g").string()},
       "collide gen: --pairs must be an integer from 1 to 2147483647, got '2147483648'\n"},
      {{"report", "--runs", "0"}, "collide report: --runs must be an integer from 1 to 1000, got '0'\n"},
      {{"convert", "--in", path("bodies.csv").string(), "--out", path("b.npz").string(), "--threads", "x"},
       "collide convert: --threads must be an integer from 0 to 4096, got 'x'\n"},
  };
  for (const auto& [args, first_line] : cases) {
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    const RunResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << joined << "\n" << r.err;
    EXPECT_EQ(r.err, first_line + "see 'collide " + args[0] + " --help'\n") << joined;
  }
  EXPECT_FALSE(fs::exists(path("g")));
  EXPECT_FALSE(fs::exists(path("ob.csv")));
  EXPECT_FALSE(fs::exists(path("b.npz")));
  // The least of each is accepted.
  EXPECT_EQ(run(solve_args({"--passes", "1", "--threads", "0"})).exit_code, 0);
  for (const char* kind : {"--pairs", "--debris", "--pile", "--chain"}) {
    const RunResult r = run({"gen", kind, "1", "--out", path(std::string("one") + kind).string()});
    EXPECT_EQ(r.exit_code, 0) << kind << ": " << r.err;
  }
}

// Every writer creates its output's missing directory (and its parents), as
// gen creates its --out directory: solve's outputs, convert's, gen's.
TEST_F(CliTest, OutputsCreateMissingDirectories) {
  spit(path("bodies.csv"), kBodies);
  spit(path("contacts.csv"), kContacts);
  RunResult r =
      run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
           "--out-bodies", path("nodir/ob.csv").string(), "--out-impulses", path("deeper/still/oj.npz").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(path("nodir/ob.csv")));
  EXPECT_TRUE(fs::is_regular_file(path("deeper/still/oj.npz")));
  r = run({"convert", "--in", path("nodir/ob.csv").string(), "--out", path("converted/a/b.npz").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(path("converted/a/b.npz")));
  r = run({"gen", "--pairs", "3", "--out", path("gen/x/y").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(path("gen/x/y/bodies.csv")));
  // A directory that cannot be created (a file is in its way): exit 1, named.
  spit(path("file"), "x");
  r = run({"solve", "--bodies", path("bodies.csv").string(), "--contacts", path("contacts.csv").string(),
           "--out-bodies", path("file/sub/ob.csv").string(), "--out-impulses", path("oj2.csv").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot create directory '" + path("file/sub").string() + "'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("oj2.csv")));
}

TEST_F(CliTest, EqualsFormOfOptions) {
  spit(path("bodies.csv"), kBodies);
  spit(path("contacts.csv"), kContacts);
  const RunResult r = run({"solve", "--bodies=" + path("bodies.csv").string(),
                           "--contacts=" + path("contacts.csv").string(), "--out-bodies=" + path("ob.csv").string(),
                           "--out-impulses=" + path("oj.csv").string(), "--precision=float"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("oj.csv")));
}

}  // namespace
