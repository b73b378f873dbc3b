// collide/io/npz.hpp - NumPy arrays in an uncompressed .npz archive: the
// container of collide's binary scene files.
//
// Design notes
// ------------
// * An .npz is a ZIP archive of .npy members (NumPy's `np.savez`). Stored,
//   not deflated, each member's array data is a contiguous run of bytes in
//   the file, so a mapped archive gives the solver its columns in place: no
//   copy, no parse. Only the ZIP directory and the small .npy headers are
//   read; the data is not touched until it is used.
// * Reading accepts what NumPy writes (ZIP64 extra fields, any member order,
//   data at any offset) and refuses, with a message naming the file and the
//   member, everything a scene cannot be: a deflated or encrypted member, a
//   header that is not a 1-D C-order array, a big-endian or object dtype, a
//   member whose size is not its header's plus count elements, a truncated
//   archive. The CRC-32 of a member is not checked on reading (it would read
//   every byte); the scene's values are validated instead.
// * Writing produces what `np.load` reads, byte-identical for the same
//   columns (fixed timestamps, no random fields), with each array's data
//   aligned to kNpzAlignment bytes in the file (by padding the local
//   header's extra field, as zipalign does), so a mapped member is aligned
//   for every element type. The writer never seeks: CRCs (libdeflate's, the
//   members in parallel) are computed before a member is written, so a FIFO
//   or stdout works as for CSV.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "collide/io/output_file.hpp"

namespace collide {

/// Element types a scene member may have: the little-endian .npy dtypes
/// '<f4', '<f8', '<u4', '<i4', '<u8', '<i8'.
enum class NpyType : std::uint8_t { f4, f8, u4, i4, u8, i8 };

/// Size in bytes of one element.
std::size_t npy_type_size(NpyType type);
/// The dtype string of the .npy header ("<f4", ...).
std::string_view npy_descr(NpyType type);

/// Where each member's array data starts, relative to the file, in archives
/// written by write_npz.
inline constexpr std::size_t kNpzAlignment = 64;

/// A parsed .npy header.
struct NpyHeader {
  NpyType type;
  std::size_t count;         ///< elements: shape (count,)
  std::size_t header_bytes;  ///< offset of the array data from the start of the .npy bytes
};

/// Parses the .npy header at the start of `bytes` (magic, version 1.0, 2.0
/// or 3.0, the header dictionary): a 1-D (or 0-D: count 1), C-order array
/// of one of the NpyType dtypes. Throws std::runtime_error with the reason
/// (the caller names the file and member). Never reads past `bytes`.
NpyHeader parse_npy_header(std::string_view bytes);

/// One member of an archive: `<name>.npy`, its array data in place.
struct NpzMember {
  std::string name;  ///< the member's name without ".npy"
  NpyType type;
  std::size_t count;
  const std::byte* data;  ///< count elements; aligned only if the writer aligned them
};

/// A read-only .npz archive: mapped from a file, or over the caller's bytes.
/// Movable, not copyable; a mapped archive unmaps when destroyed, and its
/// members' data pointers die with it.
class NpzArchive {
 public:
  /// Maps the file and reads its directory. Throws SceneError (file name,
  /// the member as column() where one is at fault: its name without ".npy",
  /// or the whole name when it lacks the suffix; the reason). A pipe or
  /// device (process substitution, /dev/stdin), which cannot be mapped, is
  /// read whole into memory the archive owns, page-aligned like a mapping.
  static NpzArchive map(const std::string& path);
  /// Reads the directory of an archive held in `bytes`, which must outlive
  /// the result. `file_name` only labels messages.
  static NpzArchive parse(std::string_view bytes, std::string file_name);

  NpzArchive(NpzArchive&& other) noexcept;
  NpzArchive& operator=(NpzArchive&& other) noexcept;
  NpzArchive(const NpzArchive&) = delete;
  NpzArchive& operator=(const NpzArchive&) = delete;
  ~NpzArchive();

  /// Members in the order of the archive's directory.
  [[nodiscard]] const std::vector<NpzMember>& members() const { return members_; }
  /// The member `name` (without ".npy"), or nullptr.
  [[nodiscard]] const NpzMember* find(std::string_view name) const;
  [[nodiscard]] const std::string& file_name() const { return file_name_; }
  /// The whole archive's bytes.
  [[nodiscard]] std::string_view bytes() const { return bytes_; }

 private:
  NpzArchive() = default;
  std::string file_name_;
  std::string_view bytes_;
  void* mapping_ = nullptr;       // non-null when this archive owns the mapping that holds bytes_
  std::size_t mapping_size_ = 0;  // its length (larger than bytes_ for a pipe read into memory)
  std::vector<NpzMember> members_;
};

/// One array to write: `count` elements of `type` at `data`, as member
/// `<name>.npy`.
struct NpzColumn {
  std::string_view name;
  NpyType type;
  const void* data;
  std::size_t count;
};

/// Writes an uncompressed .npz that np.load reads, one member per column in
/// the given order, each array's data at a multiple of kNpzAlignment in the
/// file. The same columns give the same bytes. Every member has ZIP64 sizes,
/// whatever its size; an archive without columns is the bare end record
/// np.savez writes for no arrays. Throws std::invalid_argument for a column
/// with an empty name, a name given twice, or no data for a nonzero count
/// (before anything is written), SceneError when `out` cannot be written.
void write_npz(OutputFile& out, const std::vector<NpzColumn>& columns);
/// The complete archive in memory, as write_npz writes it.
std::string format_npz(const std::vector<NpzColumn>& columns);

}  // namespace collide
