// cli/cmd_gen.cpp - `collide gen`: write a random scene as two CSV files.
//
// Design notes
// ------------
// * Streaming: items (pairs, or debris bodies then debris contacts) are
//   generated in blocks by a tbb pipeline: blocks are drawn and formatted in
//   parallel and written in order, with a few blocks in memory at a time, so
//   ten million pairs need tens of megabytes, not gigabytes. Every item is a
//   pure function of (seed, index) (generate.hpp), so the bytes do not depend
//   on the thread count or the block size.
// * Values are written as the shortest text that reads back to the same
//   double (std::to_chars), inf for the ground's mass and moments.
// * Both files go through OutputFile (temporary + rename), so an interrupted
//   or failed run leaves no half-written scene.
// * A progress line goes to stderr only when stderr is a terminal, so logs
//   and tests see no carriage-return noise.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_pipeline.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/generate.hpp"
#include "collide/scene_io.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kGenUsage =
    "usage: collide gen (--pairs N | --debris N) --out DIR [--seed S] [--friction]\n"
    "                   [--model rigid|sphere|particle] [--threads N]\n"
    "\n"
    "Writes a random scene as DIR/bodies.csv and DIR/contacts.csv (DIR is created\n"
    "if needed). The same seed gives the same bytes.\n"
    "\n"
    "  --pairs N      N independent approaching pairs: contact k joins bodies 2k, 2k+1\n"
    "  --debris N     N contacts over N/2 movable bodies that share contacts, plus an\n"
    "                 immovable ground body (the last) on side b of every 4th contact\n"
    "  --out DIR      output directory\n"
    "  --seed S       64-bit seed (default 1)\n"
    "  --friction     draw mu uniformly from [0, 1) (default: mu = 0)\n"
    "  --model M      bodies that fit model M: rigid (default) as drawn, sphere\n"
    "                 (Iy = Iz = Ix) or particle (infinite moments, w = 0);\n"
    "                 every other value is the same for all three\n"
    "  --threads N    worker threads, 0 = all (default 0); the bytes do not depend on it\n";

namespace {

/// Shows "collide gen: 42%" on a terminal, at most five times a second.
class Progress {
 public:
  Progress(std::string what, std::size_t total)
      : what_(std::move(what)), total_(total), enabled_(::isatty(STDERR_FILENO) != 0) {}
  ~Progress() {
    if (enabled_ && shown_) std::fputc('\n', stderr);
  }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(std::size_t done) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (shown_ && done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    shown_ = true;
    std::fprintf(stderr, "\rcollide gen: %s %3.0f%% (%zu / %zu)", what_.c_str(),
                 total_ ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0, done, total_);
    std::fflush(stderr);
  }

 private:
  std::string what_;
  std::size_t total_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_{};
};

/// The text of one block, for one or two files.
struct BlockText {
  std::string first, second;
};

/// Runs `items` items in blocks: format(begin, end, text) in parallel,
/// write(text, end) in block order.
void stream_blocks(std::size_t items, std::size_t block,
                   const std::function<void(std::size_t, std::size_t, BlockText&)>& format,
                   const std::function<void(const BlockText&, std::size_t)>& write) {
  const std::size_t blocks = (items + block - 1) / block;
  const std::size_t tokens = 2 * static_cast<std::size_t>(std::max(1, oneapi::tbb::this_task_arena::max_concurrency()));
  // One buffer per token: block b uses ring[b % tokens], free again because
  // the in-order writer has finished block b - tokens before b is admitted.
  std::vector<BlockText> ring(tokens);
  std::size_t next = 0;
  oneapi::tbb::parallel_pipeline(
      tokens,
      oneapi::tbb::make_filter<void, std::size_t>(oneapi::tbb::filter_mode::serial_in_order,
                                                  [&](oneapi::tbb::flow_control& fc) -> std::size_t {
                                                    if (next == blocks) {
                                                      fc.stop();
                                                      return 0;
                                                    }
                                                    return next++;
                                                  }) &
          oneapi::tbb::make_filter<std::size_t, std::size_t>(oneapi::tbb::filter_mode::parallel,
                                                             [&](std::size_t b) {
                                                               BlockText& text = ring[b % tokens];
                                                               text.first.clear();
                                                               text.second.clear();
                                                               format(b * block, std::min(items, (b + 1) * block),
                                                                      text);
                                                               return b;
                                                             }) &
          oneapi::tbb::make_filter<std::size_t, void>(oneapi::tbb::filter_mode::serial_in_order, [&](std::size_t b) {
            write(ring[b % tokens], std::min(items, (b + 1) * block));
          }));
}

void write_pairs(std::size_t pairs, const GenerateOptions& options, OutputFile& bodies, OutputFile& contacts) {
  bodies.write(bodies_header());
  contacts.write(contacts_header());
  Progress progress("pairs", pairs);
  stream_blocks(
      pairs, 8192,
      [&](std::size_t begin, std::size_t end, BlockText& text) {
        BodyRecord<double> a, b;
        ContactRecord<double> c;
        for (std::size_t k = begin; k < end; ++k) {
          draw_pair(options, k, a, b, c);
          append_body_row(text.first, a);
          append_body_row(text.first, b);
          append_contact_row(text.second, c);
        }
      },
      [&](const BlockText& text, std::size_t done) {
        bodies.write(text.first);
        contacts.write(text.second);
        progress.update(done);
      });
}

void write_debris(std::size_t count, const GenerateOptions& options, OutputFile& bodies, OutputFile& contacts) {
  const std::size_t body_count = debris_body_count(count);
  bodies.write(bodies_header());
  {
    Progress progress("debris bodies", body_count);
    stream_blocks(
        body_count, 8192,
        [&](std::size_t begin, std::size_t end, BlockText& text) {
          BodyRecord<double> body;
          for (std::size_t i = begin; i < end; ++i) {
            draw_debris_body(options, count, i, body);
            append_body_row(text.first, body);
          }
        },
        [&](const BlockText& text, std::size_t done) {
          bodies.write(text.first);
          progress.update(done);
        });
  }
  contacts.write(contacts_header());
  Progress progress("debris contacts", count);
  stream_blocks(
      count, 8192,
      [&](std::size_t begin, std::size_t end, BlockText& text) {
        ContactRecord<double> c;
        for (std::size_t k = begin; k < end; ++k) {
          draw_debris_contact(options, count, k, c);
          append_contact_row(text.first, c);
        }
      },
      [&](const BlockText& text, std::size_t done) {
        contacts.write(text.first);
        progress.update(done);
      });
}

}  // namespace

