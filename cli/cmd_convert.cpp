// cli/cmd_convert.cpp - `collide convert`: a bodies, contacts or impulses
// file from CSV to binary (.npz) or back.
//
// Design notes
// ------------
// * The table a file holds (bodies, contacts or impulses: every table the
//   CLI reads or writes) is read off the file itself: a CSV's header line,
//   an archive's member names. Nothing else is needed on the command line.
// * Exact both ways: CSV to binary stores each value as the CSV reader
//   stores it in the precision asked for (every rule checked, as for a
//   solve), binary to CSV writes each stored value as its shortest
//   round-trip text. So binary -> CSV -> binary gives the same bytes, and
//   CSV -> binary -> CSV the same text for a CSV that collide wrote.
// * The precision of a CSV input, when --precision does not say it, is read
//   off the text, since the text alone holds the values: float when it is
//   what a float table's conversion writes (every number the shortest text
//   of a float, which a float read keeps exactly, and some number of 8 or 9
//   significant digits, which hand-written values and short doubles are not),
//   double otherwise. So a float file comes back as float, the same bytes,
//   and a double file (or a hand-written one of short numbers, read exactly
//   in either precision) as double.
// * Contact ids are checked for what a file alone can tell (non-negative,
//   32-bit, a != b); whether they are below the body count is checked when
//   the scene is solved.
// * The output goes through OutputFile: nothing is written on bad input.
//   Its directory is created when missing (OutputFile, as for every
//   output), once the input has been read.
#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/rules.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kConvertUsage =
    "usage: collide convert --in FILE --out FILE [--precision float|double] [--threads N]\n"
    "\n"
    "Converts a bodies, contacts or impulses file (every table collide reads or\n"
    "writes) between CSV and the binary scene format (NumPy's uncompressed .npz,\n"
    "one array per column; docs/collision-law.md). The format of each file comes\n"
    "from its name: .npz is binary, anything else CSV. Which table the file holds\n"
    "is read from the file.\n"
    "\n"
    "  --in FILE      the file to convert\n"
    "  --out FILE     the converted file: a regular file is replaced atomically\n"
    "                 (its directory is created if needed); '-' (stdout), a device\n"
    "                 or a FIFO is written in place\n"
    "  --precision P  float or double: the precision of the values converted\n"
    "                 (default: a binary file's own; for CSV, float when the text\n"
    "                 is what a float file converts to - every number the shortest\n"
    "                 text of a float, some with 8 or 9 significant digits - else\n"
    "                 double)\n"
    "  --threads N    worker threads, 0 = all (default 0)\n"
    "\n"
    "Values are kept exactly: binary -> CSV -> binary gives the same bytes, in\n"
    "either precision.\n";

namespace {

enum class Table { bodies, contacts, impulses };

/// The table a file holds, and a binary file's own precision.
struct TableFile {
  Table table;
  std::optional<Precision> precision;
};

/// A header line without its newline.
std::string_view header_line(std::string_view header) { return header.substr(0, header.size() - 1); }

TableFile table_of(const std::string& path, SceneFormat format) {
  if (format == SceneFormat::npz) {
    const NpzArchive archive = NpzArchive::map(path);
    Table table = Table::bodies;
    if (archive.find("m") == nullptr) {
      if (archive.find("a") != nullptr) {
        table = Table::contacts;
      } else if (archive.find("jx") != nullptr) {
        table = Table::impulses;
      } else {
        throw SceneError(path,
                         "neither a bodies file (member 'm.npy'), a contacts file (member 'a.npy') nor an impulses "
                         "file (member 'jx.npy')");
      }
    }
    return {table, npz_scene_precision(archive) == NpyType::f4 ? Precision::single : Precision::double_};
  }
  std::ifstream file(path, std::ios::binary);
  std::string first;
  if (!file || !std::getline(file, first)) (void)read_file(path);  // the reader's message for a missing file
  const auto same_header = [&](std::string_view header) {
    // The header line without its newline, and a CR of a CRLF file.
    std::string_view line = first;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    return line == header_line(header);
  };
  if (same_header(bodies_header())) return {Table::bodies, std::nullopt};
  if (same_header(contacts_header())) return {Table::contacts, std::nullopt};
  if (same_header(impulses_header())) return {Table::impulses, std::nullopt};
  throw SceneError(path, 1, SceneError::kNoRow, "",
                   "neither a bodies header (" + std::string(header_line(bodies_header())) + "), a contacts header (" +
                       std::string(header_line(contacts_header())) + ") nor an impulses header (" +
                       std::string(header_line(impulses_header())) + ")");
}

/// One table loaded in precision T.
template <class T>
struct Input {
  std::optional<LoadedBodies<T>> bodies;
  std::optional<LoadedContacts<T>> contacts;
  std::optional<ImpulseBuffer<T>> impulses;

