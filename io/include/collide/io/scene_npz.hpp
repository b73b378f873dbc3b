// collide/io/scene_npz.hpp - the binary scene files: bodies, contacts and
// impulses as uncompressed NumPy .npz archives, mapped in place.
//
// Design notes
// ------------
// * One archive per table, as the CSV format has one file per table: a
//   bodies file holds the members m, Ix, ..., wz (kBodyColumns), a contacts
//   file a, b, cx, ..., mu (kContactColumns), an impulses file jx, jy, jz;
//   each member a 1-D array of one value per row, in the units and with
//   the meaning of the CSV column of the same name (docs/collision-law.md,
//   "Binary scene files"). NumPy reads them with np.load and writes them
//   with np.savez; no other tool is needed.
// * Why one .npz and not a directory of .npy files: a table stays one file,
//   as it is in CSV, to name on a command line, copy or hand over; NumPy has
//   a call for each direction; and a stored (uncompressed) member is a
//   contiguous run of the file, so mapping the archive maps every column
//   (collide/io/npz.hpp). The directory would map the same way but scatter a
//   scene over 30 files.
// * A file has one precision: every real column '<f4' (float) or every one
//   '<f8' (double); ids '<u4' (other integer dtypes, as np.savez writes
//   Python ints, are accepted and converted, each id checked). Loaded in
//   the file's own precision and aligned (as write_npz always aligns), a
//   column is used where it lies in the mapping: no copy, no parse. In the
//   other precision, or misaligned (an archive from np.savez), it is
//   converted into memory first.
// * The rules are the CSV files' (collide/rules.hpp), checked on every row
//   in parallel; the first defect in row order is a SceneError naming the
//   file, the row and the column: "bodies.npz: row 3, column 'm': mass must
//   be > 0, got -1". A member missing, extra, of the wrong dtype or length
//   is named the same way, without a row.
// * Writers go through OutputFile like the CSV writers: all or nothing for a
//   regular file, direct for stdout, devices and FIFOs. They write the same
//   bytes for the same values, so a scene converted to CSV and back is the
//   same file (shortest round-trip text both ways).
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/npz.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/large_allocator.hpp"

namespace collide {

/// How a scene file is stored.
enum class SceneFormat { csv, npz };

/// The format a path names: npz for a name ending in ".npz", else csv.
SceneFormat scene_format_of(std::string_view path);
/// "csv" or "npz"; std::invalid_argument for anything else.
SceneFormat parse_scene_format(std::string_view name);
std::string_view to_string(SceneFormat format);

/// The precision of a binary scene file: f4 or f8, from its real columns
/// (SceneError if they disagree, or if it has none).
NpyType npz_scene_precision(const NpzArchive& archive);

/// Whether load_bodies checks the rules of every body (`checked`), or leaves
/// that to its caller (`by_caller`), who must call LoadedBodies::check() or
/// LoadedBodies::fill_solve_arrays() (SolveBodies' constructor from a loaded
/// file calls it) before using a value: a caller that reads every column
/// anyway checks them in the same pass. A CSV file is checked as it is parsed either way.
enum class BodyRules { checked, by_caller };

/// A bodies file of either format, loaded for a solve in precision T: its
/// seventeen columns (columns()), in the mapping where they can stay there.
/// Movable, not copyable; columns() dies with it.
template <class T>
class LoadedBodies {
 public:
  /// Throws the SceneError of the first body that breaks a rule (the file,
  /// the row, the column and the reason); returns when none does.
  void check() const;
  /// The arrays a solve writes, size() values each (1/m, 1/I, and v and w
  /// copied), filled in the pass that checks the rules
  /// (screened_solve_arrays): check()'s SceneError for a body that breaks
  /// one. What a caller of a `by_caller` load that reads every column calls
  /// instead of check().
  void fill_solve_arrays(T* inv_mass, const Vec3Array<T>& inv_inertia, const Vec3Array<T>& v,
                         const Vec3Array<T>& w) const;
  [[nodiscard]] const BodyColumns<T>& columns() const { return columns_; }
  [[nodiscard]] std::size_t size() const { return columns_.count; }
  /// True when at least one column is used in place, in the file's mapping.
  [[nodiscard]] bool mapped() const { return mapped_; }
  /// The mapped file's bytes (empty for CSV): where in-place columns lie.
  [[nodiscard]] std::string_view mapped_bytes() const { return archive_ ? archive_->bytes() : std::string_view(); }

