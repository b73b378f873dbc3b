// report_run.hpp - one `collide report` run shared by a test suite: the
// tests of tests/cli/test_report*.cpp read the same run's table, JSON and
// plot instead of each paying for a report of its own.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "support/mini_json.hpp"
#include "support/run_cli.hpp"

namespace collide::test {

/// What a report run left: its directory, its exit status and output, and
/// its JSON document (empty when it wrote none: the tests then fail on their
/// own assertions, not in the suite's set-up).
struct ReportOutput {
  std::filesystem::path dir;
  RunResult result;
  Json json;
};

/// Runs `cli report <args> --json <dir>/report.json --plot <dir>/report.png`
/// in a fresh `dir` and reads the JSON back.
inline std::unique_ptr<const ReportOutput> run_report(const std::string& cli, const std::filesystem::path& dir,
                                                      std::vector<std::string> args) {
  auto r = std::make_unique<ReportOutput>();
  r->dir = dir;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path json = dir / "report.json";
  args.insert(args.begin(), "report");
  for (const std::string& a :
       {std::string("--json"), json.string(), std::string("--plot"), (dir / "report.png").string()}) {
    args.push_back(a);
  }
  r->result = run_program(cli, dir, args);
  if (std::filesystem::exists(json)) r->json = JsonParser(slurp(json)).parse();
  return r;
}

}  // namespace collide::test
