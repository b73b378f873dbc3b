// run_cli.hpp - what the tests that run a built program share: running it
// with its output captured, shell quoting for std::system, and reading a
// whole file back.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

/// Runs `program` with `args` through the shell, its stdout and stderr
/// captured in files under `dir` (removed afterwards).
inline RunResult run_program(const std::string& program, const std::filesystem::path& dir,
                             const std::vector<std::string>& args) {
  std::string cmd = shell_quote(program);
  for (const std::string& a : args) {
    cmd += ' ';
    cmd += shell_quote(a);
  }
  const std::filesystem::path out = dir / "_stdout.txt";
  const std::filesystem::path err = dir / "_stderr.txt";
  cmd += " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string());
  const int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

}  // namespace collide::test
