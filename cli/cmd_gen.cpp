// cli/cmd_gen.cpp - `collide gen`: write a random scene as two scene files.
//
// Design notes
// ------------
// * A thin shell: the options become generate.hpp's draw functions, and
//   collide/io/drawn_scene.hpp writes the scene from them, streamed in
//   blocks for CSV (tens of megabytes for ten million pairs), drawn into
//   columns for npz. Every item is a pure function of (seed, index), so the
//   bytes do not depend on the thread count.
// * Both files go through OutputFile (temporary + rename) and are committed
//   once both are written, so an interrupted or failed run leaves no
//   half-written scene.
// * A progress line goes to stderr only when stderr is a terminal, so logs
//   and tests see no carriage-return noise.
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "collide/io/drawn_scene.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene_npz.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kGenUsage =
    "usage: collide gen (--pairs N | --debris N | --pile S [--shuffle] | --chain N)\n"
    "                   --out DIR\n"
    "                   [--seed S] [--friction] [--model rigid|sphere|particle]\n"
    "                   [--format csv|npz] [--precision float|double] [--threads N]\n"
    "\n"
    "Writes a random scene as DIR/bodies.csv and DIR/contacts.csv, or with\n"
    "--format npz as the binary DIR/bodies.npz and DIR/contacts.npz (DIR is created\n"
    "if needed). The same seed gives the same bytes. Every count starts at 1 and\n"
    "ends where 32-bit body ids do: N up to 2147483647 pairs, 4294967295 debris\n"
    "contacts or 4294967294 chain contacts, S up to 1625.\n"
    "\n"
    "  --pairs N      N independent approaching pairs: contact k joins bodies 2k, 2k+1\n"
    "  --debris N     N contacts over N/2 movable bodies that share contacts, plus an\n"
    "                 immovable ground body (the last) on side b of every 4th contact\n"
    "  --pile S       a pile of S x S x S boxes, S boxes per side (S = 100: 1000000\n"
    "                 boxes and 2980000 contacts; at most 1625), each touching its\n"
    "                 +x, +y and +z neighbours, the bottom layer on an immovable\n"
    "                 ground body (the last): 3 S^2 (S - 1) + S^2 contacts, listed\n"
    "                 cell by cell as a grid broadphase emits them\n"
    "  --shuffle      the pile's contacts in a random order drawn from the seed\n"
    "  --chain N      a chain of N + 1 boxes, each touching the next (a staircase:\n"
    "                 +x, then +y), N contacts in chain order: every contact\n"
    "                 shares a body with the one before, so they run one by one\n"
    "  --out DIR      output directory\n"
    "  --seed S       64-bit seed (default 1)\n"
    "  --friction     draw mu uniformly from [0, 1) (default: mu = 0)\n"
    "  --model M      bodies that fit model M: rigid (default) as drawn, sphere\n"
    "                 (Iy = Iz = Ix) or particle (infinite moments, w = 0);\n"
    "                 every other value is the same for all three\n"
    "  --format F     csv (default: shortest round-trip text of the double values)\n"
    "                 or npz (binary, NumPy's uncompressed .npz, one array per column)\n"
    "  --precision P  float or double (default double): the dtype of an npz scene,\n"
    "                 each value rounded from the double drawn\n"
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

/// The progress line of each part of the scene as it is written: "pairs", or
/// "debris bodies" then "debris contacts" (and the same for a pile).
class PartProgress {
 public:
  explicit PartProgress(std::string prefix) : prefix_(std::move(prefix)) {}
  void operator()(std::string_view part, std::size_t done, std::size_t total) {
    if (!line_ || part != part_) {
      line_.reset();  // ends the previous part's line
      part_ = part;
      line_.emplace(prefix_ + part_, total);
    }
    line_->update(done);
  }

 private:
  std::string prefix_;
  std::string part_;
  std::optional<Progress> line_;
};

DrawnPairs pairs_scene(std::size_t pairs, const GenerateOptions& options) {
  return {pairs, [options](std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b, ContactRecord<double>& c) {
            draw_pair(options, k, a, b, c);
          }};
}

DrawnScene debris_scene(std::size_t count, const GenerateOptions& options) {
  return {debris_body_count(count), count,
          [count, options](std::uint64_t i, BodyRecord<double>& body) { draw_debris_body(options, count, i, body); },
          [count, options](std::uint64_t k, ContactRecord<double>& c) { draw_debris_contact(options, count, k, c); }};
}

