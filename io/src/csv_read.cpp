// csv_read.cpp - reading the scene CSV files of docs/collision-law.md: bodies.csv into a
// BodyTable, contacts.csv into a ContactBuffer (collide/io/scene_io.hpp).
//
// Design notes
// ------------
// * One pass per file over the whole text, mapped from the page cache (see
//   detail::FileBuffer, input_file.hpp). The data part (after the header) is
//   cut at line boundaries into chunks; a first parallel pass counts the
//   lines of each chunk (so every chunk knows the id of its first row and
//   writes its rows in place), a second parses the chunks in parallel. Each
//   chunk stops at its first bad value and the earliest failure in file
//   order is thrown, so the message is the same for any thread count. Every
//   line after the header is a data row (a blank line in the middle is an
//   error, trailing blank lines are ignored), hence the line of row r is
//   r + 2.
// * Two paths per row: a fast one for the common case (plain numbers, every
//   check passing) that parses straight through with from_chars, and a
//   careful one (split, trim, '+', messages) for everything else. Both accept
//   exactly the same values; the careful one alone builds messages. The
//   fields' text is csv_fields.hpp's.
// * The reader checks the text (numbers, columns, the range of double) and
//   stores each number as every route stores a scene value: the double
//   nearest the text, rounded to T (scene_value, refused when it does not
//   fit T; csv_fields.hpp). The value rules of docs/collision-law.md are rules.hpp's
//   (body_ok / contact_ok on the fast path, body_defect / contact_defect
//   for the message), on the values in T, the precision the kernel will see.
#include "collide/io/scene_io.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/rules.hpp"
#include "csv_fields.hpp"
#include "input_file.hpp"

namespace collide {
namespace {

using detail::fast_numbers;
using detail::FieldCursor;
using detail::FileBuffer;
using detail::is_blank;
using detail::parse_body_id;
using detail::parse_value;
using detail::quoted;
using detail::trim;

/// The first bad value found in a chunk: data row, column index, reason.
struct Failure {
  bool failed = false;
  std::size_t row = 0;
  std::size_t column = 0;
  std::string reason;
};

/// A body row's seventeen values (file order) as a record.
template <class T>
BodyRecord<T> body_record(const T* v) {
  BodyRecord<T> r;
  r.m = v[0];
  for (int k = 0; k < 3; ++k) r.I[k] = v[1 + k];
  for (int k = 0; k < 4; ++k) r.q[k] = v[4 + k];
  for (int k = 0; k < 3; ++k) {
    r.p[k] = v[8 + k];
    r.v[k] = v[11 + k];
    r.w[k] = v[14 + k];
  }
  return r;
}

/// A contact row's values after the ids (cx .. mu) into a record.
template <class T>
void contact_values(const T* v, ContactRecord<T>& rec) {
  for (int k = 0; k < 3; ++k) {
    rec.c[k] = v[k];
    rec.n[k] = v[3 + k];
  }
  rec.e = v[6];
  rec.mu = v[7];
}

/// The index of a rule's column among `names`.
template <std::size_t N>
std::size_t column_index(const std::array<std::string_view, N>& names, std::string_view column) {
  return static_cast<std::size_t>(std::find(names.begin(), names.end(), column) - names.begin());
}

/// Splits the text into its header line and its data rows (trailing blank
/// lines dropped) and checks the header against `names`.
template <std::size_t N>
std::string_view check_header(std::string_view text, const std::string& file,
                              const std::array<std::string_view, N>& names) {
  // A UTF-8 byte-order mark, as spreadsheets write it, is not part of 'm'.
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  const std::size_t nl = text.find('\n');
  const std::string_view header = trim(text.substr(0, nl));
  std::string_view data = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
  if (header.empty()) {
    const bool empty_file = text.find_first_not_of("\r\n \t") == std::string_view::npos;
    throw SceneError(file, 1, SceneError::kNoRow, std::string(names[0]),
                     empty_file ? "missing header: the file is empty" : "missing header: the first line is empty");
  }
  FieldCursor cursor(header.data(), header.data() + header.size());
  std::string_view field;
  for (std::size_t k = 0; k < N; ++k) {
    if (!cursor.next(field)) {
      throw SceneError(file, 1, SceneError::kNoRow, std::string(names[k]),
                       "missing column in the header (found " + std::to_string(k) + " of " + std::to_string(N) +
                           " columns; expected " + std::string(names[0]) + ",...," + std::string(names[N - 1]) + ")");
    }
    if (trim(field) != names[k]) {
      throw SceneError(file, 1, SceneError::kNoRow, std::string(names[k]),
                       "bad header: expected column '" + std::string(names[k]) + "', found " + quoted(field));
    }
  }
  if (cursor.next(field)) {
    // Named after the last expected column, as for data rows, since the extra
    // one may have no name at all (a trailing comma).
    throw SceneError(file, 1, SceneError::kNoRow, std::string(names[N - 1]),
                     "unexpected extra column " + quoted(field) + " in the header after the last column '" +
                         std::string(names[N - 1]) + "' (expected " + std::to_string(N) + " columns)");
  }
  // Trailing newlines, CRs and blanks end the file; they are not rows.
  while (!data.empty() && (data.back() == '\n' || data.back() == '\r' || is_blank(data.back()))) {
    data.remove_suffix(1);
  }
  return data;
}

/// Parses the data rows of a file with N columns in parallel chunks.
/// `prepare(rows)` sizes the destination. `fast_row(begin, end, row)` tries
/// the common case (plain numbers, no blanks, every check passing) and
/// returns false on anything else; then `parse_row(fields, row, failure)`,
/// the careful path, parses the row's N fields again and either accepts
/// them or returns false after filling `failure`. Both paths accept exactly
/// the same values; the fast one only skips the splitting and trimming.
template <std::size_t N, class Prepare, class FastRow, class ParseRow>
void parse_rows(std::string_view data, const std::string& file, const std::array<std::string_view, N>& names,
                Prepare&& prepare, FastRow&& fast_row, ParseRow&& parse_row) {
  if (data.empty()) {
    prepare(std::size_t(0));
    return;
  }
  // Chunks of at least 256 KiB, a few per thread, cut after a newline.
  const std::size_t threads = static_cast<std::size_t>(std::max(1, oneapi::tbb::this_task_arena::max_concurrency()));
  const std::size_t target = std::max<std::size_t>(std::size_t(1) << 18, data.size() / (8 * threads) + 1);
  std::vector<std::size_t> cuts{0};
  while (cuts.back() < data.size()) {
    std::size_t next = cuts.back() + target;
    if (next >= data.size()) {
      next = data.size();
    } else {
      const std::size_t nl = data.find('\n', next);
      next = nl == std::string_view::npos ? data.size() : nl + 1;
    }
    cuts.push_back(next);
  }
  const std::size_t chunks = cuts.size() - 1;
  std::vector<std::size_t> first_row(chunks + 1, 0);
  oneapi::tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    const char* b = data.data() + cuts[c];
    const char* e = data.data() + cuts[c + 1];
    // Every chunk but the last ends with its newline; the last has none.
    first_row[c + 1] = static_cast<std::size_t>(std::count(b, e, '\n')) + (c + 1 == chunks ? 1 : 0);
  });
  for (std::size_t c = 0; c < chunks; ++c) first_row[c + 1] += first_row[c];
  prepare(first_row[chunks]);

