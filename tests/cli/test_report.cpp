// test_report.cpp - `collide report` as a user runs it.
//
// One quick run (`--quick --n 20000 --json --plot`) is shared by the tests
// of this file (it takes seconds, and every test reads the same outputs):
//   * the JSON holds every variant: the pairs, debris and pile scenes,
//     friction off and on, the
//     reference in long double and double, the textbook loop in float and
//     double, and every kernel row (scalar, SIMD and accurate, float and
//     double, every model, every thread count), plus the Bullet row when the
//     report says it was built with Bullet;
//   * the accurate rows of the float pairs are within 8 ulps of the law;
//   * every row has the required fields with sane values: positive speed and
//     bandwidth fraction, kernel errors within the documented bound,
//     p99 <= max, the reference's own error 0, scalar and SIMD errors
//     identical (the paths agree bit for bit), small drifts;
//   * the PNG exists and starts with the PNG signature. gnuplot is a declared
//     dependency, so without it this test fails rather than skips;
//   * the convergence section: every scene, order, mode and pass count,
//     cold and warm, with residuals that must hold whatever the machine
//     (the solves give the same bits everywhere): 1 for one cold pass, the
//     same figures for one pass in both modes, fewer left after 32 passes
//     than after 1, a warm start below a cold one; --no-convergence leaves
//     it out;
//   * stdout is the summary: the speed-against-error frontier of each scene
//     (the rows no other row of the scene beats on both), computed here again
//     from the JSON, and where the JSON and the plot are; with --all (a
//     smaller run of its own) a line per row; usage errors exit 2.
//
// The JSON is read with tests/support/mini_json.hpp (no JSON library is a
// dependency of the project).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/bandwidth.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/io/generate.hpp"
#include "collide/isa.hpp"
#include "support/mini_json.hpp"
#include "support/report_run.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::test::Json;
using collide::test::RunResult;
using collide::test::slurp;

// ---------------------------------------------------------------------------
// Running the tool.
// ---------------------------------------------------------------------------

RunResult run(const fs::path& dir, const std::vector<std::string>& args) {
  return collide::test::run_program(COLLIDE_CLI_PATH, dir, args);
}

/// The one quick report every test reads.
class ReportRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    report_ =
        collide::test::run_report(COLLIDE_CLI_PATH, fs::path(COLLIDE_TEST_TMP) / "report", {"--quick", "--n", "20000"});
  }
  static void TearDownTestSuite() { report_.reset(); }
  static const std::vector<Json>& rows() { return report_->json.at("rows").items; }

  static std::unique_ptr<const collide::test::ReportOutput> report_;
};
std::unique_ptr<const collide::test::ReportOutput> ReportRun::report_;

const char* const kRequired[] = {"scene",
                                 "variant",
                                 "model",
                                 "precision",
                                 "simd",
                                 "threads",
                                 "n",
                                 "collisions_per_second",
                                 "bandwidth_fraction",
                                 "max_err_eps",
                                 "p99_err_eps",
                                 "max_rel_err",
                                 "friction",
                                 "momentum_drift",
                                 "angular_momentum_drift",
                                 "energy_drift",
                                 "isa",
                                 "layout",
                                 "order"};

// scene, friction, variant, precision, model, threads, isa, order
using Key = std::tuple<std::string, bool, std::string, std::string, std::string, int, std::string, std::string>;
Key key_of(const Json& row) {
  return {row.at("scene").str,     row.at("friction").b, row.at("variant").str,
          row.at("precision").str, row.at("model").str,  static_cast<int>(row.at("threads").num),
          row.at("isa").str,       row.at("order").str};
}

bool is_kernel(const Json& row) {
  const std::string& v = row.at("variant").str;
  return v == "scalar" || v == "simd" || v == "accurate";
}

