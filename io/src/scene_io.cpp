// scene_io.cpp - the scene CSV files of the spec: parsing, validation, writing.
//
// Design notes
// ------------
// * One pass per file over the whole text, mapped from the page cache (see
//   FileBuffer). The data part (after the header) is cut at line boundaries
//   into chunks; a first parallel pass
//   counts the lines of each chunk (so every chunk knows the id of its first
//   row and writes its rows in place), a second parses the chunks in
//   parallel. Each chunk stops at its first bad value and the earliest
//   failure in file order is thrown, so the message is the same for any
//   thread count. Every line after the header is a data row (a blank line in
//   the middle is an error, trailing blank lines are ignored), hence the line
//   of row r is r + 2.
// * Two paths per row: a fast one for the common case (plain numbers, every
//   check passing) that parses straight through with from_chars, and a
//   careful one (split, trim, '+', messages) for everything else. Both accept
//   exactly the same values; the careful one alone builds messages.
// * Numbers: std::from_chars (correctly rounded, locale-free, accepts inf,
//   infinity and nan case-insensitively). A leading '+' is allowed. A value
//   out of the range of T is an error if it overflows and rounds to a
//   subnormal or zero if it underflows (strtof/strtod semantics).
// * The reader checks the text (numbers, columns, the range of T); the value
//   rules of the spec are rules.hpp's (body_ok / contact_ok on the fast path,
//   body_defect / contact_defect for the message), on the values in T, the
//   precision the kernel will see.
// * Writing: blocks of rows are formatted in parallel with std::to_chars
//   (shortest text that reads back to the same T) and written in order
//   through a tbb pipeline, so memory stays bounded and output is identical
//   for any thread count.
#include "collide/io/scene_io.hpp"

#include "input_file.hpp"
#include "screen_chunks.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <system_error>
#include <type_traits>
#include <utility>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_pipeline.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

namespace collide {

// ---------------------------------------------------------------------------
// SceneError
// ---------------------------------------------------------------------------
namespace {

std::string located_message(const std::string& file, std::size_t line, std::size_t row, const std::string& column,
                            const std::string& reason) {
  std::string msg = file;
  if (line != 0) msg += ":" + std::to_string(line);
  msg += ": ";
  if (row != SceneError::kNoRow) {
    msg += "row " + std::to_string(row) + ", ";
  } else if (line != 0) {
    msg += "header, ";
  }
  if (!column.empty()) msg += "column '" + column + "': ";
  msg += reason;
  return msg;
}

}  // namespace

SceneError::SceneError(std::string file, std::size_t line, std::size_t row, std::string column, std::string reason)
    : std::runtime_error(located_message(file, line, row, column, reason)),
      file_(std::move(file)),
      line_(line),
      row_(row),
      column_(std::move(column)),
      reason_(std::move(reason)) {}

SceneError::SceneError(std::string file, std::string reason)
    : std::runtime_error(located_message(file, 0, kNoRow, std::string(), reason)),
      file_(std::move(file)),
      reason_(std::move(reason)) {}

SceneError::SceneError(std::string file, std::string reason, int os_error)
    : SceneError(std::move(file), std::move(reason)) {
  os_error_ = os_error;
}

// ---------------------------------------------------------------------------
// BodyTable
// ---------------------------------------------------------------------------
template <class T>
BodyRecord<T> BodyTable<T>::record(std::size_t i) const {
  BodyRecord<T> r;
  r.m = column[m][i];
  for (int k = 0; k < 3; ++k) r.I[k] = column[Ix + k][i];
  for (int k = 0; k < 4; ++k) r.q[k] = column[qw + k][i];
  for (int k = 0; k < 3; ++k) {
    r.p[k] = column[px + k][i];
    r.v[k] = column[vx + k][i];
    r.w[k] = column[wx + k][i];
  }
  return r;
}

template <class T>
void BodyTable<T>::push_back(const BodyRecord<T>& body) {
  column[m].push_back(body.m);
  for (int k = 0; k < 3; ++k) column[Ix + k].push_back(body.I[k]);
  for (int k = 0; k < 4; ++k) column[qw + k].push_back(body.q[k]);
  for (int k = 0; k < 3; ++k) column[px + k].push_back(body.p[k]);
  for (int k = 0; k < 3; ++k) column[vx + k].push_back(body.v[k]);
  for (int k = 0; k < 3; ++k) column[wx + k].push_back(body.w[k]);
}

// ---------------------------------------------------------------------------
// Reading files
// ---------------------------------------------------------------------------
namespace {

/// The bytes of an input file. Regular files are mapped (MAP_POPULATE):
/// the parser reads the page cache directly, where reading into a fresh
/// buffer would first have to fault in and zero as much anonymous memory as
/// the file is large, which costs more than parsing on a VM. Pipes and
/// devices are read into a growing buffer. (A mapped file truncated by
/// another process while it is parsed raises SIGBUS; inputs are not
/// expected to change under the tool.)
class FileBuffer {
 public:
  FileBuffer() = default;
  FileBuffer(const FileBuffer&) = delete;
  FileBuffer& operator=(const FileBuffer&) = delete;
  ~FileBuffer() {
    if (mapped_ != nullptr) ::munmap(mapped_, size_);
  }
  [[nodiscard]] std::string_view view() const {
    return {mapped_ != nullptr ? static_cast<const char*>(mapped_) : heap_.get(), size_};
  }

