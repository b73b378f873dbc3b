// cli/options.cpp - the shared options of options.hpp.
#include "options.hpp"

#include <charconv>
#include <cstring>
#include <limits>
#include <string_view>
#include <system_error>

#include <oneapi/tbb/global_control.h>

#include "collide/solve.hpp"

namespace collide::cli {

Options parse_options(int argc, char** argv, int first, const std::vector<OptionSpec>& specs) {
  Options options;
  for (int i = first; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      options["help"] = "";
      continue;
    }
    if (arg.substr(0, 2) != "--" || arg.size() == 2) {
      throw UsageError("unexpected argument '" + std::string(arg) + "'");
    }
    const std::size_t eq = arg.find('=');
    const std::string name(arg.substr(2, eq == std::string_view::npos ? std::string_view::npos : eq - 2));
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& s : specs) {
      if (name == s.name) spec = &s;
    }
    if (spec == nullptr) throw UsageError("unknown option '--" + name + "'");
    if (options.count(name) != 0) throw UsageError("option '--" + name + "' given twice");
    if (!spec->takes_value) {
      if (eq != std::string_view::npos) throw UsageError("option '--" + name + "' takes no value");
      options[name] = "";
    } else if (eq != std::string_view::npos) {
      options[name] = std::string(arg.substr(eq + 1));
    } else {
      // A following "--x" is another option, not this one's value.
      if (i + 1 >= argc || std::strncmp(argv[i + 1], "--", 2) == 0) {
        throw UsageError("option '--" + name + "' needs a value");
      }
      options[name] = argv[++i];
    }
    if (spec->takes_value && options[name].empty()) throw UsageError("option '--" + name + "' needs a value");
  }
  return options;
}

const std::string& required(const Options& options, const std::string& name) {
  const auto it = options.find(name);
  if (it == options.end()) throw UsageError("missing required option '--" + name + "'");
  return it->second;
}

unsigned long long parse_integer(const std::string& name, const std::string& value, unsigned long long least,
                                 unsigned long long most) {
  unsigned long long n = 0;
  const char* end = value.data() + value.size();
  const auto [ptr, ec] = std::from_chars(value.data(), end, n);
  if (value.empty() || ec != std::errc() || ptr != end || n < least || n > most) {
    throw UsageError("--" + name + " must be an integer from " + std::to_string(least) + " to " + std::to_string(most) +
                     ", got '" + value + "'");
  }
  return n;
}

unsigned long long parse_count(const std::string& name, const std::string& value) {
  return parse_integer(name, value, 0, std::numeric_limits<unsigned long long>::max());
}

std::optional<Precision> parse_precision(const Options& options) {
  const auto it = options.find("precision");
  if (it == options.end()) return std::nullopt;
  if (it->second == "float") return Precision::single;
  if (it->second == "double") return Precision::double_;
  throw UsageError("--precision must be float or double, got '" + it->second + "'");
}

int parse_threads(const Options& options) {
  const auto it = options.find("threads");
  if (it == options.end()) return 0;
  return static_cast<int>(parse_integer("threads", it->second, 0, kMaxThreads));
}

struct ThreadLimit::Control {
  oneapi::tbb::global_control control;
};

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0) {
    control_ = std::make_unique<Control>(Control{oneapi::tbb::global_control(
        oneapi::tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads))});
  }
}

ThreadLimit::~ThreadLimit() = default;

}  // namespace collide::cli
