// test_cli_npz.cpp - the binary scene files (.npz) through the `collide`
// executable: gen, solve and convert, exactness both ways, the same results
// as from CSV, and bad files refused with nothing written.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/error_bound.hpp"
#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "support/mini_json.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::NpyType;
using collide::NpzColumn;
using collide::test::RunResult;
using collide::test::slurp;

void spit(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

class CliNpzTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(COLLIDE_TEST_TMP) / (std::string("npz_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  [[nodiscard]] fs::path path(const std::string& name) const { return dir_ / name; }
  RunResult run(const std::vector<std::string>& args) const {
    return collide::test::run_program(COLLIDE_CLI_PATH, dir_, args);
  }
  RunResult solve(const std::string& bodies, const std::string& contacts, const std::string& out_bodies,
                  const std::string& out_impulses, std::vector<std::string> extra = {}) const {
    std::vector<std::string> args = {"solve",
                                     "--bodies",
                                     path(bodies).string(),
                                     "--contacts",
                                     path(contacts).string(),
                                     "--out-bodies",
                                     path(out_bodies).string(),
                                     "--out-impulses",
                                     path(out_impulses).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }
  fs::path dir_;
};

/// Two bodies and one contact as binary files, in double, with one value
/// replaced by the caller.
struct SmallScene {
  std::vector<double> body[17];
  std::vector<std::uint32_t> a{0}, b{1};
  std::vector<double> contact[8];  // cx cy cz nx ny nz e mu

  SmallScene() {
    const double rows[2][17] = {{2, 0.8, 0.8, 0.8, 1, 0, 0, 0, 0, 1, 0, 0.5, -3, 0, 0, 0, 1},
                                {1.5, 0.2, 0.6, 0.6, 1, 0, 0, 0, 0.8, 2.2, 0, -0.5, 4, 0, 0, 0, -2}};
    for (int k = 0; k < 17; ++k) body[k] = {rows[0][k], rows[1][k]};
    const double c[8] = {0.4, 1.6, 0, 0, 1, 0, 0.5, 0.3};
    for (int k = 0; k < 8; ++k) contact[k] = {c[k]};
  }
  [[nodiscard]] std::string bodies_bytes() const {
    std::vector<NpzColumn> cols;
    cols.reserve(17);
    for (int k = 0; k < 17; ++k) cols.push_back({collide::kBodyColumns[k], NpyType::f8, body[k].data(), 2});
    return collide::format_npz(cols);
  }
  [[nodiscard]] std::string contacts_bytes() const {
    std::vector<NpzColumn> cols = {{"a", NpyType::u4, a.data(), a.size()}, {"b", NpyType::u4, b.data(), b.size()}};
    for (int k = 0; k < 8; ++k) cols.push_back({collide::kContactColumns[k + 2], NpyType::f8, contact[k].data(), 1});
    return collide::format_npz(cols);
  }
};

TEST_F(CliNpzTest, GenNpzSolvesToTheCsvScenesResults) {
  // The same draws in both formats; double, so the binary values are the
  // CSV's exactly and both solves give the same bits.
  for (const char* kind : {"--pairs", "--debris"}) {
    ASSERT_EQ(run({"gen", kind, "3000", "--out", path("csv").string(), "--seed", "5", "--friction"}).exit_code, 0);
    const RunResult g =
        run({"gen", kind, "3000", "--out", path("bin").string(), "--seed", "5", "--friction", "--format", "npz"});
    ASSERT_EQ(g.exit_code, 0) << g.err;
    ASSERT_TRUE(fs::exists(path("bin/bodies.npz")));
    ASSERT_EQ(solve("csv/bodies.csv", "csv/contacts.csv", "ob.csv", "oj.csv").exit_code, 0);
    const RunResult r = solve("bin/bodies.npz", "bin/contacts.npz", "ob.npz", "oj.npz", {"--check", "--stats"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
    // The binary results as CSV are the CSV run's files, byte for byte.
    ASSERT_EQ(run({"convert", "--in", path("ob.npz").string(), "--out", path("ob2.csv").string()}).exit_code, 0);
    EXPECT_EQ(slurp(path("ob2.csv")), slurp(path("ob.csv"))) << kind;
    // Mixed: binary in, CSV out.
    ASSERT_EQ(solve("bin/bodies.npz", "bin/contacts.npz", "ob3.csv", "oj3.csv").exit_code, 0);
    EXPECT_EQ(slurp(path("ob3.csv")), slurp(path("ob.csv"))) << kind;
    EXPECT_EQ(slurp(path("oj3.csv")), slurp(path("oj.csv"))) << kind;
  }
}

TEST_F(CliNpzTest, GenPileNpzIsTheCsvPile) {
  // The pile in both formats, in cell order and shuffled: the binary files
  // in double convert to the CSV files byte for byte, and both solve to the
  // same bits.
  for (const bool shuffle : {false, true}) {
    std::vector<std::string> csv = {"gen", "--pile", "10", "--out", path("csv").string(), "--seed", "5", "--friction"};
    std::vector<std::string> bin = {"gen",    "--pile", "10",         "--out",    path("bin").string(),
                                    "--seed", "5",      "--friction", "--format", "npz"};
    if (shuffle) {
      csv.emplace_back("--shuffle");
      bin.emplace_back("--shuffle");
    }
    ASSERT_EQ(run(csv).exit_code, 0);
    const RunResult g = run(bin);
    ASSERT_EQ(g.exit_code, 0) << g.err;
    for (const char* table : {"bodies", "contacts"}) {
      const std::string back = path(std::string(table) + "_back.csv").string();
      ASSERT_EQ(run({"convert", "--in", path("bin/" + std::string(table) + ".npz").string(), "--out", back}).exit_code,
                0);
      EXPECT_EQ(slurp(back), slurp(path("csv/" + std::string(table) + ".csv"))) << table << " shuffle " << shuffle;
    }
    ASSERT_EQ(solve("csv/bodies.csv", "csv/contacts.csv", "ob.csv", "oj.csv").exit_code, 0);
    const RunResult r = solve("bin/bodies.npz", "bin/contacts.npz", "ob3.csv", "oj3.csv", {"--check", "--stats"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("\"check_passed\": true"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(path("ob3.csv")), slurp(path("ob.csv"))) << "shuffle " << shuffle;
    EXPECT_EQ(slurp(path("oj3.csv")), slurp(path("oj.csv"))) << "shuffle " << shuffle;
  }
  // In float: each value rounded once, solved in float.
  ASSERT_EQ(
      run({"gen", "--pile", "10", "--out", path("f").string(), "--format", "npz", "--precision", "float"}).exit_code,
      0);
  const RunResult f = solve("f/bodies.npz", "f/contacts.npz", "of.npz", "ojf.npz", {"--stats", "--check"});
  ASSERT_EQ(f.exit_code, 0) << f.err;
  EXPECT_NE(f.err.find("\"precision\": \"float\""), std::string::npos) << f.err;
}

TEST_F(CliNpzTest, FloatSceneSolvesInItsOwnPrecision) {
  ASSERT_EQ(
      run({"gen", "--pairs", "2000", "--out", dir_.string(), "--format", "npz", "--precision", "float"}).exit_code, 0);
  const RunResult r = solve("bodies.npz", "contacts.npz", "ob.npz", "oj.npz", {"--stats", "--check"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("\"precision\": \"float\""), std::string::npos) << r.err;
  const RunResult d = solve("bodies.npz", "contacts.npz", "ob.npz", "oj.npz", {"--stats", "--precision", "double"});
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_NE(d.err.find("\"precision\": \"double\""), std::string::npos) << d.err;
}

// Binary bodies and contacts files of different precisions: neither file's
// precision wins without a word; the run is refused (exit 2, nothing
// written) and asks for --precision, which then decides.
TEST_F(CliNpzTest, MixedPrecisionFilesNeedPrecision) {
  for (const char* precision : {"float", "double"}) {
    ASSERT_EQ(
        run({"gen", "--pairs", "200", "--out", path(precision).string(), "--format", "npz", "--precision", precision})
            .exit_code,
        0);
  }
  for (const auto& [bodies, contacts] : {std::pair<std::string, std::string>{"double", "float"}, {"float", "double"}}) {
    const std::string b = bodies + "/bodies.npz", c = contacts + "/contacts.npz";
    const RunResult r = solve(b, c, "ob.npz", "oj.npz");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(bodies == "double" ? "holds float64 (double) values but" : "holds float32 (float) values but"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("say which precision to solve the scene in with --precision float or --precision double"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(path(b).string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(path(c).string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("oj.npz")));
    for (const char* precision : {"float", "double"}) {
      const RunResult ok = solve(b, c, "ob.npz", "oj.npz", {"--precision", precision, "--stats"});
      ASSERT_EQ(ok.exit_code, 0) << ok.err;
      EXPECT_NE(ok.err.find(std::string("\"precision\": \"") + precision + "\""), std::string::npos) << ok.err;
    }
    fs::remove(path("oj.npz"));
  }
  // CSV bodies: double, whatever a binary contacts file holds (the rule of
  // --precision's default: the binary bodies file's own, else double).
  ASSERT_EQ(run({"convert", "--in", path("float/bodies.npz").string(), "--out", path("b.csv").string()}).exit_code, 0);
  const RunResult csv = solve("b.csv", "float/contacts.npz", "ob.csv", "oj.csv", {"--stats"});
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(csv.err.find("\"precision\": \"double\""), std::string::npos) << csv.err;
}

TEST_F(CliNpzTest, ConvertIsExactBothWays) {
  for (const char* precision : {"float", "double"}) {
    ASSERT_EQ(run({"gen", "--debris", "5000", "--out", dir_.string(), "--format", "npz", "--precision", precision,
                   "--friction"})
                  .exit_code,
              0);
    for (const char* table : {"bodies", "contacts"}) {
      const std::string npz = path(std::string(table) + ".npz").string();
      const std::string csv = path(std::string(table) + ".csv").string();
      const std::string back = path(std::string(table) + "_back.npz").string();
      const std::string csv2 = path(std::string(table) + "_2.csv").string();
      ASSERT_EQ(run({"convert", "--in", npz, "--out", csv}).exit_code, 0);
      // Binary -> CSV -> binary: the same bytes.
      const RunResult r = run({"convert", "--in", csv, "--out", back, "--precision", precision});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(slurp(back), slurp(npz)) << precision << " " << table;
      // CSV -> binary -> CSV: the same text.
      ASSERT_EQ(run({"convert", "--in", back, "--out", csv2}).exit_code, 0);
      EXPECT_EQ(slurp(csv2), slurp(csv)) << precision << " " << table;
    }
  }
}

// Without --precision: a binary file keeps its own precision, and its CSV
// (the shortest text of each stored value) comes back in it, the same bytes.
TEST_F(CliNpzTest, ConvertKeepsTheBinaryPrecisionThroughCsvByDefault) {
  for (const char* precision : {"float", "double"}) {
    ASSERT_EQ(run({"gen", "--debris", "5000", "--out", dir_.string(), "--format", "npz", "--precision", precision,
                   "--friction"})
                  .exit_code,
              0);
    for (const char* table : {"bodies", "contacts"}) {
      SCOPED_TRACE(std::string(precision) + " " + table);
      const std::string npz = path(std::string(table) + ".npz").string();
      const std::string csv = path(std::string(table) + ".csv").string();
      const std::string back = path(std::string(table) + "_back.npz").string();
      ASSERT_EQ(run({"convert", "--in", npz, "--out", csv}).exit_code, 0);
      const RunResult r = run({"convert", "--in", csv, "--out", back});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(slurp(back), slurp(npz));
    }
  }
}

// A CSV of short decimals, as written by hand (data/example): read exactly
// in either precision, converted in double, as a solve reads it.
TEST_F(CliNpzTest, ConvertKeepsAHandWrittenCsvInDouble) {
  spit(path("c.csv"), "a,b,cx,cy,cz,nx,ny,nz,e,mu\n0,1,0.4,1.6,0,0,1,0,0.5,0.3\n1,2,0.25,-1,0,1,0,0,0.8,0\n");
  ASSERT_EQ(run({"convert", "--in", path("c.csv").string(), "--out", path("c.npz").string()}).exit_code, 0);
  EXPECT_EQ(collide::npz_scene_precision(collide::NpzArchive::map(path("c.npz").string())), NpyType::f8);
  ASSERT_EQ(run({"convert", "--in", path("c.npz").string(), "--out", path("c2.csv").string()}).exit_code, 0);
  EXPECT_EQ(slurp(path("c2.csv")), slurp(path("c.csv")));
}

// The impulses a solve writes, either way, exactly: binary -> CSV is what the
// solve writes as CSV, and back the same bytes, in the file's own precision.
TEST_F(CliNpzTest, ConvertConvertsAnImpulsesFile) {
  for (const char* precision : {"float", "double"}) {
    SCOPED_TRACE(precision);
    ASSERT_EQ(run({"gen", "--pairs", "3000", "--out", dir_.string(), "--format", "npz", "--precision", precision,
                   "--friction"})
                  .exit_code,
              0);
    ASSERT_EQ(solve("bodies.npz", "contacts.npz", "ob.npz", "oj.npz").exit_code, 0);
    ASSERT_EQ(solve("bodies.npz", "contacts.npz", "ob.csv", "oj_solve.csv").exit_code, 0);
    const RunResult to_csv = run({"convert", "--in", path("oj.npz").string(), "--out", path("oj.csv").string()});
    ASSERT_EQ(to_csv.exit_code, 0) << to_csv.err;
    EXPECT_EQ(slurp(path("oj.csv")), slurp(path("oj_solve.csv")));
    const RunResult back = run({"convert", "--in", path("oj.csv").string(), "--out", path("oj2.npz").string()});
    ASSERT_EQ(back.exit_code, 0) << back.err;
    EXPECT_EQ(slurp(path("oj2.npz")), slurp(path("oj.npz")));
  }
  // A bad impulses file is named with its line, row and column.
  spit(path("bad.csv"), "jx,jy,jz\n1,2,3\n1,x,3\n");
  const RunResult bad = run({"convert", "--in", path("bad.csv").string(), "--out", path("bad.npz").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("bad.csv:3: row 1, column 'jy'"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(path("bad.npz")));
}

// As `collide gen` creates its output directory, convert creates its
// output's; bad input creates nothing.
TEST_F(CliNpzTest, ConvertCreatesTheOutputsDirectory) {
  spit(path("b.npz"), SmallScene().bodies_bytes());
  const fs::path out = path("new/deeper/b.csv");
  const RunResult r = run({"convert", "--in", path("b.npz").string(), "--out", out.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(out).substr(0, 2), "m,");
  SmallScene bad;
  bad.body[0][1] = -1;
  spit(path("bad.npz"), bad.bodies_bytes());
  EXPECT_EQ(run({"convert", "--in", path("bad.npz").string(), "--out", path("none/b.csv").string()}).exit_code, 1);
  EXPECT_FALSE(fs::exists(path("none")));
}

// --format names every file, the inputs too: CSV inputs with --format npz
// are refused with what to do instead, and the .npz names alone work.
TEST_F(CliNpzTest, FormatNpzWithCsvInputsSaysWhatToDo) {
  ASSERT_EQ(run({"gen", "--pairs", "100", "--out", dir_.string()}).exit_code, 0);
  const RunResult r = solve("bodies.csv", "contacts.csv", "ob", "oj", {"--format", "npz"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--format npz applies to the inputs too"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("name the outputs .npz"), std::string::npos) << r.err;
  const RunResult named = solve("bodies.csv", "contacts.csv", "ob.npz", "oj.npz");
  ASSERT_EQ(named.exit_code, 0) << named.err;
  EXPECT_EQ(slurp(path("oj.npz")).substr(0, 2), "PK");
}

TEST_F(CliNpzTest, BadValueNamesFileRowAndColumnAndWritesNothing) {
  SmallScene s;
  s.body[0][1] = -1;  // m of body 1
  spit(path("b.npz"), s.bodies_bytes());
  spit(path("c.npz"), SmallScene().contacts_bytes());
  const RunResult r = solve("b.npz", "c.npz", "ob.npz", "oj.npz");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("b.npz: row 1, column 'm': mass must be > 0, got -1"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("ob.npz")));
  EXPECT_FALSE(fs::exists(path("oj.npz")));
}

TEST_F(CliNpzTest, BadContactsNamed) {
  spit(path("b.npz"), SmallScene().bodies_bytes());
  {
    SmallScene s;
    s.b[0] = 7;
    spit(path("c.npz"), s.contacts_bytes());
    const RunResult r = solve("b.npz", "c.npz", "ob.npz", "oj.npz");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("c.npz: row 0, column 'b': body id 7 is out of range"), std::string::npos) << r.err;
  }
  {
    SmallScene s;
    s.contact[3] = {0.5};  // |n| = 0.5
    spit(path("c.npz"), s.contacts_bytes());
    const RunResult r = solve("b.npz", "c.npz", "ob.npz", "oj.npz");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("c.npz: row 0, column 'nx'"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(path("ob.npz")));
}

TEST_F(CliNpzTest, MalformedArchiveIsRefused) {
  spit(path("b.npz"), "PK\x03\x04 not really a zip archive");
  spit(path("c.npz"), SmallScene().contacts_bytes());
  const RunResult r = solve("b.npz", "c.npz", "ob.npz", "oj.npz");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("collide: "), std::string::npos);
  EXPECT_NE(r.err.find("b.npz"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("ob.npz")));
}

TEST_F(CliNpzTest, FormatOptionOverridesTheName) {
  spit(path("b.bin"), SmallScene().bodies_bytes());
  spit(path("c.bin"), SmallScene().contacts_bytes());
  const RunResult r = solve("b.bin", "c.bin", "ob.bin", "oj.bin", {"--format", "npz"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(path("oj.bin")).substr(0, 2), "PK");
  const RunResult bad = solve("b.bin", "c.bin", "ob.bin", "oj.bin", {"--format", "hdf5"});
  EXPECT_EQ(bad.exit_code, 2);
}

TEST_F(CliNpzTest, ConvertRefusesWhatIsNotATable) {
  spit(path("x.csv"), "p,q\n1,2\n");
  const RunResult r = run({"convert", "--in", path("x.csv").string(), "--out", path("x.npz").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("x.csv:1"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.npz")));
}

TEST_F(CliNpzTest, ReportMeasuresAScenesFiles) {
  // A sphere debris scene with friction: the report runs the models it fits
  // (rigid and sphere, not particle: its bodies spin and rub) in both
  // precisions, every variant within the bound, on the file's own friction.
  ASSERT_EQ(
      run({"gen", "--debris", "3000", "--out", dir_.string(), "--format", "npz", "--friction", "--model", "sphere"})
          .exit_code,
      0);
  const RunResult r = run({"report", "--quick", "--n", "1000", "--debris-n", "1000", "--threads", "1", "--bodies",
                           path("bodies.npz").string(), "--contacts", path("contacts.npz").string(), "--json",
                           path("r.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const collide::test::Json json = collide::test::JsonParser(slurp(path("r.json"))).parse();
  std::size_t file_rows = 0, kernel_rows = 0;
  bool models[2] = {false, false};  // rigid, sphere
  for (const collide::test::Json& row : json.at("rows").items) {
    if (row.at("scene").str != "file") continue;
    ++file_rows;
    EXPECT_TRUE(row.at("friction").b) << "the file's own friction";
    const std::string& variant = row.at("variant").str;
    if (variant == "simd" || variant == "scalar" || variant == "accurate") {
      ++kernel_rows;
      EXPECT_EQ(row.at("n").num, 3000);
      EXPECT_LE(row.at("max_err_eps").num, collide::kImpulseErrorBoundEps) << variant;
      models[0] |= row.at("model").str == "rigid";
      models[1] |= row.at("model").str == "sphere";
      EXPECT_NE(row.at("model").str, "particle") << "a rotating scene with friction does not fit particles";
    }
  }
  EXPECT_GT(file_rows, kernel_rows) << "the reference and textbook rows too";
  EXPECT_TRUE(models[0] && models[1]);
  // Only both files together, and a bad file stops the report with its message.
  EXPECT_EQ(run({"report", "--quick", "--bodies", path("bodies.npz").string()}).exit_code, 2);
  const RunResult bad = run({"report", "--quick", "--n", "1000", "--threads", "1", "--bodies",
                             path("missing.npz").string(), "--contacts", path("contacts.npz").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("missing.npz"), std::string::npos) << bad.err;
  // The files are read before anything is measured: the run's first phase
  // (phase_seconds lists the phases as they ran), so a bad one stops it at once.
  const std::string text = slurp(path("r.json"));
  const std::size_t phases = text.find("\"phase_seconds\": {");
  ASSERT_NE(phases, std::string::npos);
  EXPECT_EQ(text.compare(phases, 26, "\"phase_seconds\": {\"read\": "), 0) << text.substr(phases, 80);
}

}  // namespace