  explicit FileBuffer(const std::string& path) {
    const detail::InputFile file(path);
    const int fd = file.fd();
    if (file.regular() && file.size() > 0) {
      size_ = file.size();
      void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      if (p != MAP_FAILED) {
        mapped_ = p;
        return;
      }
      size_ = 0;  // fall back to reading
    }
    std::size_t capacity = std::size_t(1) << 20;
    heap_.reset(new char[capacity]);
    for (;;) {
      const ssize_t got = ::read(fd, heap_.get() + size_, capacity - size_);
      if (got < 0) {
        const int err = errno;
        if (err == EINTR) continue;
        throw SceneError(path, std::string("read error: ") + std::strerror(err), err);
      }
      if (got == 0) break;
      size_ += static_cast<std::size_t>(got);
      if (size_ == capacity) {
        capacity *= 2;
        std::unique_ptr<char[]> bigger(new char[capacity]);
        std::memcpy(bigger.get(), heap_.get(), size_);
        heap_ = std::move(bigger);
      }
    }
  }

 private:
  void* mapped_ = nullptr;
  std::unique_ptr<char[]> heap_;
  std::size_t size_ = 0;
};

}  // namespace

std::string read_file(const std::string& path) {
  const FileBuffer buf(path);
  return std::string(buf.view());
}

// ---------------------------------------------------------------------------
// Parsing
// ---------------------------------------------------------------------------
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && (is_blank(s.back()) || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// The field text as quoted in a message, shortened if long.
std::string quoted(std::string_view field) {
  field = trim(field);
  constexpr std::size_t kMax = 40;
  std::string s = "'";
  if (field.size() > kMax) {
    s.append(field.substr(0, kMax));
    s += "...";
  } else {
    s.append(field);
  }
  s += "'";
  return s;
}

/// Walks the comma-separated fields of one line.
class FieldCursor {
 public:
  FieldCursor(const char* begin, const char* end) : p_(begin), end_(end) {}
  /// The next field; false when the line has no more fields.
  bool next(std::string_view& field) {
    if (done_) return false;
    const auto* comma = static_cast<const char*>(std::memchr(p_, ',', static_cast<std::size_t>(end_ - p_)));
    if (comma == nullptr) {
      field = std::string_view(p_, static_cast<std::size_t>(end_ - p_));
      done_ = true;
    } else {
      field = std::string_view(p_, static_cast<std::size_t>(comma - p_));
      p_ = comma + 1;
    }
    return true;
  }
  [[nodiscard]] bool done() const { return done_; }

 private:
  const char* p_;
  const char* end_;
  bool done_ = false;
};

/// The first bad value found in a chunk: data row, column index, reason.
struct Failure {
  bool failed = false;
  std::size_t row = 0;
  std::size_t column = 0;
  std::string reason;
};

enum class NumberStatus { ok, empty, syntax, overflow };

template <class T>
NumberStatus parse_real(std::string_view field, T& value) {
  field = trim(field);
  if (field.empty()) return NumberStatus::empty;
  const char* first = field.data();
  const char* last = first + field.size();
  // from_chars takes no '+'; the spec's files may well have one ("+inf").
  if (*first == '+') {
    ++first;
    if (first == last || *first == '+' || *first == '-') return NumberStatus::syntax;
  }
  const auto [ptr, ec] = std::from_chars(first, last, value, std::chars_format::general);
  if (ptr != last) return NumberStatus::syntax;
  if (ec == std::errc()) return NumberStatus::ok;
  if (ec != std::errc::result_out_of_range) return NumberStatus::syntax;
  // Out of range: overflow is an error; underflow rounds to a subnormal or
  // zero as strtod does (the rare path, so a copy is fine).
  const std::string copy(first, last);
  errno = 0;
  T v;
  if constexpr (std::is_same_v<T, float>) {
    v = std::strtof(copy.c_str(), nullptr);
  } else {
    v = std::strtod(copy.c_str(), nullptr);
  }
  if (std::isinf(v)) return NumberStatus::overflow;
  value = v;
  return NumberStatus::ok;
}

/// Parses a real: the reader's own, text-level checks (the field is a
/// number, and within the range of T). The value rules are rules.hpp's.
template <class T>
bool parse_value(std::string_view field, T& value, std::string& reason) {
  switch (parse_real(field, value)) {
    case NumberStatus::ok:
      return true;
    case NumberStatus::empty:
      reason = "empty value";
      return false;
    case NumberStatus::syntax:
      reason = "not a number: " + quoted(field);
      return false;
    case NumberStatus::overflow:
      reason = quoted(field) + " is out of the range of " + precision_name<T>();
      return false;
  }
  return false;
}

/// Parses a body id: a non-negative integer that fits BodyIndex. Whether it
/// is below the body count is a rule (rules.hpp), checked with the row; an
/// id too large for BodyIndex gets that rule's message here.
bool parse_body_id(std::string_view field, std::size_t body_count, BodyIndex& id, std::string& reason) {
  field = trim(field);
  if (field.empty()) {
    reason = "empty value";
    return false;
  }
  const char* first = field.data();
  const char* last = first + field.size();
  if (*first == '+' && last - first > 1) ++first;
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    reason = "body id must be a non-negative integer, got " + quoted(field);
    return false;
  }
  if (ec == std::errc::result_out_of_range || v > std::numeric_limits<BodyIndex>::max()) {
    reason = body_id_out_of_range(ec == std::errc() ? std::to_string(v) : std::string(first, last), body_count);
    return false;
  }
  id = static_cast<BodyIndex>(v);
  return true;
}

/// Reads N plain comma-separated numbers filling the whole of [p, e): no
/// blanks, no '+', nothing out of range. False on anything else, which the
/// careful path then parses or rejects with a message.
template <std::size_t N, class T>
bool fast_numbers(const char* p, const char* e, T* out) {
  for (std::size_t k = 0; k < N; ++k) {
    const auto [ptr, ec] = std::from_chars(p, e, out[k]);
    if (ec != std::errc()) return false;
    if (k + 1 < N) {
      if (ptr == e || *ptr != ',') return false;
      p = ptr + 1;
    } else if (ptr != e) {
      return false;
    }
  }
  return true;
}

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
bool bodies_ok(const BodyColumns<T>& columns, std::size_t i0, std::size_t i1) noexcept {
  // The rules of body_ok (collide/rules.hpp), one column at a time and
  // without a branch per value, defects OR-ed into an integer so that the
  // loops vectorise: x - x == 0 exactly when x is finite.
  const auto finite = [](T x) { return (x - x) == T(0); };
  unsigned bad = 0;
  for (std::size_t k = 0; k < 4; ++k) {  // m and the moments: > 0 with a finite inverse (inf is allowed)
    const T* x = columns.column[k];
    for (std::size_t i = i0; i < i1; ++i) {
      bad |= static_cast<unsigned>(!(x[i] > T(0))) | static_cast<unsigned>(!finite(T(1) / x[i]));
    }
  }
  for (std::size_t k = 4; k < columns.column.size(); ++k) {
    const T* x = columns.column[k];
    for (std::size_t i = i0; i < i1; ++i) bad |= static_cast<unsigned>(!finite(x[i]));
  }
  const T *qw = columns.column[4], *qx = columns.column[5], *qy = columns.column[6], *qz = columns.column[7];
  for (std::size_t i = i0; i < i1; ++i) {
    const T q2 = quaternion_square(qw[i], qx[i], qy[i], qz[i]);  // quaternion_normalisable, without a branch
    bad |= static_cast<unsigned>(!finite(q2)) | static_cast<unsigned>(!(q2 >= std::numeric_limits<T>::min()));
  }
  return bad == 0;
}

template <class T>
std::optional<RowDefect> first_body_defect(const BodyColumns<T>& columns) {
  const std::size_t n = columns.size();
  if (detail::screen_chunks(n, [&](std::size_t i0, std::size_t i1) { return bodies_ok(columns, i0, i1); })) {
    return std::nullopt;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (std::optional<Defect> defect = body_defect(columns.record(i))) return RowDefect{i, std::move(*defect)};
  }
  return std::nullopt;  // not reached: bodies_ok gives body_ok's verdicts
}

template <class T>
BodyBuffer<T> to_body_buffer(const BodyColumns<T>& table) {
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  // The rules first, in parallel and without messages; the first body that
  // breaks one goes through set(), which names its defect as it always has.
  if (const std::optional<RowDefect> bad = first_body_defect(table)) {
    BodyBuffer<T>(bad->row + 1).set(bad->row, table.record(bad->row));  // throws
  }
  BodyBuffer<T> bodies(table.size());
  // Column by column: q, p, v and w are copied as they are, m and I
  // inverted (inverses_of). Disjoint row ranges, so threads never share an
  // element.
  BodyView<T> v = bodies.view();
  T* const copied[13] = {v.q.w, v.q.x, v.q.y, v.q.z, v.p.x, v.p.y, v.p.z, v.v.x, v.v.y, v.v.z, v.w.x, v.w.y, v.w.z};
  oneapi::tbb::parallel_for(Range(0, table.size(), 1 << 16), [&](const Range& r) {
    const std::size_t i0 = r.begin(), n = r.size();
    for (std::size_t k = 0; k < 13; ++k) std::memcpy(copied[k] + i0, table.column[4 + k] + i0, n * sizeof(T));
  });
  inverses_of(table, v.inv_mass, v.inv_inertia);
  return bodies;
}

template <class T>
void inverses_of(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia) {
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  // As BodyBuffer::set: 1/inf = 0, and an immovable body has no inverse
  // moments whatever its I (the law).
  oneapi::tbb::parallel_for(Range(0, columns.count, 1 << 16), [&](const Range& r) {
    const T inf = std::numeric_limits<T>::infinity();
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const T m = columns.column[0][i];
      const bool immovable = m == inf;
      inv_mass[i] = immovable ? T(0) : T(1) / m;
      const T ix = columns.column[1][i], iy = columns.column[2][i], iz = columns.column[3][i];
      inv_inertia.x[i] = immovable || ix == inf ? T(0) : T(1) / ix;
      inv_inertia.y[i] = immovable || iy == inf ? T(0) : T(1) / iy;
      inv_inertia.z[i] = immovable || iz == inf ? T(0) : T(1) / iz;
    }
  });
}