/// The row lines of a printed table (they start with the scene's name), as
/// "scene fric variant precision model thr isa": the table's fixed columns.
std::vector<std::string> table_rows(const std::string& out) {
  const auto field = [](const std::string& line, std::size_t at, std::size_t width) {
    std::string f = line.substr(at, width);
    while (!f.empty() && f.back() == ' ') f.pop_back();
    return f;
  };
  std::vector<std::string> rows;
  std::istringstream table(out);
  for (std::string line; std::getline(table, line);) {
    if (line.rfind("pairs ", 0) != 0 && line.rfind("debris ", 0) != 0 && line.rfind("pile ", 0) != 0) continue;
    if (line.size() < 62) continue;
    // %-7s %-4s %-9s %-11s %-8s %-6s %-6s %3d (report_table.cpp)
    rows.push_back(field(line, 0, 7) + " " + field(line, 8, 4) + " " + field(line, 13, 9) + " " + field(line, 23, 11) +
                   " " + field(line, 35, 8) + " " + std::to_string(std::stoi(line.substr(58, 3))) + " " +
                   field(line, 44, 6));
  }
  return rows;
}

std::string row_key_text(const Json& row) {
  return row.at("scene").str + " " + (row.at("friction").b ? "mu" : "-") + " " + row.at("variant").str + " " +
         row.at("precision").str + " " + row.at("model").str + " " +
         std::to_string(static_cast<int>(row.at("threads").num)) + " " + row.at("isa").str;
}

TEST_F(ReportRun, ExitsZeroAndPrintsTheFrontier) {
  ASSERT_EQ(report_->result.exit_code, 0) << report_->result.err;
  const std::string& out = report_->result.out;
  EXPECT_NE(out.find("scene   fric variant"), std::string::npos) << out;
  EXPECT_NE(out.find("wall time"), std::string::npos);
  ASSERT_EQ(report_->json.kind, Json::object);
  // Where the rest is: --all, the JSON and the plot this run wrote.
  EXPECT_NE(out.find("every row: collide report --all; as JSON: " + (report_->dir / "report.json").string() +
                     "; the plot: " + (report_->dir / "report.png").string()),
            std::string::npos)
      << out;
  // The frontier, again from the JSON: of each scene and friction setting,
  // the rows (kernel rows at the largest thread count) that no other beats,
  // faster at no more error (max_err_eps x eps) or less error at no less
  // speed; fastest first.
  int most_threads = 1;
  for (const Json& r : rows()) most_threads = std::max(most_threads, static_cast<int>(r.at("threads").num));
  const auto candidate = [&](const Json& r) { return !is_kernel(r) || r.at("threads").num == most_threads; };
  const auto error = [](const Json& r) { return r.at("max_err_eps").num * r.at("eps").num; };
  const auto speed = [](const Json& r) { return r.at("collisions_per_second").num; };
  std::map<std::string, std::vector<const Json*>> groups;
  std::vector<std::string> group_order;
  for (const Json& r : rows()) {
    const std::string g = r.at("scene").str + (r.at("friction").b ? " mu" : " -");
    if (groups.count(g) == 0) group_order.push_back(g);
    groups[g].push_back(&r);
  }
  std::vector<std::string> expected;
  for (const std::string& g : group_order) {
    std::vector<const Json*> kept;
    for (const Json* r : groups[g]) {
      if (!candidate(*r)) continue;
      bool beaten = false;
      for (const Json* s : groups[g]) {
        if (s == r || !candidate(*s)) continue;
        beaten |=
            (speed(*s) > speed(*r) && error(*s) <= error(*r)) || (speed(*s) >= speed(*r) && error(*s) < error(*r));
      }
      if (!beaten) kept.push_back(r);
    }
    std::stable_sort(kept.begin(), kept.end(), [&](const Json* a, const Json* b) { return speed(*a) > speed(*b); });
    EXPECT_GE(kept.size(), 2U) << g << ": the fastest row and the most accurate one at least";
    for (const Json* r : kept) expected.push_back(row_key_text(*r));
  }
  EXPECT_EQ(group_order.size(), 6U) << "pairs, debris and pile, with and without friction";
  EXPECT_EQ(table_rows(out), expected) << out;
  EXPECT_LT(expected.size(), rows().size() / 4) << "a summary";
}

