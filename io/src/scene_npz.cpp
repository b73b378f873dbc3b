// scene_npz.cpp - the binary scene files (collide/io/scene_npz.hpp).
//
// Design notes
// ------------
// * Loading is: map the archive (npz_read.cpp reads only its directory and
//   the .npy headers), check the members against the table's columns, take
//   each column in place or convert it, then screen every row against the
//   rules in parallel. The screen answers yes or no per chunk; only a scene
//   with a defect is scanned again, row by row on one thread, for the first
//   defect and its message, so the fast path forms no message and the
//   message does not depend on threads.
// * A real column in the other precision is converted as every route
//   converts a scene value (collide/io/scene_values.hpp): '<f4' widened
//   exactly, '<f8' rounded to the nearest float (narrow_column), as the CSV
//   reader stores the double nearest its text. A finite double that
//   overflows float is refused ("value 1e+39 is out of the range of float"),
//   as from CSV, instead of turning a huge mass into an immovable body; the
//   row reported is the CSV reader's (first_body_defect_before).
// * The writers list the columns and hand them to write_npz: a column that
//   lies in a mapping goes from the page cache to the output without a copy
//   of ours.
#include "collide/io/scene_npz.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "collide/io/scene_values.hpp"
#include "collide/rules.hpp"
#include "collide/validate.hpp"
#include "screen_chunks.hpp"

namespace collide {

SceneFormat scene_format_of(std::string_view path) {
  constexpr std::string_view kSuffix = ".npz";
  const bool npz = path.size() >= kSuffix.size() && path.substr(path.size() - kSuffix.size()) == kSuffix;
  return npz ? SceneFormat::npz : SceneFormat::csv;
}

SceneFormat parse_scene_format(std::string_view name) {
  if (name == "csv") return SceneFormat::csv;
  if (name == "npz") return SceneFormat::npz;
  throw std::invalid_argument("scene format must be csv or npz, got '" + std::string(name) + "'");
}

std::string_view to_string(SceneFormat format) { return format == SceneFormat::npz ? "npz" : "csv"; }

namespace {

template <class T>
constexpr NpyType kRealType = std::is_same_v<T, float> ? NpyType::f4 : NpyType::f8;

bool is_real(NpyType t) { return t == NpyType::f4 || t == NpyType::f8; }

[[noreturn]] void member_error(const NpzArchive& archive, std::string_view member, const std::string& reason) {
  throw SceneError(archive.file_name(), 0, SceneError::kNoRow, std::string(member), reason);
}

std::string list_names(const std::string_view* names, std::size_t n) {
  std::string s;
  for (std::size_t k = 0; k < n; ++k) {
    if (k != 0) s += ", ";
    s += names[k];
  }
  return s;
}

/// The members of `archive` for `names`, in that order: each present once,
/// none else, all of one length.
template <std::size_t N>
std::array<const NpzMember*, N> table_members(const NpzArchive& archive, const std::array<std::string_view, N>& names,
                                              std::string_view table) {
  std::array<const NpzMember*, N> found{};
  for (const NpzMember& m : archive.members()) {
    std::size_t k = 0;
    while (k < N && names[k] != m.name) ++k;
    if (k == N) {
      member_error(archive, m.name,
                   "unexpected member: a " + std::string(table) + " file holds " + list_names(names.data(), N));
    }
    found[k] = &m;
  }
  for (std::size_t k = 0; k < N; ++k) {
    if (found[k] == nullptr) {
      member_error(archive, names[k], "missing: the file has no member '" + std::string(names[k]) + ".npy'");
    }
    if (found[k]->count != found[0]->count) {
      member_error(archive, names[k],
                   std::to_string(found[k]->count) + " rows, but '" + std::string(names[0]) + "' has " +
                       std::to_string(found[0]->count));
    }
  }
  return found;
}

/// The first row i of [0, n) for which ok(i) is false, or n. Screened in
/// parallel chunks; only a failed screen is scanned again, row by row on
/// one thread, so the row found does not depend on threads.
template <class Ok>
std::size_t first_failing_row(std::size_t n, const Ok& ok) {
  const bool all = detail::screen_chunks(n, [&](std::size_t i0, std::size_t i1) {
    bool good = true;
    for (std::size_t i = i0; i < i1; ++i) good &= ok(i);
    return good;
  });
  if (all) return n;
  std::size_t i = 0;
  while (i < n && ok(i)) ++i;
  return i;
}

template <class From, class T>
void convert_into(const std::byte* data, std::size_t n, T* out) {
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, n, std::size_t{1} << 16),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                From x;
                                std::memcpy(&x, data + i * sizeof(From), sizeof(From));
                                out[i] = static_cast<T>(x);
                              }
                            });
}