template <class T>
BodyTable<T> to_body_table(const BodyView<const T>& bodies) {
  using Table = BodyTable<T>;
  Table table;
  table.resize(bodies.count);
  // 1/x with 1/0 = inf, as BodyBuffer::record reads a body back.
  auto physical = [](T x) { return x == T(0) ? std::numeric_limits<T>::infinity() : T(1) / x; };
  const T* from[Table::kCount] = {
      bodies.inv_mass, bodies.inv_inertia.x, bodies.inv_inertia.y, bodies.inv_inertia.z, bodies.q.w, bodies.q.x,
      bodies.q.y,      bodies.q.z,           bodies.p.x,           bodies.p.y,           bodies.p.z, bodies.v.x,
      bodies.v.y,      bodies.v.z,           bodies.w.x,           bodies.w.y,           bodies.w.z};
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, bodies.count, 1 << 14),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t k = 0; k < Table::kCount; ++k) {
                                T* to = table.column[k].data();
                                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                  to[i] = k <= Table::Iz ? physical(from[k][i]) : from[k][i];
                                }
                              }
                            });
  return table;
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

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------
namespace {

/// Upper bound on the characters of one number (double: 24, float: 15).
constexpr std::size_t kMaxNumberChars = 26;
/// Upper bound on the characters of one body id (2^32 - 1: 10).
constexpr std::size_t kMaxIdChars = 12;

template <class T>
inline char* put_number(char* p, T value) {
  // Shortest round trip; to_chars writes inf as "inf" already.
  return std::to_chars(p, p + kMaxNumberChars, value).ptr;
}

/// Formats rows [begin, end) with `row(p, i) -> p` appending one row of at
/// most `max_row_chars` characters.
template <class RowFn>
void format_rows(std::string& out, std::size_t begin, std::size_t end, std::size_t max_row_chars, RowFn&& row) {
  const std::size_t old = out.size();
  out.resize(old + (end - begin) * max_row_chars);
  char* p = out.data() + old;
  for (std::size_t i = begin; i < end; ++i) p = row(p, i);
  out.resize(static_cast<std::size_t>(p - out.data()));
}

/// Formats `rows` rows block by block, in parallel, and hands the text to
/// `sink` in order. At most a few blocks are in memory at once.
template <class Sink, class RowFn>
void emit_rows(Sink&& sink, std::string_view header, std::size_t rows, std::size_t max_row_chars, RowFn&& row) {
  sink(header);
  constexpr std::size_t kBlock = 16384;
  const std::size_t blocks = (rows + kBlock - 1) / kBlock;
  if (blocks <= 1) {
    std::string text;
    format_rows(text, 0, rows, max_row_chars, row);
    sink(std::string_view(text));
    return;
  }
  const std::size_t tokens = 2 * static_cast<std::size_t>(std::max(1, oneapi::tbb::this_task_arena::max_concurrency()));
  // A ring of buffers, one per token: block b uses ring[b % tokens]; the
  // in-order output stage guarantees block b - tokens has been written out.
  std::vector<std::string> ring(tokens);
  std::size_t next_block = 0;
  oneapi::tbb::parallel_pipeline(
      tokens,
      oneapi::tbb::make_filter<void, std::size_t>(oneapi::tbb::filter_mode::serial_in_order,
                                                  [&](oneapi::tbb::flow_control& fc) -> std::size_t {
                                                    if (next_block == blocks) {
                                                      fc.stop();
                                                      return 0;
                                                    }
                                                    return next_block++;
                                                  }) &
          oneapi::tbb::make_filter<std::size_t, std::size_t>(
              oneapi::tbb::filter_mode::parallel,
              [&](std::size_t b) {
                std::string& text = ring[b % tokens];
                text.clear();
                format_rows(text, b * kBlock, std::min(rows, (b + 1) * kBlock), max_row_chars, row);
                return b;
              }) &
          oneapi::tbb::make_filter<std::size_t, void>(oneapi::tbb::filter_mode::serial_in_order, [&](std::size_t b) {
            sink(std::string_view(ring[b % tokens]));
          }));
}

template <class T>
auto body_result_row(const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  return [&inputs, solved](char* p, std::size_t i) {
    using Table = BodyTable<T>;
    for (std::size_t k = 0; k < Table::vx; ++k) {
      p = put_number(p, inputs.column[k][i]);
      *p++ = ',';
    }
    const T out[6] = {solved.v.x[i], solved.v.y[i], solved.v.z[i], solved.w.x[i], solved.w.y[i], solved.w.z[i]};
    for (int k = 0; k < 6; ++k) {
      p = put_number(p, out[k]);
      *p++ = k == 5 ? '\n' : ',';
    }
    return p;
  };
}

template <class T>
auto body_table_row(const BodyColumns<T>& table) {
  return [&table](char* p, std::size_t i) {
    for (std::size_t k = 0; k < 17; ++k) {
      p = put_number(p, table.column[k][i]);
      *p++ = k == 16 ? '\n' : ',';
    }
    return p;
  };
}

template <class T>
auto impulse_row(const ImpulseView<const T>& impulses) {
  return [impulses](char* p, std::size_t i) {
    p = put_number(p, impulses.j.x[i]);
    *p++ = ',';
    p = put_number(p, impulses.j.y[i]);
    *p++ = ',';
    p = put_number(p, impulses.j.z[i]);
    *p++ = '\n';
    return p;
  };
}

/// One contacts.csv row from its ids and its eight values (cx .. mu).
template <class T>
char* put_contact(char* p, BodyIndex a, BodyIndex b, const T* v) {
  p = std::to_chars(p, p + kMaxIdChars, a).ptr;
  *p++ = ',';
  p = std::to_chars(p, p + kMaxIdChars, b).ptr;
  for (int k = 0; k < 8; ++k) {
    *p++ = ',';
    p = put_number(p, v[k]);
  }
  *p++ = '\n';
  return p;
}

template <class T>
auto contact_row(const ContactView<T>& contacts) {
  return [contacts](char* p, std::size_t k) {
    const T v[8] = {contacts.c.x[k],
                    contacts.c.y[k],
                    contacts.c.z[k],
                    contacts.n.x[k],
                    contacts.n.y[k],
                    contacts.n.z[k],
                    contacts.e ? contacts.e[k] : contacts.uniform_e,
                    contacts.mu ? contacts.mu[k] : T(0)};
    return put_contact(p, contacts.a[k], contacts.b[k], v);
  };
}

template <class T>
void check_same_count(const BodyColumns<T>& inputs, const BodyView<const T>& solved, const std::string& file) {
  if (inputs.size() != solved.count) {
    throw SceneError(file, "internal error: " + std::to_string(inputs.size()) + " input bodies but " +
                               std::to_string(solved.count) + " solved bodies");
  }
}

constexpr std::size_t kBodyRowChars = 17 * (kMaxNumberChars + 1);
constexpr std::size_t kImpulseRowChars = 3 * (kMaxNumberChars + 1);
constexpr std::size_t kContactRowChars = 2 * (kMaxIdChars + 1) + 8 * (kMaxNumberChars + 1);

}  // namespace