  std::vector<Failure> failures(chunks);
  oneapi::tbb::parallel_for(
      oneapi::tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const oneapi::tbb::blocked_range<std::size_t>& range) {
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          const char* p = data.data() + cuts[c];
          const char* end = data.data() + cuts[c + 1];
          std::size_t row = first_row[c];
          std::array<std::string_view, N> fields;
          Failure& failure = failures[c];
          while (p < end) {
            const auto* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
            const char* line_end = nl ? nl : end;
            const char* next = nl ? nl + 1 : end;
            if (line_end > p && line_end[-1] == '\r') --line_end;
            if (fast_row(p, line_end, row)) {
              ++row;
              p = next;
              continue;
            }
            FieldCursor cursor(p, line_end);
            std::size_t k = 0;
            for (; k < N && cursor.next(fields[k]); ++k) {
            }
            if (k == 1 && trim(fields[0]).empty()) {
              failure = {true, row, 0, "empty line (expected " + std::to_string(N) + " columns)"};
              break;
            }
            if (k < N) {
              failure = {true, row, k,
                         "missing column (the row has " + std::to_string(k) + " of " + std::to_string(N) + " columns)"};
              break;
            }
            if (!cursor.done()) {
              failure = {true, row, N - 1,
                         "unexpected extra column after the last column '" + std::string(names[N - 1]) +
                             "' (expected " + std::to_string(N) + " columns)"};
              break;
            }
            if (!parse_row(fields, row, failure)) {
              failure.failed = true;
              failure.row = row;
              break;
            }
            ++row;
            p = next;
          }
        }
      },
      oneapi::tbb::simple_partitioner());

  for (const Failure& f : failures) {
    if (f.failed) throw SceneError(file, f.row + 2, f.row, std::string(names[f.column]), f.reason);
  }
}

}  // namespace

template <class T>
BodyTable<T> parse_bodies(std::string_view text, std::string_view file_name) {
  const std::string file(file_name);
  const std::string_view data = check_header(text, file, kBodyColumns);
  BodyTable<T> table;
  auto prepare = [&](std::size_t rows) { table.resize(rows); };
  auto parse_row = [&](const std::array<std::string_view, 17>& f, std::size_t row, Failure& failure) {
    T v[17];
    for (std::size_t k = 0; k < 17; ++k) {
      if (!parse_value(f[k], v[k], failure.reason)) {
        failure.column = k;
        return false;
      }
    }
    if (std::optional<Defect> defect = body_defect(body_record(v))) {
      failure.column = column_index(kBodyColumns, defect->column);
      failure.reason = std::move(defect->reason);
      return false;
    }
    for (std::size_t k = 0; k < 17; ++k) table.column[k][row] = v[k];
    return true;
  };
  auto fast_row = [&](const char* b, const char* e, std::size_t row) {
    T v[17];
    if (!fast_numbers<17>(b, e, v) || !body_ok(body_record(v))) return false;
    for (std::size_t k = 0; k < 17; ++k) table.column[k][row] = v[k];
    return true;
  };
  parse_rows(data, file, kBodyColumns, prepare, fast_row, parse_row);
  return table;
}

