// test_report_hard.cpp - `collide report --hard` as a user runs it.
//
// One small run (`--quick --n 2000 --threads 1 --hard --hard-n 200 --json
// --plot`) is shared by the tests of this file:
//   * the table has the hard section, one line per hard row;
//   * the JSON's "hard" array has exactly one row per scene of the library's
//     catalogue (hard::hard_scene_catalogue()), precision (float only where
//     the scene is meant for float) and mode (fast, accurate), with sane
//     speeds and sizes;
//   * every fast row is within the fast mode's target (kImpulseErrorTargetEps
//     eps-units), every accurate row within kAccurateErrorUlps ulps (and the
//     target in eps-units too);
//   * the section measures what it says: on grazing contacts the fast
//     sphere and rigid kernels' plain relative error is far above the
//     accurate mode's bound (the fast particle kernel, whose vn and jn are
//     compensated, is within it);
//   * the PNG has the third panel (the hard rows).
// Without --hard the report has no hard rows (test_report.cpp's run).
#include <cstddef>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/check.hpp"
#include "collide/eval/hard_scenes.hpp"
#include "collide/eval/reference.hpp"  // COLLIDE_HAS_FLOAT128
#include "collide/model.hpp"
#include "support/mini_json.hpp"
#include "support/report_run.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::test::Json;
using collide::test::RunResult;
using collide::test::slurp;

constexpr std::size_t kHardN = 200;

class HardReportRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    report_ = collide::test::run_report(
        COLLIDE_CLI_PATH, fs::path(COLLIDE_TEST_TMP) / "report-hard",
        {"--quick", "--n", "2000", "--threads", "1", "--hard", "--hard-n", std::to_string(kHardN)});
  }
  static void TearDownTestSuite() { report_.reset(); }
  static const std::vector<Json>& hard() { return report_->json.at("hard").items; }

  static std::unique_ptr<const collide::test::ReportOutput> report_;
};
std::unique_ptr<const collide::test::ReportOutput> HardReportRun::report_;

std::string trace(const Json& row) {
  return row.at("family").str + " " + row.at("model").str + " " + row.at("precision").str + " " + row.at("mode").str;
}

TEST_F(HardReportRun, ExitsZeroAndPrintsTheSection) {
  ASSERT_EQ(report_->result.exit_code, 0) << report_->result.err;
  const std::size_t start = report_->result.out.find("hard scenes (--hard");
  ASSERT_NE(start, std::string::npos) << report_->result.out;
  ASSERT_TRUE(report_->json.has("hard"));
  // One table line per hard row, in the JSON's order.
  std::istringstream table(report_->result.out.substr(start));
  std::string line;
  std::size_t next = 0;
  while (std::getline(table, line) && next < hard().size()) {
    const Json& row = hard()[next];
    if (line.rfind(row.at("family").str + " ", 0) == 0 &&
        line.find(" " + row.at("mode").str + " ") != std::string::npos) {
      ++next;
    }
  }
  EXPECT_EQ(next, hard().size()) << "table lines of the hard section do not match the JSON rows";
}

TEST_F(HardReportRun, OneRowPerCatalogueScenePrecisionAndMode) {
  ASSERT_TRUE(report_->json.has("hard"));
  EXPECT_EQ(report_->json.at("hard_n").num, static_cast<double>(kHardN));
  using Key = std::tuple<std::string, std::string, std::string, std::string>;
  std::map<Key, int> seen;
  for (const Json& row : hard()) {
    ++seen[{row.at("family").str, row.at("model").str, row.at("precision").str, row.at("mode").str}];
  }
  std::size_t expected = 0;
  for (const collide::hard::HardScene& s : collide::hard::hard_scene_catalogue()) {
    for (const char* precision : {"float", "double"}) {
      if (s.float_only && std::string(precision) == "double") continue;
      for (const char* mode : {"fast", "accurate"}) {
        EXPECT_EQ((seen[{s.family, collide::to_string(s.fit), precision, mode}]), 1)
            << s.family << " " << collide::to_string(s.fit) << " " << precision << " " << mode;
        ++expected;
      }
    }
  }
  EXPECT_EQ(hard().size(), expected);
}