/// Column `m` in precision T: the member's own bytes when it holds T and is
/// aligned for T, else a converted copy in `owned`. Refuses a dtype that is
/// not a real one. `out_of_range` receives the first row whose double does
/// not fit T (narrow_column), or the count.
template <class T>
const T* real_column(const NpzArchive& archive, const NpzMember& m, NpyType precision, std::vector<T>& owned,
                     bool& in_place, std::size_t& out_of_range) {
  out_of_range = m.count;
  if (!is_real(m.type)) {
    member_error(archive, m.name,
                 "dtype " + std::string(npy_descr(m.type)) + ": real columns are '<f4' (float) or '<f8' (double)");
  }
  if (m.type != precision) {
    member_error(archive, m.name,
                 "dtype " + std::string(npy_descr(m.type)) + ", but the file's other real columns are " +
                     std::string(npy_descr(precision)) + ": a scene file has one precision");
  }
  if (m.type == kRealType<T> && reinterpret_cast<std::uintptr_t>(m.data) % alignof(T) == 0) {
    in_place = true;
    return reinterpret_cast<const T*>(m.data);
  }
  owned.resize(m.count);
  if (m.type == NpyType::f4) {
    convert_into<float>(m.data, m.count, owned.data());  // exact: a float is its own scene value
  } else {
    out_of_range = narrow_column(m.data, m.count, owned.data());
  }
  return owned.data();
}

/// Element `row` of an '<f8' member.
double stored_double(const NpzMember& m, std::size_t row) {
  double x;
  std::memcpy(&x, m.data + row * sizeof(double), sizeof(double));
  return x;
}

/// Keeps in `range` the first value out of T's range over the columns
/// visited in order (the least row, and in it the first column): `row` is
/// real_column's for member `m`, the table's column `column`.
template <class T>
void keep_first_out_of_range(std::optional<RowDefect>& range, const NpzMember& m, std::string_view column,
                             std::size_t row) {
  if (row < m.count && (!range || row < range->row)) {
    range = RowDefect{row, Defect{column, out_of_range_reason<T>(stored_double(m, row))}};
  }
}