std::string_view bodies_header() { return "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"; }
std::string_view contacts_header() { return "a,b,cx,cy,cz,nx,ny,nz,e,mu\n"; }
std::string_view impulses_header() { return "jx,jy,jz\n"; }

template <class T>
void write_bodies(OutputFile& out, const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  check_same_count(inputs, solved, out.path());
  emit_rows([&](std::string_view s) { out.write(s); }, bodies_header(), inputs.size(), kBodyRowChars,
            body_result_row(inputs, solved));
}

template <class T>
void write_impulses(OutputFile& out, const ImpulseView<const T>& impulses) {
  emit_rows([&](std::string_view s) { out.write(s); }, impulses_header(), impulses.count, kImpulseRowChars,
            impulse_row(impulses));
}

template <class T>
void write_body_table(OutputFile& out, const BodyColumns<T>& table) {
  emit_rows([&](std::string_view s) { out.write(s); }, bodies_header(), table.size(), kBodyRowChars,
            body_table_row(table));
}

template <class T>
void write_contacts(OutputFile& out, const ContactView<T>& contacts) {
  emit_rows([&](std::string_view s) { out.write(s); }, contacts_header(), contacts.count, kContactRowChars,
            contact_row(contacts));
}

template <class T>
std::string format_body_table(const BodyColumns<T>& table) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, bodies_header(), table.size(), kBodyRowChars,
            body_table_row(table));
  return text;
}