TEST_F(HardReportRun, SpeedsAndSizesAreSane) {
  ASSERT_TRUE(report_->json.has("hard"));
  for (const Json& row : hard()) {
    SCOPED_TRACE(trace(row));
    EXPECT_GT(row.at("collisions_per_second").num, 0);
    EXPECT_GE(row.at("runs").num, 3);
    EXPECT_EQ(row.at("threads").num, 1);
    EXPECT_FALSE(row.at("isa").str.empty());
    if (!row.at("shared").b) {
      EXPECT_EQ(row.at("n").num, static_cast<double>(kHardN));
    }
    EXPECT_GT(row.at("n").num, 0);
    EXPECT_LE(row.at("acting").num, row.at("n").num);
    EXPECT_LE(row.at("p99_err_eps").num, row.at("max_err_eps").num);
  }
}

TEST_F(HardReportRun, FastRowsWithinTheTargetAccurateRowsWithinTheirUlps) {
  ASSERT_TRUE(report_->json.has("hard"));
  std::size_t fast = 0, accurate = 0;
  for (const Json& row : hard()) {
    SCOPED_TRACE(trace(row));
    // Missing (null) figures fail: a JSON null leaves the kind at null.
    ASSERT_EQ(row.at("max_err_eps").kind, Json::number);
    EXPECT_LE(row.at("max_err_eps").num, collide::kImpulseErrorTargetEps);
    // Double's ulps need the __float128 reference (GCC on x86-64); a build
    // without it says so and leaves the figure out.
    if (row.at("judge").str == "none") {
      EXPECT_EQ(row.at("precision").str, "double");
      EXPECT_EQ(row.at("max_err_ulps").kind, Json::null);
      continue;
    }
    ASSERT_EQ(row.at("max_err_ulps").kind, Json::number);
    if (row.at("mode").str == "accurate") {
      EXPECT_LE(row.at("max_err_ulps").num, collide::kAccurateErrorUlps);
      ++accurate;
    } else {
      ++fast;
    }
  }
  EXPECT_EQ(fast, accurate);
  EXPECT_GT(fast, 0U);
#if COLLIDE_HAS_FLOAT128
  for (const Json& row : hard()) EXPECT_NE(row.at("judge").str, "none") << trace(row);
#endif
}

TEST_F(HardReportRun, GrazingShowsWhyTheAccurateModeExists) {
  // Grazing contacts (vn / |u| down to 1e-7): the fast sphere and rigid
  // kernels form vn in the working precision, and their plain relative
  // error is orders of magnitude above the accurate mode's bound. The fast
  // particle kernel forms vn and jn in double lanes (float) or compensated
  // (double) and rounds jn once, so it is within the bound there too.
  ASSERT_TRUE(report_->json.has("hard"));
  std::size_t checked = 0;
  for (const Json& row : hard()) {
    if (row.at("family").str != "grazing" || row.at("mode").str != "fast") continue;
    SCOPED_TRACE(trace(row));
    ++checked;
    if (row.at("judge").str == "none") continue;  // no __float128 in this build
    if (row.at("model").str == "particle") {
      EXPECT_LE(row.at("max_err_ulps").num, collide::kAccurateErrorUlps);
    } else {
      EXPECT_GT(row.at("max_err_ulps").num, 1000 * collide::kAccurateErrorUlps);
    }
  }
  EXPECT_EQ(checked, 3U * 2U);  // models x precisions
}

TEST_F(HardReportRun, ThePngHasTheHardPanel) {
  // gnuplot is a declared dependency: no skip. Four panels (the
  // convergence section's among them): 3200 px wide, 800 a panel, read from
  // the PNG's IHDR chunk.
  ASSERT_TRUE(fs::exists(report_->dir / "report.png")) << report_->result.err;
  const std::string png = slurp(report_->dir / "report.png");
  ASSERT_GE(png.size(), 24U);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const auto byte = [&](std::size_t i) { return static_cast<unsigned>(static_cast<unsigned char>(png[i])); };
  const unsigned width = (byte(16) << 24) | (byte(17) << 16) | (byte(18) << 8) | byte(19);
  EXPECT_EQ(width, 3200U);
}

TEST(HardReportUsage, BadHardSizeExitsTwo) {
  const fs::path dir = fs::path(COLLIDE_TEST_TMP) / "report-hard-usage";
  fs::create_directories(dir);
  EXPECT_EQ(collide::test::run_program(COLLIDE_CLI_PATH, dir, {"report", "--hard-n", "0"}).exit_code, 2);
  EXPECT_EQ(collide::test::run_program(COLLIDE_CLI_PATH, dir, {"report", "--hard-n", "lots"}).exit_code, 2);
  const RunResult help = collide::test::run_program(COLLIDE_CLI_PATH, dir, {"report", "--help"});
  EXPECT_NE(help.out.find("--hard"), std::string::npos);
}

}  // namespace