 private:
  template <class U>
  friend LoadedBodies<U> load_bodies(const std::string& path, SceneFormat format, BodyRules rules);
  BodyTable<T> table_;                   // CSV rows, or converted binary columns
  std::unique_ptr<NpzArchive> archive_;  // binary: the mapped file
  BodyColumns<T> columns_;
  bool mapped_ = false;
  bool checked_ = false;  // every body known to obey the rules
};

/// A contacts file of either format, loaded for a solve in precision T; its
/// view() points into the mapping where the columns can stay there. As
/// ContactBuffer::view(), mu is null when every mu is 0.
template <class T>
class LoadedContacts {
 public:
  [[nodiscard]] const ContactView<T>& view() const { return view_; }
  [[nodiscard]] std::size_t size() const { return view_.count; }
  [[nodiscard]] bool mapped() const { return mapped_; }
  [[nodiscard]] std::string_view mapped_bytes() const { return archive_ ? archive_->bytes() : std::string_view(); }

 private:
  template <class U>
  friend LoadedContacts<U> load_contacts(const std::string& path, SceneFormat format, std::size_t body_count);
  ContactBuffer<T> buffer_;            // CSV rows
  std::vector<std::vector<T>> owned_;  // binary: converted real columns
  std::vector<BodyIndex> owned_a_, owned_b_;
  std::unique_ptr<NpzArchive> archive_;  // binary: the mapped file
  ContactView<T> view_;
  bool mapped_ = false;
};

/// The bodies of a solve over columns in physical units (a loaded file's):
/// q and p are read where the columns hold them (a mapped file's pages, a
/// table) and never copied; 1/m and 1/I (inverses_of) and v and w, which the
/// solve writes, live in arrays of its own, allocated without being cleared
/// first, in 2 MiB pages where the system gives them (first touch faults
/// once per 2 MiB; docs/decisions/0002-binary-scene-files.md), and filled
/// in the pass that checks the rules (screened_solve_arrays). view() is
/// valid while the columns are. Not copyable; movable.
template <class T>
class SolveBodies {
 public:
  /// std::invalid_argument naming the first row that breaks a rule.
  explicit SolveBodies(const BodyColumns<T>& columns);
  /// The same from a loaded file, checking its rules in the pass that fills
  /// the arrays (screened_solve_arrays) where load_bodies left them to the
  /// caller: the SceneError of LoadedBodies::check() for a body that breaks
  /// one.
  explicit SolveBodies(const LoadedBodies<T>& loaded);
  /// For the solver: q and p must not be written through it (the kernels
  /// only read them; a mapped file's pages are read-only).
  [[nodiscard]] BodyView<T> view();
  [[nodiscard]] BodyView<const T> view() const;
  [[nodiscard]] std::size_t size() const { return count_; }

 private:
  /// q and p pointed at `columns`; the view of the arrays to fill.
  BodyView<T> point_at(const BodyColumns<T>& columns);
  std::size_t count_ = 0;
  std::unique_ptr<T[], detail::FreeLarge> own_;  // inv_mass, Ix, Iy, Iz, vx, vy, vz, wx, wy, wz: 10 runs of count_
  std::array<const T*, 7> read_{};               // qw, qx, qy, qz, px, py, pz
};

/// Reads a bodies file (CSV: read_bodies; binary: mapped, and checked
/// unless `rules` leaves that to the caller).
template <class T>
LoadedBodies<T> load_bodies(const std::string& path, SceneFormat format, BodyRules rules = BodyRules::checked);
/// Reads a contacts file whose ids refer to `body_count` bodies.
template <class T>
LoadedContacts<T> load_contacts(const std::string& path, SceneFormat format, std::size_t body_count);
/// Reads an impulses file (what `collide solve --out-impulses` writes) in
/// precision T: read_impulses for CSV; for binary, the members jx, jy, jz,
/// copied (a double too large for float is refused, as in a scene file).
template <class T>
ImpulseBuffer<T> load_impulses(const std::string& path, SceneFormat format);

// ---------------------------------------------------------------------------
// Binary writers: the CSV writers' counterparts (collide/io/scene_io.hpp).
// ---------------------------------------------------------------------------

/// The result bodies file: every column of `inputs` except v and w, which
/// come from `solved`.
template <class T>
void write_bodies_npz(OutputFile& out, const BodyColumns<T>& inputs, const BodyView<const T>& solved);
/// The impulses file: members jx, jy, jz.
template <class T>
void write_impulses_npz(OutputFile& out, const ImpulseView<const T>& impulses);
/// A bodies file as given (a scene input file).
template <class T>
void write_body_table_npz(OutputFile& out, const BodyColumns<T>& table);
/// A contacts file, values as given; a view without e gets uniform_e in
/// every row, one without mu gets 0.
template <class T>
void write_contacts_npz(OutputFile& out, const ContactView<T>& contacts);

/// Writes a scene input file in either format.
template <class T>
void write_body_table(OutputFile& out, SceneFormat format, const BodyColumns<T>& table);
template <class T>
void write_contacts(OutputFile& out, SceneFormat format, const ContactView<T>& contacts);
/// Writes an impulses file in either format.
template <class T>
void write_impulses(OutputFile& out, SceneFormat format, const ImpulseView<const T>& impulses);

}  // namespace collide