  /// The real columns, rows() values each (contact ids left out).
  [[nodiscard]] std::vector<const T*> columns() const {
    if (bodies) return {bodies->columns().column.begin(), bodies->columns().column.end()};
    if (contacts) {
      const ContactView<T>& c = contacts->view();
      std::vector<const T*> cols = {c.c.x, c.c.y, c.c.z, c.n.x, c.n.y, c.n.z};
      for (const T* optional : {c.e, c.mu}) {
        if (optional != nullptr) cols.push_back(optional);
      }
      return cols;
    }
    const ImpulseView<const T> j = std::as_const(*impulses).view();
    return {j.j.x, j.j.y, j.j.z};
  }
  [[nodiscard]] std::size_t rows() const {
    return bodies ? bodies->size() : contacts ? contacts->size() : impulses->size();
  }
  void write(OutputFile& out, SceneFormat format) const {
    if (bodies) {
      write_body_table(out, format, bodies->columns());
    } else if (contacts) {
      write_contacts(out, format, contacts->view());
    } else {
      write_impulses(out, format, std::as_const(*impulses).view());
    }
  }
};

template <class T>
Input<T> load(const std::string& in, SceneFormat format, Table table) {
  Input<T> input;
  if (table == Table::bodies) {
    input.bodies.emplace(load_bodies<T>(in, format));
  } else if (table == Table::contacts) {
    input.contacts.emplace(load_contacts<T>(in, format, kUnknownBodyCount));
  } else {
    input.impulses.emplace(load_impulses<T>(in, format));
  }
  return input;
}

/// Whether a number read as double (d) and as float (f) was the shortest
/// text of the float, which the float read keeps exactly. `long_text` is set
/// when that text has 8 or 9 significant digits.
bool float_text(double d, float f, bool& long_text) {
  char a[32];
  char b[32];
  const char* const ea = std::to_chars(a, a + sizeof a, d).ptr;
  const char* const eb = std::to_chars(b, b + sizeof b, f).ptr;
  if (ea - a != eb - b || std::memcmp(a, b, static_cast<std::size_t>(eb - b)) != 0) return false;
  int digits = 0;
  int zeros = 0;  // trailing zeros of the digits so far
  for (const char* p = b; p != eb && *p != 'e'; ++p) {
    if (*p < '0' || *p > '9' || (digits == 0 && *p == '0')) continue;
    ++digits;
    zeros = *p == '0' ? zeros + 1 : 0;
  }
  if (digits - zeros >= 8) long_text = true;
  return true;
}

/// Whether a CSV table read in double and in float is the text a float
/// table's conversion writes: every value the shortest text of a float, and
/// some of 8 or 9 significant digits (a table of short numbers is read
/// exactly in either precision and stays double).
bool written_from_floats(const Input<double>& d, const Input<float>& f) {
  const std::vector<const double*> dc = d.columns();
  const std::vector<const float*> fc = f.columns();
  if (dc.size() != fc.size() || d.rows() != f.rows()) return false;
  std::atomic<bool> all{true};
  std::atomic<bool> any_long{false};
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, d.rows(), std::size_t{1} << 14),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              if (!all.load(std::memory_order_relaxed)) return;
                              bool long_text = false;
                              for (std::size_t k = 0; k < dc.size(); ++k) {
                                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                  if (!float_text(dc[k][i], fc[k][i], long_text)) {
                                    all.store(false, std::memory_order_relaxed);
                                    return;
                                  }
                                }
                              }
                              if (long_text) any_long.store(true, std::memory_order_relaxed);
                            });
  return all.load() && any_long.load();
}

/// The output, its directory created if missing (OutputFile).
template <class T>
void write(const Input<T>& input, const std::string& out_path, SceneFormat out_format) {
  OutputFile out(out_path);
  input.write(out, out_format);
  out.commit();
}

}  // namespace

int run_convert(int argc, char** argv) {
  const Options opt =
      parse_options(argc, argv, 2, {{"in", true}, {"out", true}, {"precision", true}, {"threads", true}});
  if (opt.count("help") != 0) {
    std::fputs(kConvertUsage, stdout);
    return kExitOk;
  }
  const std::string& in = required(opt, "in");
  const std::string& out = required(opt, "out");
  const SceneFormat in_format = scene_format_of(in);
  const SceneFormat out_format = scene_format_of(out);
  const std::optional<Precision> precision = parse_precision(opt);
  const ThreadLimit limit(parse_threads(opt));
  const TableFile table = table_of(in, in_format);
  const std::optional<Precision> given = precision ? precision : table.precision;
  if (given == Precision::single) {
    write(load<float>(in, in_format, table.table), out, out_format);
  } else if (given == Precision::double_) {
    write(load<double>(in, in_format, table.table), out, out_format);
  } else {
    // A CSV input without --precision: the text says (design notes). The
    // double read reports what is wrong with the file; a file that float
    // cannot hold (a value out of its range) is double.
    Input<double> as_double = load<double>(in, in_format, table.table);
    std::optional<Input<float>> as_float;
    try {
      as_float.emplace(load<float>(in, in_format, table.table));
    } catch (const SceneError&) {
    }
    if (as_float && written_from_floats(as_double, *as_float)) {
      write(*as_float, out, out_format);
    } else {
      write(as_double, out, out_format);
    }
  }
  return kExitOk;
}

}  // namespace collide::cli
