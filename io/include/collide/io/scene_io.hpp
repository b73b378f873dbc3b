// collide/io/scene_io.hpp - reading and writing the scene CSV files of
// docs/collision-law.md.
//
// Design notes
// ------------
// * Reading keeps two layers apart. `read_bodies` returns a BodyTable: the
//   seventeen columns exactly as parsed, in the precision T the kernel runs
//   in (inf kept for m and I, q not normalised). The solver needs inverse
//   masses and unit quaternions (`to_body_buffer`), but the result file must
//   copy every column other than v and w unchanged, so the writer takes the
//   table and the solved velocities.
// * Every bad input docs/collision-law.md lists ("Bad input") is a SceneError
//   whose message names the file, the 1-based line, the 0-based data row (the
//   body or contact id) and the column:
//   "bodies.csv:5: row 3, column 'm': mass must be > 0, got -1".
//   What the text itself gets wrong (not a number, an empty field, a missing
//   or extra column, a number beyond the range of double) is the reader's to
//   say; each number is the double nearest its text, stored in T as every
//   route stores a scene value (collide/io/scene_values.hpp: a double with
//   no value in T is refused with the reason every route gives). A row whose
//   every field parses is then checked with the rules of collide/rules.hpp,
//   on the T values, and the reason is theirs, the same text the buffers and
//   the Python constructors give for the same value. So a value that is fine
//   in double but unusable in float (1e39, a mass of 1e-45, a quaternion too
//   small to normalise) is rejected with the precision named. A row with
//   both kinds of defect reports the text one.
// * The parse-from-memory entry points (`parse_bodies`, `parse_contacts`)
//   take the text and a file name for the messages, so fuzzers and tests can
//   drive the parser without files.
// * Speed: the file is mapped, split at line boundaries into chunks that are
//   parsed in parallel (tbb) with std::from_chars; the first error in file
//   order wins, so messages do not depend on threads.
//   Writing formats blocks of rows in parallel with std::to_chars (shortest
//   round trip: the text reads back to the same T) and writes them in order.
// * Outputs go through OutputFile (collide/io/output_file.hpp): a temporary
//   renamed over a regular destination by commit(), or a device, FIFO or
//   stdout written directly.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <array>
#include <cstddef>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/output_file.hpp"
#include "collide/rules.hpp"

namespace collide {

// kBodyColumns, kContactColumns (the columns of bodies.csv and contacts.csv)
// and kNormalTolerance come from collide/rules.hpp.

/// Columns of the impulses file.
inline constexpr std::array<std::string_view, 3> kImpulseColumns = {"jx", "jy", "jz"};

/// A scene file that cannot be read or written. For a bad value, line() is
/// the 1-based line, row() the 0-based data row (body or contact id) and
/// column() the column name; for a bad header row() is kNoRow; for an error
/// about the whole file (cannot open, cannot write) line() is 0 and column()
/// is empty.
class SceneError : public std::runtime_error {
 public:
  static constexpr std::size_t kNoRow = static_cast<std::size_t>(-1);

  SceneError(std::string file, std::size_t line, std::size_t row, std::string column, std::string reason);
  /// An error about the whole file.
  SceneError(std::string file, std::string reason);
  /// An error of the operating system about the whole file (cannot open,
  /// read or write it): `os_error` is its errno value.
  SceneError(std::string file, std::string reason, int os_error);

  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  [[nodiscard]] std::size_t row() const noexcept { return row_; }
  [[nodiscard]] const std::string& column() const noexcept { return column_; }
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }
  /// The errno value of an operating-system error (the file is missing,
  /// unreadable, a directory...); 0 when the problem is the file's content.
  [[nodiscard]] int os_error() const noexcept { return os_error_; }

 private:
  std::string file_;
  std::size_t line_ = 0;
  std::size_t row_ = kNoRow;
  std::string column_;
  std::string reason_;
  int os_error_ = 0;
};