/// An id column as BodyIndex: in place for aligned '<u4', else converted,
/// each id checked to fit (negative or too large: out of range).
const BodyIndex* index_column(const NpzArchive& archive, const NpzMember& m, std::size_t body_count,
                              std::vector<BodyIndex>& owned, bool& in_place) {
  if (m.type == NpyType::u4) {
    if (reinterpret_cast<std::uintptr_t>(m.data) % alignof(BodyIndex) == 0) {
      in_place = true;
      return reinterpret_cast<const BodyIndex*>(m.data);
    }
    owned.resize(m.count);
    std::memcpy(owned.data(), m.data, m.count * sizeof(BodyIndex));
    return owned.data();
  }
  if (is_real(m.type)) {
    member_error(archive, m.name,
                 "dtype " + std::string(npy_descr(m.type)) + ": body ids are integers ('<u4', or '<i4', '<u8', '<i8')");
  }
  owned.resize(m.count);
  const std::size_t size = npy_type_size(m.type);
  const bool is_signed = m.type == NpyType::i4 || m.type == NpyType::i8;
  // The id as a signed 128-bit-free pair: negative flag and magnitude.
  const auto read = [&](std::size_t i, bool& negative) -> std::uint64_t {
    const std::byte* p = m.data + i * size;
    if (size == 4) {
      std::uint32_t u;
      std::memcpy(&u, p, 4);
      negative = is_signed && static_cast<std::int32_t>(u) < 0;
      return negative ? static_cast<std::uint64_t>(-static_cast<std::int64_t>(static_cast<std::int32_t>(u))) : u;
    }
    std::uint64_t u;
    std::memcpy(&u, p, 8);
    negative = is_signed && static_cast<std::int64_t>(u) < 0;
    return negative ? ~u + 1 : u;
  };
  const std::size_t bad = first_failing_row(m.count, [&](std::size_t i) {
    bool negative = false;
    const std::uint64_t id = read(i, negative);
    owned[i] = static_cast<BodyIndex>(id);
    return !negative && id <= std::numeric_limits<BodyIndex>::max();
  });
  if (bad < m.count) {
    bool negative = false;
    std::string text = std::to_string(read(bad, negative));
    if (negative) text.insert(text.begin(), '-');
    const std::string reason =
        negative ? "body id must be a non-negative integer, got " + text : body_id_out_of_range(text, body_count);
    throw SceneError(archive.file_name(), 0, bad, m.name, reason);
  }
  return owned.data();
}

}  // namespace

NpyType npz_scene_precision(const NpzArchive& archive) {
  const NpzMember* first = nullptr;
  for (const NpzMember& m : archive.members()) {
    if (!is_real(m.type)) continue;
    if (first == nullptr) {
      first = &m;
    } else if (m.type != first->type) {
      member_error(archive, m.name,
                   "dtype " + std::string(npy_descr(m.type)) + ", but '" + first->name + "' is " +
                       std::string(npy_descr(first->type)) + ": a scene file has one precision");
    }
  }
  if (first == nullptr) throw SceneError(archive.file_name(), "no real ('<f4' or '<f8') member: not a scene file");
  return first->type;
}

template <class T>
void LoadedBodies<T>::check() const {
  if (checked_) return;
  if (const std::optional<RowDefect> bad = first_body_defect(columns_)) {
    throw SceneError(archive_ ? archive_->file_name() : std::string(), 0, bad->row, std::string(bad->defect.column),
                     bad->defect.reason);
  }
}

template <class T>
void LoadedBodies<T>::fill_solve_arrays(T* inv_mass, const Vec3Array<T>& inv_inertia, const Vec3Array<T>& v,
                                        const Vec3Array<T>& w) const {
  if (!screened_solve_arrays(columns_, inv_mass, inv_inertia, v, w)) check();
}

template <class T>
LoadedBodies<T> load_bodies(const std::string& path, SceneFormat format, BodyRules rules) {
  LoadedBodies<T> out;
  if (format == SceneFormat::csv) {
    out.table_ = read_bodies<T>(path);  // every row checked as it is parsed
    out.columns_ = columns_of(out.table_);
    out.checked_ = true;
    return out;
  }
  out.archive_ = std::make_unique<NpzArchive>(NpzArchive::map(path));
  const NpzArchive& archive = *out.archive_;
  const auto members = table_members(archive, kBodyColumns, "bodies");
  const NpyType precision = npz_scene_precision(archive);
  const std::size_t n = members[0]->count;
  out.columns_.count = n;
  std::optional<RowDefect> range;
  for (std::size_t k = 0; k < kBodyColumns.size(); ++k) {
    bool in_place = false;
    std::size_t out_of_range = n;
    out.columns_.column[k] =
        real_column<T>(archive, *members[k], precision, out.table_.column[k], in_place, out_of_range);
    out.mapped_ |= in_place;
    keep_first_out_of_range<T>(range, *members[k], kBodyColumns[k], out_of_range);
  }
  if (range) {
    const RowDefect bad = first_body_defect_before(out.columns_, std::move(*range));
    throw SceneError(archive.file_name(), 0, bad.row, std::string(bad.defect.column), bad.defect.reason);
  }
  if (rules == BodyRules::checked) {
    out.check();
    out.checked_ = true;
  }
  return out;
}

