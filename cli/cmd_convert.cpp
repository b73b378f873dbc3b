// cli/cmd_convert.cpp - `collide convert`: a scene file from CSV to binary
// (.npz) or back.
//
// Design notes
// ------------
// * The table a file holds (bodies or contacts) is read off the file itself:
//   a CSV's header line, an archive's member names. Nothing else is needed
//   on the command line.
// * Exact both ways: CSV to binary stores each value as the CSV reader
//   stores it in the precision asked for (every rule checked, as for a
//   solve), binary to CSV writes each stored value as its shortest
//   round-trip text. So binary -> CSV -> binary gives the same bytes, and
//   CSV -> binary -> CSV the same text for a CSV that collide wrote.
// * Contact ids are checked for what a file alone can tell (non-negative,
//   32-bit, a != b); whether they are below the body count is checked when
//   the scene is solved.
// * The output goes through OutputFile: nothing is written on bad input.
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>

#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/rules.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kConvertUsage =
    "usage: collide convert --in FILE --out FILE [--precision float|double] [--threads N]\n"
    "\n"
    "Converts a bodies or contacts file between CSV and the binary scene format\n"
    "(NumPy's uncompressed .npz, one array per column; docs/collision-law.md).\n"
    "The format of each file comes from its name: .npz is binary, anything else\n"
    "CSV. Which table the file holds is read from the file.\n"
    "\n"
    "  --in FILE      the file to convert\n"
    "  --out FILE     the converted file: a regular file is replaced atomically;\n"
    "                 '-' (stdout), a device or a FIFO is written in place\n"
    "  --precision P  float or double: the precision of the values converted\n"
    "                 (default: a binary file's own, double for CSV text)\n"
    "  --threads N    worker threads, 0 = all (default 0)\n"
    "\n"
    "Values are kept exactly: binary -> CSV -> binary gives the same bytes.\n";

namespace {

enum class Table { bodies, contacts };

/// The table a file holds, and a binary file's own precision.
struct TableFile {
  Table table;
  std::optional<Precision> precision;
};

TableFile table_of(const std::string& path, SceneFormat format) {
  if (format == SceneFormat::npz) {
    const NpzArchive archive = NpzArchive::map(path);
    const bool bodies = archive.find("m") != nullptr;
    if (!bodies && archive.find("a") == nullptr) {
      throw SceneError(path, "neither a bodies file (member 'm.npy') nor a contacts file (member 'a.npy')");
    }
    return {bodies ? Table::bodies : Table::contacts,
            npz_scene_precision(archive) == NpyType::f4 ? Precision::single : Precision::double_};
  }
  std::ifstream file(path, std::ios::binary);
  std::string first;
  if (!file || !std::getline(file, first)) (void)read_file(path);  // the reader's message for a missing file
  const auto same_header = [&](std::string_view header) {
    // The header line without its newline, and a CR of a CRLF file.
    std::string_view line = first;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    return line == header.substr(0, header.size() - 1);
  };
  if (same_header(bodies_header())) return {Table::bodies, std::nullopt};
  if (same_header(contacts_header())) return {Table::contacts, std::nullopt};
  throw SceneError(path, 1, SceneError::kNoRow, "",
                   "neither a bodies header (" + std::string(bodies_header().substr(0, bodies_header().size() - 1)) +
                       ") nor a contacts header (" +
                       std::string(contacts_header().substr(0, contacts_header().size() - 1)) + ")");
}

template <class T>
void convert(const std::string& in, SceneFormat in_format, Table table, const std::string& out_path,
             SceneFormat out_format) {
  OutputFile out(out_path);
  if (table == Table::bodies) {
    const LoadedBodies<T> bodies = load_bodies<T>(in, in_format);
    write_body_table(out, out_format, bodies.columns());
  } else {
    const LoadedContacts<T> contacts = load_contacts<T>(in, in_format, kUnknownBodyCount);
    write_contacts(out, out_format, contacts.view());
  }
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
  const Precision chosen = precision.value_or(table.precision.value_or(Precision::double_));
  if (chosen == Precision::single) {
    convert<float>(in, in_format, table.table, out, out_format);
  } else {
    convert<double>(in, in_format, table.table, out, out_format);
  }
  return kExitOk;
}

}  // namespace collide::cli