/// The columns of bodies.csv exactly as parsed: column[k][i] is column
/// kBodyColumns[k] of body i. m and I may be inf; q is as written.
template <class T>
struct BodyTable {
  enum Column : std::size_t { m, Ix, Iy, Iz, qw, qx, qy, qz, px, py, pz, vx, vy, vz, wx, wy, wz, kCount };
  std::array<std::vector<T>, kCount> column;

  [[nodiscard]] std::size_t size() const { return column[0].size(); }
  void resize(std::size_t n) {
    for (auto& c : column) c.resize(n);
  }
  /// Body i in physical units, as written in the file.
  [[nodiscard]] BodyRecord<T> record(std::size_t i) const;
  /// Appends a body in physical units (no checks).
  void push_back(const BodyRecord<T>& body);
};

/// The seventeen columns of a bodies file wherever they are held (a
/// BodyTable, a mapped binary file): column[k] points at `count` values of
/// column kBodyColumns[k], in physical units as written.
template <class T>
struct BodyColumns {
  std::size_t count = 0;
  std::array<const T*, kBodyColumns.size()> column{};

  [[nodiscard]] std::size_t size() const { return count; }

  /// Body i in physical units, as written.
  [[nodiscard]] BodyRecord<T> record(std::size_t i) const {
    BodyRecord<T> r;
    r.m = column[0][i];
    for (int k = 0; k < 3; ++k) r.I[k] = column[1 + k][i];
    for (int k = 0; k < 4; ++k) r.q[k] = column[4 + k][i];
    for (int k = 0; k < 3; ++k) {
      r.p[k] = column[8 + k][i];
      r.v[k] = column[11 + k][i];
      r.w[k] = column[14 + k][i];
    }
    return r;
  }
};

/// Whether bodies [i0, i1) of `columns` all obey the rules: body_ok's
/// verdict for every one, formed column by column (loops the compiler
/// vectorises) instead of body by body. No message: body_defect names the
/// defect of a body.
template <class T>
bool bodies_ok(const BodyColumns<T>& columns, std::size_t i0, std::size_t i1) noexcept;

/// The defect of one row of a table: the 0-based row, and the column and
/// reason of the rule it breaks (collide/rules.hpp).
struct RowDefect {
  std::size_t row = 0;
  Defect defect;
};

/// The first body of `columns` that breaks a rule, with body_defect's
/// column and reason, or nothing. bodies_ok screens every body in parallel
/// chunks; only a failed screen is scanned, body by body in order, so the
/// body named does not depend on threads. What the binary scene loader, the
/// CSV tables' to_body_buffer and the Python module's from_physical check
/// columns in physical units with.
template <class T>
std::optional<RowDefect> first_body_defect(const BodyColumns<T>& columns);

/// A table's columns as BodyColumns (valid while the table lives unchanged).
template <class T>
BodyColumns<T> columns_of(const BodyTable<T>& table) {
  BodyColumns<T> c;
  c.count = table.size();
  for (std::size_t k = 0; k < c.column.size(); ++k) c.column[k] = table.column[k].data();
  return c;
}

// ---------------------------------------------------------------------------
// Reading. All readers throw SceneError on the first bad input in file order.
// ---------------------------------------------------------------------------

/// Parses the text of a bodies file. `file_name` only labels messages.
template <class T>
BodyTable<T> parse_bodies(std::string_view text, std::string_view file_name);
/// Reads and parses a bodies file.
template <class T>
BodyTable<T> read_bodies(const std::string& path);

/// Converts a table into what the kernels consume (1/m, 1/I, unit q),
/// through BodyBuffer::set (std::invalid_argument for a body that breaks a
/// rule; a table from parse_bodies has none).
template <class T>
BodyBuffer<T> to_body_buffer(const BodyColumns<T>& table);
template <class T>
BodyBuffer<T> to_body_buffer(const BodyTable<T>& table) {
  return to_body_buffer(columns_of(table));
}
/// The inverses the kernels take, from columns that obey the rules:
/// inv_mass = 1/m and inv_inertia = 1/I, 0 for inf and every inverse
/// moment of an immovable body 0, as BodyBuffer::set stores them; rows in
/// parallel. No rule is checked (to_body_buffer checks them).
template <class T>
void inverses_of(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia);
/// The arrays a solve of `columns` writes, and the rules, in one read of the
/// columns: chunk by chunk, bodies_ok's verdict and, while the chunk is in
/// cache, 1/m and 1/I as inverses_of stores them and v, w copied. False when
/// some body breaks a rule: the outputs are then unspecified, and
/// first_body_defect names the body. Rows in parallel.
template <class T>
bool screened_solve_arrays(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia,
                           const Vec3Array<T>& v, const Vec3Array<T>& w);