template <class T>
BodyView<T> SolveBodies<T>::point_at(const BodyColumns<T>& columns) {
  for (std::size_t k = 0; k < read_.size(); ++k) read_[k] = columns.column[4 + k];
  return view();
}

template <class T>
SolveBodies<T>::SolveBodies(const BodyColumns<T>& columns)
    : count_(columns.count), own_(detail::allocate_large_array<T>(10 * columns.count)) {
  const BodyView<T> v = point_at(columns);
  if (!screened_solve_arrays(columns, v.inv_mass, v.inv_inertia, v.v, v.w)) {
    const std::optional<RowDefect> bad = first_body_defect(columns);
    throw std::invalid_argument("SolveBodies: row " + std::to_string(bad ? bad->row : 0) + ", column '" +
                                std::string(bad ? bad->defect.column : "?") +
                                "': " + (bad ? bad->defect.reason : std::string("breaks a rule")));
  }
}

template <class T>
SolveBodies<T>::SolveBodies(const LoadedBodies<T>& loaded)
    : count_(loaded.size()), own_(detail::allocate_large_array<T>(10 * loaded.size())) {
  const BodyView<T> v = point_at(loaded.columns());
  loaded.fill_solve_arrays(v.inv_mass, v.inv_inertia, v.v, v.w);
}

template <class T>
BodyView<T> SolveBodies<T>::view() {
  T* o = own_.get();
  const std::size_t n = count_;
  // The kernels read q and p and write only v and w (BodyView): the const
  // is taken off for the view's type, never for a write.
  const auto read = [this](std::size_t k) { return const_cast<T*>(read_[k]); };
  return {n,
          o,
          {o + n, o + 2 * n, o + 3 * n},
          {read(0), read(1), read(2), read(3)},
          {read(4), read(5), read(6)},
          {o + 4 * n, o + 5 * n, o + 6 * n},
          {o + 7 * n, o + 8 * n, o + 9 * n}};
}

template <class T>
BodyView<const T> SolveBodies<T>::view() const {
  return const_view(const_cast<SolveBodies*>(this)->view());
}

