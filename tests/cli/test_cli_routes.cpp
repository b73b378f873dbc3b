// test_cli_routes.cpp - one scene, one answer through the `collide`
// executable (docs/collision-law.md, "Scene values"): a scene's CSV files,
// the binary files `collide convert` makes of them in each precision and
// mixed pairs of both solve to the same output files in float and double,
// fast and accurate; `collide gen`'s CSV and binary scenes solve alike in
// float; a value beyond float is refused from CSV and from binary with one
// message, and nothing is written.
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::test::RunResult;
using collide::test::slurp;

class CliRoutes : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(COLLIDE_TEST_TMP) / (std::string("routes_") + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  RunResult run(const std::vector<std::string>& args) const {
    return collide::test::run_program(COLLIDE_CLI_PATH, dir_, args);
  }
  /// `collide convert` of dir/<table>.csv into dir/<tag>/<table>.npz.
  void convert(const std::string& tag, const std::string& precision) const {
    fs::create_directories(dir_ / tag);
    for (const char* table : {"bodies", "contacts"}) {
      const RunResult r = run({"convert", "--in", path(std::string(table) + ".csv"), "--out",
                               path(tag + "/" + table + ".npz"), "--precision", precision});
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }
  /// `collide solve` of the files into dir/out_<name>.csv and .../j_<name>.csv;
  /// the two outputs' text.
  std::string solve(const std::string& bodies, const std::string& contacts, const std::string& precision,
                    const std::string& accuracy) const {
    const std::string ob = path("out.csv"), oj = path("j.csv");
    const RunResult r = run({"solve", "--bodies", path(bodies), "--contacts", path(contacts), "--out-bodies", ob,
                             "--out-impulses", oj, "--precision", precision, "--accuracy", accuracy});
    EXPECT_EQ(r.exit_code, 0) << bodies << " " << contacts << ": " << r.err;
    return slurp(ob) + slurp(oj);
  }
  /// Every pair of the scene's files (CSV, `convert`'s '<f8' files, its
  /// '<f4' files in float, mixed) solves to the CSV files' outputs.
  void expect_every_route_agrees() const {
    convert("f8", "double");
    convert("f4", "float");
    for (const std::string precision : {"float", "double"}) {
      for (const std::string accuracy : {"fast", "accurate"}) {
        const std::string want = solve("bodies.csv", "contacts.csv", precision, accuracy);
        std::vector<std::pair<std::string, std::string>> pairs = {
            {"f8/bodies.npz", "f8/contacts.npz"}, {"bodies.csv", "f8/contacts.npz"}, {"f8/bodies.npz", "contacts.csv"}};
        if (precision == "float") {
          pairs.emplace_back("f4/bodies.npz", "f4/contacts.npz");
          pairs.emplace_back("f4/bodies.npz", "contacts.csv");
          pairs.emplace_back("bodies.csv", "f4/contacts.npz");
        }
        for (const auto& [b, c] : pairs) {
          EXPECT_EQ(solve(b, c, precision, accuracy), want) << b << " " << c << " " << precision << " " << accuracy;
        }
      }
    }
  }
  fs::path dir_;
};

TEST_F(CliRoutes, TheTwoBodiesGiveOneAnswer) {
  for (const char* table : {"bodies.csv", "contacts.csv"}) {
    fs::copy_file(fs::path(COLLIDE_DATA_DIR) / "scene-values" / "two-bodies" / table, dir_ / table);
  }
  expect_every_route_agrees();
  // Body 0's wz after the solve, in float, as every route writes it.
  for (const std::string accuracy : {"fast", "accurate"}) {
    const std::string out = solve("bodies.csv", "contacts.csv", "float", accuracy);
    const std::string body0 = out.substr(out.find('\n') + 1, out.find('\n', out.find('\n') + 1) - out.find('\n') - 1);
    EXPECT_EQ(body0.substr(body0.rfind(',') + 1), "6.996387") << accuracy;
  }
}

TEST_F(CliRoutes, GeneratedScenesGiveOneAnswer) {
  // `collide gen` writes the doubles it draws: as CSV text (read in float,
  // each double rounded once) and as '<f4' (each double rounded once).
  for (const char* kind : {"--pairs", "--debris", "--pile"}) {
    const std::string n = std::string(kind) == "--pile" ? "9" : "4000";
    ASSERT_EQ(run({"gen", kind, n, "--out", dir_.string(), "--seed", "2", "--friction"}).exit_code, 0);
    const RunResult g = run(
        {"gen", kind, n, "--out", path("gf4"), "--seed", "2", "--friction", "--format", "npz", "--precision", "float"});
    ASSERT_EQ(g.exit_code, 0) << g.err;
    expect_every_route_agrees();
    for (const std::string accuracy : {"fast", "accurate"}) {
      EXPECT_EQ(solve("gf4/bodies.npz", "gf4/contacts.npz", "float", accuracy),
                solve("bodies.csv", "contacts.csv", "float", accuracy))
          << kind << " " << accuracy;
    }
  }
}

TEST_F(CliRoutes, ADoubleBeyondFloatIsRefusedFromEveryFormatWithOneMessage) {
  const std::string header = "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n";
  const std::string good = "2,1,1,1,1,0,0,0,0,0,0,0.5,-3,0,0,0,1\n";
  std::ofstream(path("bodies.csv")) << header << good << "2,1,1,1,1,0,0,0,0,0,0,3.4028235677973365e38,-3,0,0,0,1\n";
  std::ofstream(path("contacts.csv")) << "a,b,cx,cy,cz,nx,ny,nz,e,mu\n0,1,0,0,0,0,0,1,0.5,0\n";
  convert("f8", "double");
  const std::string reason = "row 1, column 'vx': value 3.4028235677973366e+38 is out of the range of float";
  for (const auto& [b, c] :
       {std::pair<std::string, std::string>{"bodies.csv", "contacts.csv"}, {"f8/bodies.npz", "f8/contacts.npz"}}) {
    const RunResult r = run({"solve", "--bodies", path(b), "--contacts", path(c), "--out-bodies", path("o.csv"),
                             "--out-impulses", path("j.csv"), "--precision", "float"});
    EXPECT_EQ(r.exit_code, 1) << b;
    EXPECT_NE(r.err.find(path(b) + (b == "bodies.csv" ? ":3: " : ": ") + reason), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("o.csv")));
    // `collide convert` to float refuses it alike.
    const RunResult cv = run({"convert", "--in", path(b), "--out", path("o.npz"), "--precision", "float"});
    EXPECT_EQ(cv.exit_code, 1) << b;
    EXPECT_NE(cv.err.find(reason), std::string::npos) << cv.err;
    EXPECT_FALSE(fs::exists(path("o.npz")));
  }
}

}  // namespace
