// test_cli_isa.cpp - `collide solve --isa` and COLLIDE_ISA through the real
// CLI: every ISA this CPU has writes the same bytes and says which
// ran in --stats, and how it was chosen; an unknown or unsupported ISA is a
// usage error that writes nothing. The same holds for --accuracy accurate
//, on every ISA.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "collide/isa.hpp"
#include "support/run_cli.hpp"

namespace {

namespace fs = std::filesystem;
using collide::Isa;
using collide::test::RunResult;
using collide::test::slurp;

class CliIsaTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(COLLIDE_TEST_TMP) /
           (std::string("isa.") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  RunResult run(const std::vector<std::string>& args) const {
    return collide::test::run_program(COLLIDE_CLI_PATH, dir_, args);
  }
  /// A debris scene with friction (shared bodies, a ground body, tails).
  void generate() const {
    const RunResult g = run({"gen", "--debris", "3001", "--friction", "--out", dir_.string()});
    ASSERT_EQ(g.exit_code, 0) << g.err;
  }
  RunResult solve(const std::string& tag, std::vector<std::string> extra) const {
    std::vector<std::string> args = {"solve",
                                     "--bodies",
                                     (dir_ / "bodies.csv").string(),
                                     "--contacts",
                                     (dir_ / "contacts.csv").string(),
                                     "--out-bodies",
                                     (dir_ / ("ob-" + tag + ".csv")).string(),
                                     "--out-impulses",
                                     (dir_ / ("oj-" + tag + ".csv")).string(),
                                     "--stats"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }
  fs::path dir_;
};

TEST_F(CliIsaTest, EveryIsaTheCpuHasWritesTheSameBytes) {
  generate();
  for (const char* precision : {"float", "double"}) {
    SCOPED_TRACE(precision);
    const RunResult base = solve("scalar", {"--path", "scalar", "--precision", precision});
    ASSERT_EQ(base.exit_code, 0) << base.err;
    int ran = 0;
    for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
      if (!collide::isa_supported(isa)) continue;
      const std::string name = collide::to_string(isa);
      const RunResult r = solve(name, {"--isa", name, "--precision", precision, "--threads", "2"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_NE(r.err.find("\"isa\": \"" + name + "\""), std::string::npos) << r.err;
      EXPECT_EQ(slurp(dir_ / ("ob-" + name + ".csv")), slurp(dir_ / "ob-scalar.csv")) << name;
      EXPECT_EQ(slurp(dir_ / ("oj-" + name + ".csv")), slurp(dir_ / "oj-scalar.csv")) << name;
      ++ran;
    }
    EXPECT_GE(ran, 1);
  }
}

// --stats names the ISA that ran and how it was chosen: measured by default
// (an ISA this CPU has, with the time the measurement took), environment
// under COLLIDE_ISA, forced by --isa; the bytes are the same every way.
TEST_F(CliIsaTest, StatsNameTheIsaAndHowItWasChosen) {
  generate();
  unsetenv("COLLIDE_ISA");
  const RunResult r = solve("auto", {});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("\"isa_choice\": \"measured\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\"isa_calibration_seconds\": "), std::string::npos) << r.err;
  int named = 0;
  for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
    if (r.err.find(std::string("\"isa\": \"") + collide::to_string(isa) + "\"") == std::string::npos) continue;
    EXPECT_TRUE(collide::isa_supported(isa)) << collide::to_string(isa);
    ++named;
  }
  EXPECT_EQ(named, 1) << r.err;

  setenv("COLLIDE_ISA", "sse2", 1);
  const RunResult e = solve("env", {});
  const RunResult a = solve("env-auto", {"--isa", "auto"});  // auto is the default: the environment decides
  unsetenv("COLLIDE_ISA");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_NE(e.err.find("\"isa\": \"sse2\", \"isa_choice\": \"environment\""), std::string::npos) << e.err;
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.err.find("\"isa\": \"sse2\", \"isa_choice\": \"environment\""), std::string::npos) << a.err;