template <class T>
LoadedContacts<T> load_contacts(const std::string& path, SceneFormat format, std::size_t body_count) {
  LoadedContacts<T> out;
  if (format == SceneFormat::csv) {
    out.buffer_ = read_contacts<T>(path, body_count);
    out.view_ = out.buffer_.view();
    return out;
  }
  out.archive_ = std::make_unique<NpzArchive>(NpzArchive::map(path));
  const NpzArchive& archive = *out.archive_;
  const auto members = table_members(archive, kContactColumns, "contacts");
  const NpyType precision = npz_scene_precision(archive);
  const std::size_t n = members[0]->count;
  ContactView<T> v;
  v.count = n;
  bool in_place = false;
  v.a = index_column(archive, *members[0], body_count, out.owned_a_, in_place);
  out.mapped_ |= in_place;
  v.b = index_column(archive, *members[1], body_count, out.owned_b_, in_place);
  out.mapped_ |= in_place;
  out.owned_.resize(kContactColumns.size());
  const T* real[8];
  std::optional<RowDefect> range;
  for (std::size_t k = 2; k < kContactColumns.size(); ++k) {
    in_place = false;
    std::size_t out_of_range = n;
    real[k - 2] = real_column<T>(archive, *members[k], precision, out.owned_[k], in_place, out_of_range);
    out.mapped_ |= in_place;
    keep_first_out_of_range<T>(range, *members[k], kContactColumns[k], out_of_range);
  }
  v.c = {real[0], real[1], real[2]};
  v.n = {real[3], real[4], real[5]};
  v.e = real[6];
  v.mu = real[7];
  const auto record = [&v](std::size_t i) {
    ContactRecord<T> r;
    r.a = v.a[i];
    r.b = v.b[i];
    r.c[0] = v.c.x[i];
    r.c[1] = v.c.y[i];
    r.c[2] = v.c.z[i];
    r.n[0] = v.n.x[i];
    r.n[1] = v.n.y[i];
    r.n[2] = v.n.z[i];
    r.e = v.e[i];
    r.mu = v.mu[i];
    return r;
  };
  // The lane layer's screen first (validate.hpp); only a scene it does not
  // clear is judged row by row, exactly. With a value out of T's range, the
  // rows before it are judged, as the CSV reader meets them first.
  const std::size_t limit = range ? range->row : n;
  const std::size_t bad =
      !range && contacts_pass_screen(v, body_count)
          ? n
          : first_failing_row(limit, [&](std::size_t i) { return contact_ok(record(i), body_count); });
  if (bad < limit) {
    const auto defect = contact_defect(record(bad), body_count);  // contact_ok's verdict, with its reason
    throw SceneError(archive.file_name(), 0, bad, std::string(defect->column), defect->reason);
  }
  if (range) {
    throw SceneError(archive.file_name(), 0, range->row, std::string(range->defect.column), range->defect.reason);
  }
  // As ContactBuffer::view(): a scene without friction runs the frictionless
  // kernel.
  const bool friction = first_failing_row(n, [&](std::size_t i) { return v.mu[i] == T(0); }) < n;
  if (!friction) v.mu = nullptr;
  out.view_ = v;
  return out;
}

template <class T>
ImpulseBuffer<T> load_impulses(const std::string& path, SceneFormat format) {
  if (format == SceneFormat::csv) return read_impulses<T>(path);
  const NpzArchive archive = NpzArchive::map(path);
  const auto members = table_members(archive, kImpulseColumns, "impulses");
  const NpyType precision = npz_scene_precision(archive);
  ImpulseBuffer<T> out(members[0]->count);
  const ImpulseView<T> j = out.view();
  T* const into[3] = {j.j.x, j.j.y, j.j.z};
  std::optional<RowDefect> range;
  for (std::size_t k = 0; k < kImpulseColumns.size(); ++k) {
    std::vector<T> owned;
    bool in_place = false;
    std::size_t out_of_range = j.count;
    const T* column = real_column<T>(archive, *members[k], precision, owned, in_place, out_of_range);
    keep_first_out_of_range<T>(range, *members[k], kImpulseColumns[k], out_of_range);
    std::copy(column, column + j.count, into[k]);
  }
  // An impulse beyond T's range, as a scene value would be: refused at its row.
  if (range) {
    throw SceneError(archive.file_name(), 0, range->row, std::string(range->defect.column), range->defect.reason);
  }
  return out;
}

// ---------------------------------------------------------------------------
// Writers
// ---------------------------------------------------------------------------

template <class T>
void write_bodies_npz(OutputFile& out, const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  if (inputs.count != solved.count) {
    throw SceneError(out.path(), "internal error: " + std::to_string(inputs.count) + " input bodies but " +
                                     std::to_string(solved.count) + " solved bodies");
  }
  std::vector<NpzColumn> columns;
  const T* const solved_columns[6] = {solved.v.x, solved.v.y, solved.v.z, solved.w.x, solved.w.y, solved.w.z};
  for (std::size_t k = 0; k < kBodyColumns.size(); ++k) {
    const T* data = k < 11 ? inputs.column[k] : solved_columns[k - 11];
    columns.push_back({kBodyColumns[k], kRealType<T>, data, inputs.count});
  }
  write_npz(out, columns);
}

