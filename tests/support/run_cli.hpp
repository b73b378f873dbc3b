// run_cli.hpp - what the tests that run a built program share: its result,
// shell quoting for std::system, and reading a whole file back.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace collide::test {

/// Exit status and the captured output of one run.
struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// `s` as one single-quoted shell word.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

/// The whole file, bytes as they are ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace collide::test
