// drawn_scene.cpp - writing a scene drawn item by item to its two scene files
// (collide/io/drawn_scene.hpp).
//
// Design notes
// ------------
// * CSV: the blocks run through the CSV writers' pipeline
//   (ordered_blocks.hpp): drawn and formatted in parallel with the writers'
//   row formatting (append_body_row, append_contact_row), written in order.
//   Separately drawn bodies and contacts are two passes, one per file; pairs
//   are one pass writing both files, so each pair is drawn once (its draw
//   costs about as much as formatting its rows).
// * Blocks of 8192 items: a few megabytes of text per block in flight (a
//   pair is about 800 bytes of CSV), enough to keep the threads busy.
// * npz: the columns are drawn in parallel into a BodyTable and contact
//   columns (each value rounded to T by scene_value, as detail::narrow
//   rounds the generated scenes), then written by write_body_table_npz and
//   write_contacts_npz. Held whole, as a column-by-column file needs them:
//   about 340 bytes a pair in double.
#include "collide/io/drawn_scene.hpp"

#include <array>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include "collide/io/scene_io.hpp"
#include "collide/io/scene_values.hpp"
#include "ordered_blocks.hpp"

namespace collide {
namespace {

constexpr std::size_t kBlock = 8192;

using Progress = std::function<void(std::string_view, std::size_t, std::size_t)>;

void check_options(const DrawnSceneOptions& options) {
  if (options.precision != NpyType::f4 && options.precision != NpyType::f8) {
    throw std::invalid_argument("a drawn scene's precision must be f4 or f8, got " +
                                std::string(npy_descr(options.precision)));
  }
  if (options.format == SceneFormat::csv && options.precision != NpyType::f8) {
    throw std::invalid_argument("a CSV scene is written from the doubles drawn: its precision is f8");
  }
}

/// Writes `count` CSV rows to `out` after `header`: fill(begin, end, text)
/// appends rows [begin, end) to text; progress(part, done, count) after each
/// block.
template <class Fill>
void stream_rows(OutputFile& out, std::string_view header, std::size_t count, std::string_view part,
                 const Progress& progress, const Fill& fill) {
  out.write(header);
  detail::ordered_blocks<std::string>(
      count, kBlock,
      [&](std::size_t begin, std::size_t end, std::string& text) {
        text.clear();
        fill(begin, end, text);
      },
      [&](const std::string& text, std::size_t done) {
        out.write(text);
        if (progress) progress(part, done, count);
      });
}

/// The columns of a binary scene in precision T, filled row by row from
/// several threads (each row written by one) and written whole.
template <class T>
class SceneColumns {
 public:
  SceneColumns(std::size_t bodies, std::size_t contacts) : a_(contacts), b_(contacts) {
    table_.resize(bodies);
    for (auto& c : real_) c.resize(contacts);
  }

  void put_body(std::size_t i, const BodyRecord<double>& r) {
    const double v[17] = {r.m,    r.I[0], r.I[1], r.I[2], r.q[0], r.q[1], r.q[2], r.q[3], r.p[0],
                          r.p[1], r.p[2], r.v[0], r.v[1], r.v[2], r.w[0], r.w[1], r.w[2]};
    for (std::size_t k = 0; k < 17; ++k) table_.column[k][i] = scene_value<T>(v[k]);
  }

  void put_contact(std::size_t k, const ContactRecord<double>& c) {
    a_[k] = c.a;
    b_[k] = c.b;
    const double v[8] = {c.c[0], c.c[1], c.c[2], c.n[0], c.n[1], c.n[2], c.e, c.mu};
    for (std::size_t j = 0; j < 8; ++j) real_[j][k] = scene_value<T>(v[j]);
  }

  void write(OutputFile& bodies, OutputFile& contacts) const {
    write_body_table_npz(bodies, columns_of(table_));
    ContactView<T> view;
    view.count = a_.size();
    view.a = a_.data();
    view.b = b_.data();
    view.c = {real_[0].data(), real_[1].data(), real_[2].data()};
    view.n = {real_[3].data(), real_[4].data(), real_[5].data()};
    view.e = real_[6].data();
    view.mu = real_[7].data();
    write_contacts_npz(contacts, view);
  }