template <class T>
void write_impulses_npz(OutputFile& out, const ImpulseView<const T>& impulses) {
  write_npz(out, {{kImpulseColumns[0], kRealType<T>, impulses.j.x, impulses.count},
                  {kImpulseColumns[1], kRealType<T>, impulses.j.y, impulses.count},
                  {kImpulseColumns[2], kRealType<T>, impulses.j.z, impulses.count}});
}

template <class T>
void write_body_table_npz(OutputFile& out, const BodyColumns<T>& table) {
  std::vector<NpzColumn> columns;
  for (std::size_t k = 0; k < kBodyColumns.size(); ++k) {
    columns.push_back({kBodyColumns[k], kRealType<T>, table.column[k], table.count});
  }
  write_npz(out, columns);
}

template <class T>
void write_contacts_npz(OutputFile& out, const ContactView<T>& contacts) {
  const std::size_t n = contacts.count;
  std::vector<T> e_fill, mu_fill;
  const T* e = contacts.e;
  const T* mu = contacts.mu;
  if (e == nullptr) {
    e_fill.assign(n, contacts.uniform_e);
    e = e_fill.data();
  }
  if (mu == nullptr) {
    mu_fill.assign(n, T(0));
    mu = mu_fill.data();
  }
  const NpyType t = kRealType<T>;
  write_npz(out, {{"a", NpyType::u4, contacts.a, n},
                  {"b", NpyType::u4, contacts.b, n},
                  {"cx", t, contacts.c.x, n},
                  {"cy", t, contacts.c.y, n},
                  {"cz", t, contacts.c.z, n},
                  {"nx", t, contacts.n.x, n},
                  {"ny", t, contacts.n.y, n},
                  {"nz", t, contacts.n.z, n},
                  {"e", t, e, n},
                  {"mu", t, mu, n}});
}

template <class T>
void write_body_table(OutputFile& out, SceneFormat format, const BodyColumns<T>& table) {
  if (format == SceneFormat::npz) {
    write_body_table_npz(out, table);
  } else {
    write_body_table(out, table);
  }
}

template <class T>
void write_contacts(OutputFile& out, SceneFormat format, const ContactView<T>& contacts) {
  if (format == SceneFormat::npz) {
    write_contacts_npz(out, contacts);
  } else {
    write_contacts(out, contacts);
  }
}

template <class T>
void write_impulses(OutputFile& out, SceneFormat format, const ImpulseView<const T>& impulses) {
  if (format == SceneFormat::npz) {
    write_impulses_npz(out, impulses);
  } else {
    write_impulses(out, impulses);
  }
}

#define COLLIDE_SCENE_NPZ_INSTANTIATE(T)                                                           \
  template class LoadedBodies<T>;                                                                  \
  template class LoadedContacts<T>;                                                                \
  template class SolveBodies<T>;                                                                   \
  template LoadedBodies<T> load_bodies<T>(const std::string&, SceneFormat, BodyRules);             \
  template LoadedContacts<T> load_contacts<T>(const std::string&, SceneFormat, std::size_t);       \
  template void write_bodies_npz<T>(OutputFile&, const BodyColumns<T>&, const BodyView<const T>&); \
  template void write_impulses_npz<T>(OutputFile&, const ImpulseView<const T>&);                   \
  template void write_body_table_npz<T>(OutputFile&, const BodyColumns<T>&);                       \
  template void write_contacts_npz<T>(OutputFile&, const ContactView<T>&);                         \
  template void write_body_table<T>(OutputFile&, SceneFormat, const BodyColumns<T>&);              \
  template void write_contacts<T>(OutputFile&, SceneFormat, const ContactView<T>&);                \
  template ImpulseBuffer<T> load_impulses<T>(const std::string&, SceneFormat);                     \
  template void write_impulses<T>(OutputFile&, SceneFormat, const ImpulseView<const T>&);

COLLIDE_SCENE_NPZ_INSTANTIATE(float)
COLLIDE_SCENE_NPZ_INSTANTIATE(double)

#undef COLLIDE_SCENE_NPZ_INSTANTIATE

}  // namespace collide