int run_gen(int argc, char** argv) {
  const Options opt = parse_options(argc, argv, 2,
                                    {{"pairs", true},
                                     {"debris", true},
                                     {"out", true},
                                     {"seed", true},
                                     {"threads", true},
                                     {"friction", false},
                                     {"model", true}});
  if (opt.count("help") != 0) {
    std::fputs(kGenUsage, stdout);
    return kExitOk;
  }
  const bool pairs = opt.count("pairs") != 0;
  const bool debris = opt.count("debris") != 0;
  if (pairs == debris) throw UsageError("give exactly one of --pairs N and --debris N");
  const unsigned long long n = pairs ? parse_count("pairs", opt.at("pairs")) : parse_count("debris", opt.at("debris"));
  // Body ids are 32-bit (contacts.hpp): 2N bodies for pairs, N/2 + 1 for debris.
  const unsigned long long max_n = pairs ? 0x7FFFFFFFULL : 0xFFFFFFFFULL;
  if (n > max_n) throw UsageError("scene too large: body ids are 32-bit");
  const std::string& dir = required(opt, "out");
  GenerateOptions options;
  if (const auto it = opt.find("seed"); it != opt.end()) options.seed = parse_count("seed", it->second);
  options.friction = opt.count("friction") != 0;
  if (const auto it = opt.find("model"); it != opt.end()) {
    const std::string& m = it->second;
    if (m != "rigid" && m != "sphere" && m != "particle") {
      throw UsageError("--model must be rigid, sphere or particle, got '" + m + "'");
    }
    options.model = m == "rigid" ? Model::rigid : m == "sphere" ? Model::sphere : Model::particle;
  }
  std::unique_ptr<oneapi::tbb::global_control> limit;
  if (const auto it = opt.find("threads"); it != opt.end()) {
    const unsigned long long threads = parse_count("threads", it->second);
    if (threads > 4096) throw UsageError("--threads " + it->second + " is too many");
    if (threads > 0) {
      limit = std::make_unique<oneapi::tbb::global_control>(oneapi::tbb::global_control::max_allowed_parallelism,
                                                            static_cast<std::size_t>(threads));
    }
  }

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "collide: cannot create directory '%s': %s\n", dir.c_str(),
                 ec ? ec.message().c_str() : "not a directory");
    return kExitBadInput;
  }
  OutputFile bodies(dir + "/bodies.csv");
  OutputFile contacts(dir + "/contacts.csv");
  if (pairs) {
    write_pairs(static_cast<std::size_t>(n), options, bodies, contacts);
  } else {
    write_debris(static_cast<std::size_t>(n), options, bodies, contacts);
  }
  bodies.commit();
  contacts.commit();
  return kExitOk;
}

}  // namespace collide::cli