template <class T>
BodyTable<T> read_bodies(const std::string& path) {
  const FileBuffer buf(path);
  return parse_bodies<T>(buf.view(), path);
}

template <class T>
ContactBuffer<T> parse_contacts(std::string_view text, std::string_view file_name, std::size_t body_count) {
  const std::string file(file_name);
  const std::string_view data = check_header(text, file, kContactColumns);
  ContactBuffer<T> contacts;
  auto prepare = [&](std::size_t rows) { contacts.resize(rows); };
  auto parse_row = [&](const std::array<std::string_view, 10>& f, std::size_t row, Failure& failure) {
    ContactRecord<T> rec;
    if (!parse_body_id(f[0], body_count, rec.a, failure.reason)) {
      failure.column = 0;
      return false;
    }
    if (!parse_body_id(f[1], body_count, rec.b, failure.reason)) {
      failure.column = 1;
      return false;
    }
    T v[8];
    for (std::size_t k = 2; k < 10; ++k) {
      if (!parse_value(f[k], v[k - 2], failure.reason)) {
        failure.column = k;
        return false;
      }
    }
    contact_values(v, rec);
    if (std::optional<Defect> defect = contact_defect(rec, body_count)) {
      failure.column = column_index(kContactColumns, defect->column);
      failure.reason = std::move(defect->reason);
      return false;
    }
    contacts.set(row, rec);  // normalises n; writes element `row` only
    return true;
  };
  auto fast_row = [&](const char* b, const char* e, std::size_t row) {
    std::uint64_t ids[2];
    for (std::uint64_t& id : ids) {
      const auto [ptr, ec] = std::from_chars(b, e, id);
      if (ec != std::errc() || ptr == e || *ptr != ',' || id > std::numeric_limits<BodyIndex>::max()) return false;
      b = ptr + 1;
    }
    ContactRecord<T> rec;
    rec.a = static_cast<BodyIndex>(ids[0]);
    rec.b = static_cast<BodyIndex>(ids[1]);
    T v[8];
    if (!fast_numbers<8>(b, e, v)) return false;
    contact_values(v, rec);
    if (!contact_ok(rec, body_count)) return false;
    contacts.set(row, rec);
    return true;
  };
  parse_rows(data, file, kContactColumns, prepare, fast_row, parse_row);
  return contacts;
}

template <class T>
ContactBuffer<T> read_contacts(const std::string& path, std::size_t body_count) {
  const FileBuffer buf(path);
  return parse_contacts<T>(buf.view(), path, body_count);
}

template <class T>
ImpulseBuffer<T> parse_impulses(std::string_view text, std::string_view file_name) {
  const std::string file(file_name);
  const std::string_view data = check_header(text, file, kImpulseColumns);
  ImpulseBuffer<T> impulses;
  ImpulseView<T> j;
  auto prepare = [&](std::size_t rows) {
    impulses.resize(rows);
    j = impulses.view();
  };
  const auto store = [&](const T* v, std::size_t row) {
    j.j.x[row] = v[0];
    j.j.y[row] = v[1];
    j.j.z[row] = v[2];
  };
  auto parse_row = [&](const std::array<std::string_view, 3>& f, std::size_t row, Failure& failure) {
    T v[3];
    for (std::size_t k = 0; k < 3; ++k) {
      if (!parse_value(f[k], v[k], failure.reason)) {
        failure.column = k;
        return false;
      }
    }
    store(v, row);
    return true;
  };
  auto fast_row = [&](const char* b, const char* e, std::size_t row) {
    T v[3];
    if (!fast_numbers<3>(b, e, v)) return false;
    store(v, row);
    return true;
  };
  parse_rows(data, file, kImpulseColumns, prepare, fast_row, parse_row);
  return impulses;
}

template <class T>
ImpulseBuffer<T> read_impulses(const std::string& path) {
  const FileBuffer buf(path);
  return parse_impulses<T>(buf.view(), path);
}

#define COLLIDE_CSV_READ_INSTANTIATE(T)                                                         \
  template BodyTable<T> parse_bodies<T>(std::string_view, std::string_view);                    \
  template BodyTable<T> read_bodies<T>(const std::string&);                                     \
  template ContactBuffer<T> parse_contacts<T>(std::string_view, std::string_view, std::size_t); \
  template ContactBuffer<T> read_contacts<T>(const std::string&, std::size_t);                  \
  template ImpulseBuffer<T> parse_impulses<T>(std::string_view, std::string_view);              \
  template ImpulseBuffer<T> read_impulses<T>(const std::string&);

COLLIDE_CSV_READ_INSTANTIATE(float)
COLLIDE_CSV_READ_INSTANTIATE(double)

#undef COLLIDE_CSV_READ_INSTANTIATE

}  // namespace collide