DrawnScene chain_scene(std::size_t count, const GenerateOptions& options) {
  return {chain_body_count(count), count,
          [count, options](std::uint64_t i, BodyRecord<double>& body) { draw_chain_body(options, count, i, body); },
          [count, options](std::uint64_t k, ContactRecord<double>& c) { draw_chain_contact(options, count, k, c); }};
}

DrawnScene pile_scene(std::size_t side, const GenerateOptions& options) {
  return {pile_body_count(side), pile_contact_count(side),
          [side, options](std::uint64_t i, BodyRecord<double>& body) { draw_pile_body(options, side, i, body); },
          [side, options](std::uint64_t k, ContactRecord<double>& c) { draw_pile_contact(options, side, k, c); }};
}

}  // namespace

int run_gen(int argc, char** argv) {
  const Options opt = parse_options(argc, argv, 2,
                                    {{"pairs", true},
                                     {"debris", true},
                                     {"pile", true},
                                     {"chain", true},
                                     {"shuffle", false},
                                     {"out", true},
                                     {"seed", true},
                                     {"threads", true},
                                     {"friction", false},
                                     {"model", true},
                                     {"format", true},
                                     {"precision", true}});
  if (opt.count("help") != 0) {
    std::fputs(kGenUsage, stdout);
    return kExitOk;
  }
  const bool pairs = opt.count("pairs") != 0;
  const bool debris = opt.count("debris") != 0;
  const bool pile = opt.count("pile") != 0;
  const bool chain = opt.count("chain") != 0;
  if (static_cast<int>(pairs) + static_cast<int>(debris) + static_cast<int>(pile) + static_cast<int>(chain) != 1) {
    throw UsageError("give exactly one of --pairs N, --debris N, --pile S and --chain N");
  }
  const char* const kind = pairs ? "pairs" : debris ? "debris" : pile ? "pile" : "chain";
  // From 1 (no scene is empty) to what 32-bit body ids allow: the range
  // collide.generate takes too (max_scene_count).
  const unsigned long long n = parse_integer(kind, opt.at(kind), 1, max_scene_count(kind));
  if (opt.count("shuffle") != 0 && !pile) {
    throw UsageError("--shuffle is for --pile (the pairs, debris and chain contacts have no cell order to shuffle)");
  }
  const std::string& dir = required(opt, "out");
  GenerateOptions options;
  if (const auto it = opt.find("seed"); it != opt.end()) options.seed = parse_count("seed", it->second);
  options.friction = opt.count("friction") != 0;
  options.shuffle = opt.count("shuffle") != 0;
  if (const auto it = opt.find("model"); it != opt.end()) {
    const std::string& m = it->second;
    if (m != "rigid" && m != "sphere" && m != "particle") {
      throw UsageError("--model must be rigid, sphere or particle, got '" + m + "'");
    }
    options.model = m == "rigid" ? Model::rigid : m == "sphere" ? Model::sphere : Model::particle;
  }
  SceneFormat format = SceneFormat::csv;
  if (const auto it = opt.find("format"); it != opt.end()) {
    try {
      format = parse_scene_format(it->second);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--format: ") + e.what());
    }
  }
  const std::optional<Precision> precision = parse_precision(opt);
  if (precision && format != SceneFormat::npz) {
    throw UsageError("--precision is for --format npz (CSV text is the double's)");
  }
  const bool want_float = precision == Precision::single;
  const ThreadLimit limit(parse_threads(opt));

  // OutputFile creates DIR (and its parents) when missing.
  const std::string suffix = format == SceneFormat::npz ? ".npz" : ".csv";
  OutputFile bodies(dir + "/bodies" + suffix);
  OutputFile contacts(dir + "/contacts" + suffix);
  const auto count = static_cast<std::size_t>(n);
  PartProgress progress(pairs ? "" : std::string(kind) + " ");
  DrawnSceneOptions how;
  how.format = format;
  how.precision = want_float ? NpyType::f4 : NpyType::f8;
  how.progress = std::ref(progress);
  if (pairs) {
    write_drawn_scene(pairs_scene(count, options), how, bodies, contacts);
  } else {
    write_drawn_scene(debris ? debris_scene(count, options)
                      : pile ? pile_scene(count, options)
                             : chain_scene(count, options),
                      how, bodies, contacts);
  }
  bodies.commit();
  contacts.commit();
  return kExitOk;
}

}  // namespace collide::cli