template <class T>
std::string format_contacts(const ContactView<T>& contacts) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, contacts_header(), contacts.count, kContactRowChars,
            contact_row(contacts));
  return text;
}

template <class T>
std::string format_bodies(const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  check_same_count(inputs, solved, "<memory>");
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, bodies_header(), inputs.size(), kBodyRowChars,
            body_result_row(inputs, solved));
  return text;
}

template <class T>
std::string format_impulses(const ImpulseView<const T>& impulses) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, impulses_header(), impulses.count, kImpulseRowChars,
            impulse_row(impulses));
  return text;
}

template <class T>
void append_number(std::string& out, T value) {
  char buf[kMaxNumberChars];
  out.append(buf, put_number(buf, value));
}

template <class T>
void append_body_row(std::string& out, const BodyRecord<T>& body) {
  const T v[17] = {body.m,    body.I[0], body.I[1], body.I[2], body.q[0], body.q[1], body.q[2], body.q[3], body.p[0],
                   body.p[1], body.p[2], body.v[0], body.v[1], body.v[2], body.w[0], body.w[1], body.w[2]};
  for (std::size_t k = 0; k < 17; ++k) {
    append_number(out, v[k]);
    out += k == 16 ? '\n' : ',';
  }
}

template <class T>
void append_contact_row(std::string& out, const ContactRecord<T>& contact) {
  char buf[kContactRowChars];
  const T v[8] = {contact.c[0], contact.c[1], contact.c[2], contact.n[0],
                  contact.n[1], contact.n[2], contact.e,    contact.mu};
  out.append(buf, put_contact(buf, contact.a, contact.b, v));
}