 private:
  BodyTable<T> table_;
  std::vector<BodyIndex> a_, b_;
  std::array<std::vector<T>, 8> real_;  // cx cy cz nx ny nz e mu
};

using Range = oneapi::tbb::blocked_range<std::size_t>;

template <class T>
void write_npz(const DrawnScene& scene, OutputFile& bodies, OutputFile& contacts) {
  SceneColumns<T> columns(scene.bodies, scene.contacts);
  oneapi::tbb::parallel_for(Range(0, scene.bodies, kBlock), [&](const Range& r) {
    BodyRecord<double> body;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      scene.draw_body(i, body);
      columns.put_body(i, body);
    }
  });
  oneapi::tbb::parallel_for(Range(0, scene.contacts, kBlock), [&](const Range& r) {
    ContactRecord<double> c;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      scene.draw_contact(k, c);
      columns.put_contact(k, c);
    }
  });
  columns.write(bodies, contacts);
}

template <class T>
void write_npz(const DrawnPairs& scene, OutputFile& bodies, OutputFile& contacts) {
  SceneColumns<T> columns(2 * scene.pairs, scene.pairs);
  oneapi::tbb::parallel_for(Range(0, scene.pairs, kBlock), [&](const Range& r) {
    BodyRecord<double> a, b;
    ContactRecord<double> c;
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      scene.draw_pair(k, a, b, c);
      columns.put_body(2 * k, a);
      columns.put_body(2 * k + 1, b);
      columns.put_contact(k, c);
    }
  });
  columns.write(bodies, contacts);
}

/// The text of one block of pairs: its rows of each file.
struct PairText {
  std::string bodies, contacts;
};

/// Checks the options and, when they ask for npz, writes the scene in its
/// precision and returns true; false leaves CSV to the caller.
template <class Drawn>
bool write_npz_if_asked(const Drawn& scene, const DrawnSceneOptions& options, OutputFile& bodies,
                        OutputFile& contacts) {
  check_options(options);
  if (options.format != SceneFormat::npz) return false;
  if (options.precision == NpyType::f4) {
    write_npz<float>(scene, bodies, contacts);
  } else {
    write_npz<double>(scene, bodies, contacts);
  }
  return true;
}

}  // namespace

void write_drawn_scene(const DrawnScene& scene, const DrawnSceneOptions& options, OutputFile& bodies,
                       OutputFile& contacts) {
  if (write_npz_if_asked(scene, options, bodies, contacts)) return;
  stream_rows(bodies, bodies_header(), scene.bodies, "bodies", options.progress,
              [&](std::size_t begin, std::size_t end, std::string& text) {
                BodyRecord<double> body;
                for (std::size_t i = begin; i < end; ++i) {
                  scene.draw_body(i, body);
                  append_body_row(text, body);
                }
              });
  stream_rows(contacts, contacts_header(), scene.contacts, "contacts", options.progress,
              [&](std::size_t begin, std::size_t end, std::string& text) {
                ContactRecord<double> c;
                for (std::size_t k = begin; k < end; ++k) {
                  scene.draw_contact(k, c);
                  append_contact_row(text, c);
                }
              });
}

void write_drawn_scene(const DrawnPairs& scene, const DrawnSceneOptions& options, OutputFile& bodies,
                       OutputFile& contacts) {
  if (write_npz_if_asked(scene, options, bodies, contacts)) return;
  bodies.write(bodies_header());
  contacts.write(contacts_header());
  detail::ordered_blocks<PairText>(
      scene.pairs, kBlock,
      [&](std::size_t begin, std::size_t end, PairText& text) {
        text.bodies.clear();
        text.contacts.clear();
        BodyRecord<double> a, b;
        ContactRecord<double> c;
        for (std::size_t k = begin; k < end; ++k) {
          scene.draw_pair(k, a, b, c);
          append_body_row(text.bodies, a);
          append_body_row(text.bodies, b);
          append_contact_row(text.contacts, c);
        }
      },
      [&](const PairText& text, std::size_t done) {
        bodies.write(text.bodies);
        contacts.write(text.contacts);
        if (options.progress) options.progress("pairs", done, scene.pairs);
      });
}

}  // namespace collide
