// cli/cmd_gen.cpp - `collide gen`: write a random scene as two scene files.
//
// Design notes
// ------------
// * Streaming: items (pairs, or the bodies then the contacts of a debris or
//   pile scene) are
//   generated in blocks by a tbb pipeline: blocks are drawn and formatted in
//   parallel and written in order, with a few blocks in memory at a time, so
//   ten million pairs need tens of megabytes, not gigabytes. Every item is a
//   pure function of (seed, index) (generate.hpp), so the bytes do not depend
//   on the thread count or the block size.
// * Values are written as the shortest text that reads back to the same
//   double (std::to_chars), inf for the ground's mass and moments.
// * Both files go through OutputFile (temporary + rename), so an interrupted
//   or failed run leaves no half-written scene.
// * --format npz writes the binary scene files (collide/io/scene_npz.hpp) in
//   --precision: the columns are drawn in parallel into memory (the same
//   draws as the CSV, rounded to the precision) and written in one pass.
// * A progress line goes to stderr only when stderr is a terminal, so logs
//   and tests see no carriage-return noise.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_pipeline.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kGenUsage =
    "usage: collide gen (--pairs N | --debris N | --pile S [--shuffle]) --out DIR\n"
    "                   [--seed S] [--friction] [--model rigid|sphere|particle]\n"
    "                   [--format csv|npz] [--precision float|double] [--threads N]\n"
    "\n"
    "Writes a random scene as DIR/bodies.csv and DIR/contacts.csv, or with\n"
    "--format npz as the binary DIR/bodies.npz and DIR/contacts.npz (DIR is created\n"
    "if needed). The same seed gives the same bytes.\n"
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

/// A scene drawn body by body and contact by contact (debris, pile): item
/// i of each is a pure function of the options and i (generate.hpp).
struct SharedBodyScene {
  std::string name;  ///< for the progress line
  std::size_t bodies = 0, contacts = 0;
  std::function<void(std::uint64_t, BodyRecord<double>&)> draw_body;
  std::function<void(std::uint64_t, ContactRecord<double>&)> draw_contact;
};

SharedBodyScene debris_scene(std::size_t count, const GenerateOptions& options) {
  return {"debris", debris_body_count(count), count,
          [count, options](std::uint64_t i, BodyRecord<double>& body) { draw_debris_body(options, count, i, body); },
          [count, options](std::uint64_t k, ContactRecord<double>& c) { draw_debris_contact(options, count, k, c); }};
}

SharedBodyScene pile_scene(std::size_t side, const GenerateOptions& options) {
  return {"pile", pile_body_count(side), pile_contact_count(side),
          [side, options](std::uint64_t i, BodyRecord<double>& body) { draw_pile_body(options, side, i, body); },
          [side, options](std::uint64_t k, ContactRecord<double>& c) { draw_pile_contact(options, side, k, c); }};
}

void write_shared(const SharedBodyScene& scene, OutputFile& bodies, OutputFile& contacts) {
  bodies.write(bodies_header());
  {
    Progress progress(scene.name + " bodies", scene.bodies);
    stream_blocks(
        scene.bodies, 8192,
        [&](std::size_t begin, std::size_t end, BlockText& text) {
          BodyRecord<double> body;
          for (std::size_t i = begin; i < end; ++i) {
            scene.draw_body(i, body);
            append_body_row(text.first, body);
          }
        },
        [&](const BlockText& text, std::size_t done) {
          bodies.write(text.first);
          progress.update(done);
        });
  }
  contacts.write(contacts_header());
  Progress progress(scene.name + " contacts", scene.contacts);
  stream_blocks(
      scene.contacts, 8192,
      [&](std::size_t begin, std::size_t end, BlockText& text) {
        ContactRecord<double> c;
        for (std::size_t k = begin; k < end; ++k) {
          scene.draw_contact(k, c);
          append_contact_row(text.first, c);
        }
      },
      [&](const BlockText& text, std::size_t done) {
        contacts.write(text.first);
        progress.update(done);
      });
}

