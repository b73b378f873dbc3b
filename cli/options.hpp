// cli/options.hpp - what the subcommands of the `collide` tool share: the
// exit codes, the usage error, the option parser and the values it reads
// for every command (counts, precision, threads and their cap).
//
// Design notes
// ------------
// * Exit codes are part of the interface (scripts and tests rely on them):
//   0 success, 1 bad input or an I/O failure (nothing written), 2 usage
//   error, 3 `solve --check` found an error above the documented bound.
// * A usage error prints one line that says what is wrong and "see
//   'collide <command> --help'", not the whole help: the line is what a
//   reader must find in a script's log.
// * Options are GNU-style long options, "--name value" or "--name=value";
//   an option given twice is a usage error rather than "last one wins", so
//   a typo in a script cannot silently override an earlier value.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace collide::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitCheckFailed = 3;

/// A command line that does not follow the usage; the message says why.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One option a command accepts.
struct OptionSpec {
  const char* name;  ///< without the leading "--"
  bool takes_value;
};

/// Parsed options: name -> value ("" for flags). "help" is set for --help/-h.
using Options = std::map<std::string, std::string>;

/// Parses argv[first..argc) against `specs`. Throws UsageError.
Options parse_options(int argc, char** argv, int first, const std::vector<OptionSpec>& specs);
/// The value of a required option. Throws UsageError when it is missing.
const std::string& required(const Options& options, const std::string& name);
/// Parses a decimal integer option value from `least` to `most`; otherwise
/// UsageError("--passes must be an integer from 1 to 1000000, got '-1'").
unsigned long long parse_integer(const std::string& name, const std::string& value, unsigned long long least,
                                 unsigned long long most);
/// parse_integer from 0 to the largest 64-bit value (a seed).
unsigned long long parse_count(const std::string& name, const std::string& value);

/// The precision a scene is read, solved or written in.
enum class Precision { single, double_ };
/// --precision float|double, or nothing when it is not given.
std::optional<Precision> parse_precision(const Options& options);
/// --threads N: worker threads, 0 (the default) for all; at most 4096.
int parse_threads(const Options& options);

/// Caps TBB's threads for the rest of a command while it lives (also the
/// threads of parsing and writing); no cap for 0.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Control;
  std::unique_ptr<Control> control_;
};

}  // namespace collide::cli