// --all prints every row, one line each, in the JSON's order.
TEST(ReportAll, PrintsEveryRow) {
  const fs::path dir = fs::path(COLLIDE_TEST_TMP) / "report-all";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const RunResult r = run(dir, {"report", "--quick", "--n", "2000", "--threads", "1", "--runs", "1", "--all",
                                "--no-convergence", "--json", (dir / "r.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Json json = collide::test::JsonParser(slurp(dir / "r.json")).parse();
  // --no-convergence: no section, in the JSON or the text.
  EXPECT_TRUE(json.at("convergence").items.empty());
  EXPECT_EQ(json.at("convergence_pile_side").num, 0);
  EXPECT_EQ(json.at("phase_seconds").fields.count("convergence"), 0U);
  EXPECT_EQ(r.out.find("convergence ("), std::string::npos) << r.out;
  std::vector<std::string> expected;
  for (const Json& row : json.at("rows").items) expected.push_back(row_key_text(row));
  EXPECT_EQ(table_rows(r.out), expected) << r.out;
  EXPECT_EQ(r.out.find("every row: collide report --all"), std::string::npos) << "the summary's pointer";
}

TEST_F(ReportRun, MachineFactsAreKnownOrUnknownNeverZero) {
  // Each cache size is the library's (/sys, else sysconf, else CPUID): a
  // positive number, or null in JSON and "unknown" in the text - never 0.
  ASSERT_TRUE(report_->json.has("machine")) << report_->result.err;
  const Json& m = report_->json.at("machine");
  const std::pair<const char*, int> caches[] = {{"l1d_bytes", 1}, {"l2_bytes", 2}, {"l3_bytes", 3}};
  for (const auto& [key, level] : caches) {
    ASSERT_TRUE(m.has(key)) << key;
    const std::optional<std::size_t> known = collide::cache_bytes(level);
    if (known) {
      ASSERT_EQ(m.at(key).kind, Json::number) << key;
      EXPECT_EQ(m.at(key).num, static_cast<double>(*known)) << key;
    } else {
      EXPECT_EQ(m.at(key).kind, Json::null) << key;
    }
  }
  const std::size_t at = report_->result.out.find("machine: ");
  ASSERT_NE(at, std::string::npos) << report_->result.out;
  const std::string line = report_->result.out.substr(at, report_->result.out.find('\n', at) - at);
  EXPECT_EQ(line.find(" 0 KiB"), std::string::npos) << line;
  if (!collide::cache_bytes(1)) {
    EXPECT_NE(line.find("L1d unknown"), std::string::npos) << line;
  }
  // The triad's arrays stay within memory whatever L3 the machine reports.
  EXPECT_EQ(m.at("triad_array_bytes").num, static_cast<double>(collide::default_triad_array_bytes()));
}

// The machine block shows what Isa::automatic picks: every precision,
// accuracy, model and scene kind, each an ISA this CPU has, in the JSON and
// in the table.
TEST_F(ReportRun, MachineShowsTheIsaAutoPicks) {
  ASSERT_TRUE(report_->json.has("machine")) << report_->result.err;
  const Json& m = report_->json.at("machine");
  ASSERT_TRUE(m.has("isa_auto"));
  const Json& picks = m.at("isa_auto");
  ASSERT_EQ(picks.kind, Json::array);
  std::set<std::string> keys;
  for (const Json& p : picks.items) {
    keys.insert(p.at("precision").str + " " + p.at("accuracy").str + " " + p.at("model").str + " " + p.at("scene").str);
    const std::string& isa = p.at("isa").str;
    EXPECT_TRUE(collide::isa_supported(collide::parse_isa(isa)) && isa != "auto") << isa;
    EXPECT_EQ(p.at("ns_per_contact").fields.count(isa), p.at("ns_per_contact").fields.empty() ? 0U : 1U) << isa;
    EXPECT_GE(p.at("calibration_seconds").num, 0.0);
  }
  EXPECT_EQ(keys.size(), 24U);
  EXPECT_EQ(picks.items.size(), 24U);
  EXPECT_NE(report_->result.out.find("isa auto ("), std::string::npos) << report_->result.out;
}

TEST_F(ReportRun, JsonHoldsEveryVariant) {
  ASSERT_TRUE(report_->json.has("rows")) << report_->result.err;
  std::set<Key> seen;
  for (const Json& row : rows()) {
    for (const char* field : kRequired) ASSERT_TRUE(row.has(field)) << "missing " << field;
    EXPECT_TRUE(seen.insert(key_of(row)).second)
        << "duplicate row " << row.at("scene").str << " " << row.at("variant").str;
  }
  std::set<Key> expected;
  for (const std::string scene : {"pairs", "debris", "pile"}) {
    for (const bool friction : {false, true}) {
      expected.insert({scene, friction, "reference", "long double", "rigid", 1, "sse2", "input"});
      expected.insert({scene, friction, "reference", "double", "rigid", 1, "sse2", "input"});
      expected.insert({scene, friction, "textbook", "float", "rigid", 1, "sse2", "input"});
      expected.insert({scene, friction, "textbook", "double", "rigid", 1, "sse2", "input"});
      for (const std::string precision : {"float", "double"}) {
        for (const std::string model : {"particle", "sphere", "rigid"}) {
          // The scalar path is the baseline object's, on the first thread count ...
          expected.insert({scene, friction, "scalar", precision, model, 1, "sse2", "input"});
          for (const int threads : {1, 2}) {
            // ... SIMD runs the default ISA ...
            expected.insert({scene, friction, "simd", precision, model, threads,
                             collide::to_string(collide::default_isa()), "input"});
            // ... in the fast and the accurate mode.
            expected.insert({scene, friction, "accurate", precision, model, threads,
                             collide::to_string(collide::default_isa()), "input"});
            // The pile also in the colour order, SIMD.
            if (scene == "pile") {
              expected.insert({scene, friction, "simd", precision, model, threads,
                               collide::to_string(collide::default_isa()), "colour"});
            }
          }
          // ... and every other ISA this CPU has, on the first thread count.
          for (const collide::Isa isa : {collide::Isa::sse2, collide::Isa::avx2, collide::Isa::avx512}) {
            if (collide::isa_supported(isa) && isa != collide::default_isa()) {
              expected.insert({scene, friction, "simd", precision, model, 1, collide::to_string(isa), "input"});
            }
          }
        }
      }
    }
  }
  // The peer row exists exactly when the report says Bullet was built in.
  const bool bullet = report_->json.at("peer").str.rfind("bullet", 0) == 0;
  if (bullet) expected.insert({"pairs", false, "bullet", "float", "rigid", 1, "sse2", "input"});
  for (const Key& k : expected) {
    EXPECT_EQ(seen.count(k), 1U) << "no row for " << std::get<0>(k) << (std::get<1>(k) ? " friction " : " ")
                                 << std::get<2>(k) << " " << std::get<3>(k) << " " << std::get<4>(k) << " "
                                 << std::get<5>(k) << " threads " << std::get<6>(k);
  }
  EXPECT_EQ(seen.size(), expected.size()) << "rows beyond the expected variants";
}

TEST_F(ReportRun, ValuesAreSane) {
  ASSERT_TRUE(report_->json.has("rows"));
  for (const Json& row : rows()) {
    SCOPED_TRACE(row.at("scene").str + " " + row.at("variant").str + " " + row.at("precision").str + " " +
                 row.at("model").str + " t" + std::to_string(static_cast<int>(row.at("threads").num)) +
                 (row.at("friction").b ? " friction" : ""));
    // --n 20000: the pairs and debris scenes have 20000 collisions, the pile
    // is the largest within 20000 (19^3 boxes, 19855 contacts).
    EXPECT_EQ(row.at("n").num, row.at("scene").str == "pile" ? 19855 : 20000);
    EXPECT_EQ(row.at("simd").b, row.at("variant").str == "simd" || row.at("variant").str == "accurate");
    ASSERT_EQ(row.at("collisions_per_second").kind, Json::number);
    EXPECT_GT(row.at("collisions_per_second").num, 0);
    ASSERT_EQ(row.at("bandwidth_fraction").kind, Json::number);
    EXPECT_GT(row.at("bandwidth_fraction").num, 0);
    for (const char* f :
         {"max_err_eps", "p99_err_eps", "max_rel_err", "momentum_drift", "angular_momentum_drift", "energy_drift"}) {
      ASSERT_EQ(row.at(f).kind, Json::number) << f << " is not a finite number";
      EXPECT_GE(row.at(f).num, 0) << f;
    }
    EXPECT_LE(row.at("p99_err_eps").num, row.at("max_err_eps").num);
    if (is_kernel(row)) {
      EXPECT_LE(row.at("max_err_eps").num, collide::kImpulseErrorBoundEps);
      EXPECT_GE(row.at("lanes").num, 1);
    }
    if (row.at("variant").str == "reference" && row.at("precision").str == "long double") {
      // The yardstick against itself.
      EXPECT_EQ(row.at("max_err_eps").num, 0);
      EXPECT_EQ(row.at("energy_drift").num, 0);
    }
    // Every variant solves the law: relative impulse errors stay far below 1
    // and momentum, angular momentum and energy agree with the reference to
    // rounding (float eps is 1.2e-7).
    EXPECT_LT(row.at("max_rel_err").num, 0.5);
    EXPECT_LT(row.at("momentum_drift").num, 1e-5);
    EXPECT_LT(row.at("angular_momentum_drift").num, 1e-5);
    EXPECT_LT(row.at("energy_drift").num, 1e-5);
  }
}

TEST_F(ReportRun, ThePileSceneIsReported) {
  // The pile of at most min(--n, 1e6) contacts, its size in the JSON and in
  // the table's first line, its own phase, and an error sample that is a
  // whole pile (the largest within the sample's 20000 contacts).
  ASSERT_TRUE(report_->json.has("pile_n")) << report_->result.err;
  EXPECT_EQ(report_->json.at("pile_side").num, 19);
  EXPECT_EQ(report_->json.at("pile_n").num, static_cast<double>(collide::pile_contact_count(19)));
  EXPECT_NE(report_->result.out.find("pile scene 19855 (19^3 boxes)"), std::string::npos) << report_->result.out;
  EXPECT_EQ(report_->json.at("phase_seconds").fields.count("pile"), 1U);
  std::size_t pile_rows = 0;
  for (const Json& row : rows()) {
    if (row.at("scene").str != "pile") continue;
    ++pile_rows;
    EXPECT_EQ(row.at("error_sample").num, 19855) << row.at("variant").str;
  }
  EXPECT_GT(pile_rows, 0U);
}

TEST_F(ReportRun, ScalarAndSimdErrorsAreIdentical) {
  ASSERT_TRUE(report_->json.has("rows"));
  // The paths and thread counts agree bit for bit, so their errors do too
  // (in each solve order: the pile's colour order has errors of its own,
  // against the reference replaying it).
  std::map<std::tuple<std::string, bool, std::string, std::string, std::string>, double> first;
  for (const Json& row : rows()) {
    if (!is_kernel(row) || row.at("variant").str == "accurate") continue;
    const auto k = std::make_tuple(row.at("scene").str, row.at("friction").b, row.at("precision").str,
                                   row.at("model").str, row.at("order").str);
    const auto [it, inserted] = first.emplace(k, row.at("max_err_eps").num);
    if (!inserted) {
      EXPECT_EQ(it->second, row.at("max_err_eps").num)
          << std::get<0>(k) << " " << std::get<2>(k) << " " << std::get<3>(k) << " " << row.at("variant").str;
    }
  }
}

TEST_F(ReportRun, AccurateRowsAreWithinAFewUlps) {
  ASSERT_TRUE(report_->json.has("rows"));
  // The accurate variant on independent pairs: J within 8 ulps
  // of the long double reference, which judges float exactly enough; and
  // never less accurate than the fast SIMD row of the same scene.
  std::size_t checked = 0;
  for (const Json& row : rows()) {
    if (row.at("variant").str != "accurate" || row.at("scene").str != "pairs" || row.at("precision").str != "float") {
      continue;
    }
    SCOPED_TRACE(row.at("model").str + (row.at("friction").b ? " friction" : ""));
    EXPECT_LE(row.at("max_rel_err").num, 8 * 1.1920929e-7);
    ++checked;
  }
  EXPECT_EQ(checked, 2U * 3U * 2U);  // friction x models x threads
}

/// The words joined by spaces: a key of the convergence rows.
std::string words(std::initializer_list<std::string> parts) {
  std::string out;
  for (const std::string& p : parts) {
    if (!out.empty()) out += ' ';
    out += p;
  }
  return out;
}

/// The key of a convergence row without its passes.
std::string convergence_line(const Json& c) {
  return c.at("scene").str + " " + c.at("order").str + " " + c.at("iteration").str + (c.at("warm").b ? " warm" : "");
}

TEST_F(ReportRun, TheConvergenceSectionHasEveryRow) {
  ASSERT_TRUE(report_->json.has("convergence")) << report_->result.err;
  // --quick: a pile of 8^3 boxes, its contact count for each scene.
  EXPECT_EQ(report_->json.at("convergence_pile_side").num, 8);
  EXPECT_EQ(report_->json.at("phase_seconds").fields.count("convergence"), 1U);
  std::set<std::string> seen;
  for (const Json& c : report_->json.at("convergence").items) {
    for (const char* key : {"scene", "order", "iteration", "passes", "warm", "n", "threads", "isa", "runs", "seconds",
                            "collisions_per_second", "residual", "start_residual", "next_pass"}) {
      ASSERT_TRUE(c.has(key)) << key;
    }
    SCOPED_TRACE(convergence_line(c) + " " + std::to_string(static_cast<int>(c.at("passes").num)));
    EXPECT_EQ(c.at("n").num, static_cast<double>(collide::pile_contact_count(8)));
    EXPECT_EQ(c.at("threads").num, 2);  // the largest of the default 1,2
    EXPECT_EQ(c.at("runs").num, 3);
    EXPECT_GT(c.at("seconds").num, 0);
    EXPECT_NEAR(c.at("collisions_per_second").num, c.at("n").num * c.at("passes").num / c.at("seconds").num,
                1e-5 * c.at("collisions_per_second").num);
    ASSERT_EQ(c.at("next_pass").kind, Json::number);
    EXPECT_GE(c.at("next_pass").num, 0);
    EXPECT_TRUE(!c.at("warm").b || c.at("iteration").str == "accumulate") << "a warm start is accumulate only";
    seen.insert(convergence_line(c) + " " + std::to_string(static_cast<int>(c.at("passes").num)));
  }
  for (const std::string scene : {"pile", "stack", "debris"}) {
    for (const std::string order : {"input", "colour"}) {
      for (const std::string mode : {"repeat", "accumulate"}) {
        for (const int passes : {1, 2, 4, 8, 16, 32}) {
          EXPECT_EQ(seen.count(words({scene, order, mode, std::to_string(passes)})), 1U)
              << scene << " " << order << " " << mode << " " << passes;
        }
      }
      for (const int passes : {1, 2}) {
        EXPECT_EQ(seen.count(words({scene, order, "accumulate warm", std::to_string(passes)})), 1U)
            << scene << " " << order << " warm " << passes;
      }
    }
  }
  EXPECT_EQ(seen.size(), 3U * 2U * (2U * 6U + 2U));
}

TEST_F(ReportRun, ConvergenceResidualsAreWhatTheIterationPromises) {
  ASSERT_TRUE(report_->json.has("convergence")) << report_->result.err;
  // Residual by line (scene, order, mode, warm) and passes.
  std::map<std::string, std::map<int, const Json*>> lines;
  for (const Json& c : report_->json.at("convergence").items) {
    lines[convergence_line(c)][static_cast<int>(c.at("passes").num)] = &c;
  }
  for (const auto& [key, by_passes] : lines) {
    SCOPED_TRACE(key);
    const bool warm = key.find(" warm") != std::string::npos;
    for (const auto& [passes, c] : by_passes) {
      // Frictionless: every pass's impulse lies along the contact's normal
      // total, so no change exceeds the largest J.
      ASSERT_EQ(c->at("residual").kind, Json::number);
      EXPECT_GT(c->at("residual").num, 0) << passes;
      EXPECT_LE(c->at("residual").num, 1) << passes;
    }
    if (warm) {
      // The warm start is the converged J: its own residual is small, and
      // a warm pass's change is below a cold one's (1).
      EXPECT_LT(by_passes.at(1)->at("start_residual").num, 0.01);
      EXPECT_LT(by_passes.at(1)->at("residual").num, 1);
      continue;
    }
    EXPECT_EQ(by_passes.at(1)->at("start_residual").num, 1);
    // One cold pass: all of J is its change.
    EXPECT_EQ(by_passes.at(1)->at("residual").num, 1);
    // Passes converge: 32 leave less than 1.
    EXPECT_LT(by_passes.at(32)->at("residual").num, by_passes.at(1)->at("residual").num);
  }
  for (const std::string scene : {"pile", "stack", "debris"}) {
    for (const std::string order : {"input", "colour"}) {
      SCOPED_TRACE(words({scene, order}));
      // One pass from zero is the same solve in both modes, bit for bit.
      const Json& repeat = *lines.at(words({scene, order, "repeat"})).at(1);
      const Json& accumulate = *lines.at(words({scene, order, "accumulate"})).at(1);
      EXPECT_EQ(repeat.at("next_pass").num, accumulate.at("next_pass").num);
      // The support of a resting stack is what a warm start has and a cold
      // pass lacks.
      if (scene == "stack") {
        EXPECT_LT(lines.at(words({scene, order, "accumulate warm"})).at(1)->at("residual").num,
                  accumulate.at("residual").num);
      }
    }
  }
  // The summary's line.
  EXPECT_NE(report_->result.out.find(" passes (accumulate, colour) reach residual <= 0.01; warm-started: "),
            std::string::npos)
      << report_->result.out;
}

TEST_F(ReportRun, NoHardRowsWithoutTheFlag) {
  // The hard section is `--hard` only (test_report_hard.cpp runs it).
  ASSERT_TRUE(report_->json.has("hard"));
  EXPECT_TRUE(report_->json.at("hard").items.empty());
  EXPECT_EQ(report_->json.at("hard_n").num, 0);
  EXPECT_EQ(report_->result.out.find("hard scenes"), std::string::npos);
}

TEST_F(ReportRun, WritesThePng) {
  // gnuplot is a declared dependency (scripts/install-deps.sh): no skip.
  ASSERT_TRUE(fs::exists(report_->dir / "report.png")) << "no PNG written; stderr: " << report_->result.err;
  const std::string png = slurp(report_->dir / "report.png");
  ASSERT_GE(png.size(), 8U);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_GT(png.size(), 10000U) << "suspiciously small plot";
  // Three panels, the convergence section's the third: 800 px each, read
  // from the PNG's IHDR chunk.
  ASSERT_GE(png.size(), 24U);
  const auto byte = [&](std::size_t i) { return static_cast<unsigned>(static_cast<unsigned char>(png[i])); };
  EXPECT_EQ((byte(16) << 24) | (byte(17) << 16) | (byte(18) << 8) | byte(19), 2400U);
}

TEST_F(ReportRun, SweepCoversTheRequestedSizes) {
  ASSERT_TRUE(report_->json.has("sweep"));
  std::set<std::pair<std::string, double>> points;
  for (const Json& p : report_->json.at("sweep").items) {
    EXPECT_GT(p.at("collisions_per_second").num, 0);
    EXPECT_GT(p.at("bandwidth_fraction").num, 0);
    points.insert({p.at("model").str, p.at("n").num});
  }
  for (const std::string model : {"rigid", "particle"}) {
    for (const double n : {1e4, 1e5, 1e6}) EXPECT_EQ(points.count({model, n}), 1U) << model << " " << n;
  }
}

TEST(ReportUsage, BadOptionsExitTwo) {
  const fs::path dir = fs::path(COLLIDE_TEST_TMP) / "report-usage";
  fs::create_directories(dir);
  EXPECT_EQ(run(dir, {"report", "--threads", "0"}).exit_code, 2);
  EXPECT_EQ(run(dir, {"report", "--n", "many"}).exit_code, 2);
  EXPECT_EQ(run(dir, {"report", "--bogus"}).exit_code, 2);
  const RunResult pile = run(dir, {"report", "--pile-n", "0"});
  EXPECT_EQ(pile.exit_code, 2);
  EXPECT_EQ(pile.err,
            "collide report: --pile-n must be an integer from 1 to 4294967295, got '0'\n"
            "see 'collide report --help'\n");
  EXPECT_EQ(run(dir, {"report", "--pile-n", "lots"}).exit_code, 2);
  const RunResult help = run(dir, {"report", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("usage: collide report"), std::string::npos);
}

}  // namespace