/// Draws the scene (pairs of `pairs` pairs, or else `shared`) into columns
/// of T and writes them as binary files.
template <class T>
void write_npz_scene(const SharedBodyScene* shared, std::size_t pairs, const GenerateOptions& options,
                     OutputFile& bodies_out, OutputFile& contacts_out) {
  const std::size_t body_count = shared ? shared->bodies : 2 * pairs;
  const std::size_t n = shared ? shared->contacts : pairs;
  BodyTable<T> table;
  table.resize(body_count);
  std::vector<BodyIndex> a(n), b(n);
  std::array<std::vector<T>, 8> real;  // cx cy cz nx ny nz e mu
  for (auto& c : real) c.resize(n);
  const auto put_body = [&table](std::size_t i, const BodyRecord<double>& r) {
    const double v[17] = {r.m,    r.I[0], r.I[1], r.I[2], r.q[0], r.q[1], r.q[2], r.q[3], r.p[0],
                          r.p[1], r.p[2], r.v[0], r.v[1], r.v[2], r.w[0], r.w[1], r.w[2]};
    for (std::size_t k = 0; k < 17; ++k) table.column[k][i] = static_cast<T>(v[k]);
  };
  const auto put_contact = [&](std::size_t k, const ContactRecord<double>& c) {
    a[k] = c.a;
    b[k] = c.b;
    const double v[8] = {c.c[0], c.c[1], c.c[2], c.n[0], c.n[1], c.n[2], c.e, c.mu};
    for (std::size_t j = 0; j < 8; ++j) real[j][k] = static_cast<T>(v[j]);
  };
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  if (!shared) {
    oneapi::tbb::parallel_for(Range(0, n, 8192), [&](const Range& r) {
      BodyRecord<double> ba, bb;
      ContactRecord<double> c;
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        draw_pair(options, k, ba, bb, c);
        put_body(2 * k, ba);
        put_body(2 * k + 1, bb);
        put_contact(k, c);
      }
    });
  } else {
    oneapi::tbb::parallel_for(Range(0, body_count, 8192), [&](const Range& r) {
      BodyRecord<double> body;
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        shared->draw_body(i, body);
        put_body(i, body);
      }
    });
    oneapi::tbb::parallel_for(Range(0, n, 8192), [&](const Range& r) {
      ContactRecord<double> c;
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        shared->draw_contact(k, c);
        put_contact(k, c);
      }
    });
  }
  write_body_table_npz(bodies_out, columns_of(table));
  ContactView<T> contacts;
  contacts.count = n;
  contacts.a = a.data();
  contacts.b = b.data();
  contacts.c = {real[0].data(), real[1].data(), real[2].data()};
  contacts.n = {real[3].data(), real[4].data(), real[5].data()};
  contacts.e = real[6].data();
  contacts.mu = real[7].data();
  write_contacts_npz(contacts_out, contacts);
}

}  // namespace

int run_gen(int argc, char** argv) {
  const Options opt = parse_options(argc, argv, 2,
                                    {{"pairs", true},
                                     {"debris", true},
                                     {"pile", true},
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
  if (static_cast<int>(pairs) + static_cast<int>(debris) + static_cast<int>(pile) != 1) {
    throw UsageError("give exactly one of --pairs N, --debris N and --pile S");
  }
  const char* const kind = pairs ? "pairs" : debris ? "debris" : "pile";
  const unsigned long long n = parse_count(kind, opt.at(kind));
  // Body ids are 32-bit (contacts.hpp): 2N bodies for pairs, N/2 + 1 for
  // debris, S^3 + 1 for a pile.
  if (pile && n > kMaxPileSide) {
    throw UsageError("--pile " + opt.at("pile") + " is too large: at most " + std::to_string(kMaxPileSide) +
                     " boxes per side (body ids are 32-bit)");
  }
  const unsigned long long max_n = pairs ? 0x7FFFFFFFULL : 0xFFFFFFFFULL;
  if (n > max_n) throw UsageError("scene too large: body ids are 32-bit");
  if (opt.count("shuffle") != 0 && !pile) {
    throw UsageError("--shuffle is for --pile (the pairs and debris contacts have no spatial order to shuffle)");
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

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "collide: cannot create directory '%s': %s\n", dir.c_str(),
                 ec ? ec.message().c_str() : "not a directory");
    return kExitBadInput;
  }
  const std::string suffix = format == SceneFormat::npz ? ".npz" : ".csv";
  OutputFile bodies(dir + "/bodies" + suffix);
  OutputFile contacts(dir + "/contacts" + suffix);
  const auto count = static_cast<std::size_t>(n);
  std::optional<SharedBodyScene> shared;
  if (debris) shared = debris_scene(count, options);
  if (pile) shared = pile_scene(count, options);
  const SharedBodyScene* const scene = shared ? &*shared : nullptr;
  if (format == SceneFormat::npz) {
    if (want_float) {
      write_npz_scene<float>(scene, count, options, bodies, contacts);
    } else {
      write_npz_scene<double>(scene, count, options, bodies, contacts);
    }
  } else if (scene) {
    write_shared(*scene, bodies, contacts);
  } else {
    write_pairs(count, options, bodies, contacts);
  }
  bodies.commit();
  contacts.commit();
  return kExitOk;
}

}  // namespace collide::cli