// ---------------------------------------------------------------------------
// Instantiations
// ---------------------------------------------------------------------------
#define COLLIDE_SCENE_IO_INSTANTIATE(T)                                                         \
  template struct BodyTable<T>;                                                                 \
  template BodyTable<T> parse_bodies<T>(std::string_view, std::string_view);                    \
  template BodyTable<T> read_bodies<T>(const std::string&);                                     \
  template BodyBuffer<T> to_body_buffer<T>(const BodyColumns<T>&);                              \
  template bool bodies_ok<T>(const BodyColumns<T>&, std::size_t, std::size_t) noexcept;         \
  template std::optional<RowDefect> first_body_defect<T>(const BodyColumns<T>&);                \
  template void inverses_of<T>(const BodyColumns<T>&, T*, const Vec3Array<T>&);                 \
  template ContactBuffer<T> parse_contacts<T>(std::string_view, std::string_view, std::size_t); \
  template ContactBuffer<T> read_contacts<T>(const std::string&, std::size_t);                  \
  template void write_bodies<T>(OutputFile&, const BodyColumns<T>&, const BodyView<const T>&);  \
  template void write_impulses<T>(OutputFile&, const ImpulseView<const T>&);                    \
  template void write_body_table<T>(OutputFile&, const BodyColumns<T>&);                        \
  template void write_contacts<T>(OutputFile&, const ContactView<T>&);                          \
  template std::string format_body_table<T>(const BodyColumns<T>&);                             \
  template std::string format_contacts<T>(const ContactView<T>&);                               \
  template BodyTable<T> to_body_table<T>(const BodyView<const T>&);                             \
  template std::string format_bodies<T>(const BodyColumns<T>&, const BodyView<const T>&);       \
  template std::string format_impulses<T>(const ImpulseView<const T>&);                         \
  template void append_number<T>(std::string&, T);                                              \
  template void append_body_row<T>(std::string&, const BodyRecord<T>&);                         \
  template void append_contact_row<T>(std::string&, const ContactRecord<T>&);

COLLIDE_SCENE_IO_INSTANTIATE(float)
COLLIDE_SCENE_IO_INSTANTIATE(double)

#undef COLLIDE_SCENE_IO_INSTANTIATE

}  // namespace collide