/// The other way: a kernel view in physical units (1/x, inf for 0), what
/// write_body_table writes as a scene file.
template <class T>
BodyTable<T> to_body_table(const BodyView<const T>& bodies);

/// Parses the text of a contacts file whose ids refer to `body_count` bodies.
/// |n| is checked against 1 within kNormalTolerance before n is normalised.
template <class T>
ContactBuffer<T> parse_contacts(std::string_view text, std::string_view file_name, std::size_t body_count);
/// Reads and parses a contacts file.
template <class T>
ContactBuffer<T> read_contacts(const std::string& path, std::size_t body_count);

/// Parses the text of an impulses file (header jx,jy,jz), as `collide solve`
/// writes it: any value of T, NaN and inf included (no rule applies to a
/// result).
template <class T>
ImpulseBuffer<T> parse_impulses(std::string_view text, std::string_view file_name);
/// Reads and parses an impulses file.
template <class T>
ImpulseBuffer<T> read_impulses(const std::string& path);

/// Reads a whole file into memory (also used by the CLI to compare files).
std::string read_file(const std::string& path);

// ---------------------------------------------------------------------------
// Writing.
// ---------------------------------------------------------------------------

/// Writes the result bodies file: every column of `inputs` except v and w,
/// which come from `solved` (same body count). Use std::as_const(buffer).view().
template <class T>
void write_bodies(OutputFile& out, const BodyColumns<T>& inputs, const BodyView<const T>& solved);
template <class T>
void write_bodies(OutputFile& out, const BodyTable<T>& inputs, const BodyView<const T>& solved) {
  write_bodies(out, columns_of(inputs), solved);
}
/// Writes the impulses file (header jx,jy,jz).
template <class T>
void write_impulses(OutputFile& out, const ImpulseView<const T>& impulses);
/// Writes a body table as it is (a scene input file).
template <class T>
void write_body_table(OutputFile& out, const BodyColumns<T>& table);
template <class T>
void write_body_table(OutputFile& out, const BodyTable<T>& table) {
  write_body_table(out, columns_of(table));
}
/// Writes contacts as a contacts file (a scene input file), values as given;
/// a view without e gets uniform_e in every row, one without mu gets 0.
template <class T>
void write_contacts(OutputFile& out, const ContactView<T>& contacts);

/// In-memory forms of the writers above: the complete file text.
template <class T>
std::string format_bodies(const BodyColumns<T>& inputs, const BodyView<const T>& solved);
template <class T>
std::string format_bodies(const BodyTable<T>& inputs, const BodyView<const T>& solved) {
  return format_bodies(columns_of(inputs), solved);
}
template <class T>
std::string format_impulses(const ImpulseView<const T>& impulses);
template <class T>
std::string format_body_table(const BodyColumns<T>& table);
template <class T>
std::string format_body_table(const BodyTable<T>& table) {
  return format_body_table(columns_of(table));
}
template <class T>
std::string format_contacts(const ContactView<T>& contacts);

/// Header lines, newline included.
std::string_view bodies_header();
std::string_view contacts_header();
std::string_view impulses_header();

/// Appends one number in shortest round-trip form ("inf" for infinity): the
/// shortest text that the readers read back to the same T (one float needs
/// a digit more than its shortest text, csv_fields.hpp).
template <class T>
void append_number(std::string& out, T value);
/// Appends one bodies.csv row (newline included), values as given.
template <class T>
void append_body_row(std::string& out, const BodyRecord<T>& body);
/// Appends one contacts.csv row (newline included), values as given.
template <class T>
void append_contact_row(std::string& out, const ContactRecord<T>& contact);

}  // namespace collide