  const RunResult f = solve("forced", {"--isa", "sse2"});
  ASSERT_EQ(f.exit_code, 0) << f.err;
  EXPECT_NE(f.err.find("\"isa\": \"sse2\", \"isa_choice\": \"forced\""), std::string::npos) << f.err;
  EXPECT_NE(f.err.find("\"isa_calibration_seconds\": 0,"), std::string::npos) << f.err;

  for (const char* tag : {"env", "env-auto", "forced"}) {
    EXPECT_EQ(slurp(dir_ / ("ob-" + std::string(tag) + ".csv")), slurp(dir_ / "ob-auto.csv")) << tag;
    EXPECT_EQ(slurp(dir_ / ("oj-" + std::string(tag) + ".csv")), slurp(dir_ / "oj-auto.csv")) << tag;
  }
}

TEST_F(CliIsaTest, UnknownOrUnsupportedIsaIsAUsageErrorAndWritesNothing) {
  generate();
  const RunResult r = solve("bad", {"--isa", "avx3"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("avx3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "ob-bad.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "oj-bad.csv"));

  setenv("COLLIDE_ISA", "mmx", 1);
  const RunResult e = solve("badenv", {});
  unsetenv("COLLIDE_ISA");
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_NE(e.err.find("COLLIDE_ISA"), std::string::npos) << e.err;
  EXPECT_FALSE(fs::exists(dir_ / "ob-badenv.csv"));

  for (const Isa isa : {Isa::avx2, Isa::avx512}) {
    if (collide::isa_supported(isa)) continue;  // only a CPU without it can refuse it
    const RunResult u = solve("unsupported", {"--isa", collide::to_string(isa)});
    EXPECT_EQ(u.exit_code, 2);
    EXPECT_NE(u.err.find("not supported"), std::string::npos) << u.err;
    EXPECT_FALSE(fs::exists(dir_ / "ob-unsupported.csv"));
  }
}

// The accurate mode runs on the same dispatch: the same bytes on
// every ISA, path and thread count, its name in --stats, and its bytes differ
// from the fast mode's somewhere (it is not silently the fast mode).
TEST_F(CliIsaTest, AccurateModeWritesTheSameBytesOnEveryIsaPathAndThreadCount) {
  generate();
  for (const char* precision : {"float", "double"}) {
    SCOPED_TRACE(precision);
    const RunResult fast = solve("fast", {"--precision", precision});
    ASSERT_EQ(fast.exit_code, 0) << fast.err;
    EXPECT_NE(fast.err.find("\"accuracy\": \"fast\""), std::string::npos) << fast.err;
    const RunResult base =
        solve("acc-scalar", {"--path", "scalar", "--precision", precision, "--accuracy", "accurate"});
    ASSERT_EQ(base.exit_code, 0) << base.err;
    EXPECT_NE(base.err.find("\"accuracy\": \"accurate\""), std::string::npos) << base.err;
    EXPECT_NE(slurp(dir_ / "oj-acc-scalar.csv"), slurp(dir_ / "oj-fast.csv"));
    for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
      if (!collide::isa_supported(isa)) continue;
      const std::string name = std::string("acc-") + collide::to_string(isa);
      const RunResult r = solve(name, {"--isa", collide::to_string(isa), "--precision", precision, "--threads", "2",
                                       "--accuracy", "accurate", "--check"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      EXPECT_EQ(slurp(dir_ / ("ob-" + name + ".csv")), slurp(dir_ / "ob-acc-scalar.csv")) << name;
      EXPECT_EQ(slurp(dir_ / ("oj-" + name + ".csv")), slurp(dir_ / "oj-acc-scalar.csv")) << name;
    }
  }
  const RunResult bad = solve("acc-bad", {"--accuracy", "exact"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--accuracy"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "ob-acc-bad.csv"));
}

}  // namespace
