// npz_write.cpp - writing an .npz archive in one pass (write_npz,
// format_npz; collide/io/npz.hpp): each member's .npy header and CRC-32, its
// aligned local header and data, then the central directory and the ZIP64
// end records. The format's constants, shared with the reader, are
// npz_format.hpp's.
//
// Design notes
// ------------
// * Writing has one layout for every size: each member has ZIP64 sizes
//   (0xFFFFFFFF in the classic fields, the values in a ZIP64 extra block) in
//   its local header and its central entry, and the archive ends with the
//   ZIP64 end records. A column over 4 GiB therefore gets exactly the layout
//   the tests read back with np.load and Python's zipfile, not a branch no
//   test reaches. The one exception is an archive without members: the bare
//   22-byte end record np.savez writes for no arrays, because np.load
//   recognises an empty .npz only by those bytes at the start of the file.
// * Alignment: the local header's extra field ends with an Android zipalign
//   block (id 0xD935: the alignment as a 16-bit value, then zeros), sized so
//   the member's .npy bytes start at a multiple of kNpzAlignment. NumPy pads
//   the .npy header of a 1-D array to a multiple of 64 bytes, so the array
//   data that follows is aligned too.
// * One pass in file order, so the CRC-32 that the local header holds must
//   be known before the data is written: every member's is computed first,
//   the members in parallel, each by libdeflate (carry-less multiplication
//   where the CPU has it, about four times zlib's speed), and
//   the data is then written straight from the caller's array: to a file
//   under a temporary name at its offsets, in 8 MiB slices on every thread
//   (pwrite), to a stream or a device in order.
#include "collide/io/npz.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include <oneapi/tbb/parallel_for.h>

#include "npz_format.hpp"

namespace collide {
namespace {

// The format's constants and helpers (npz_format.hpp).
using namespace detail::npz;

// Fixed fields: every archive of the same columns has the same bytes.
constexpr std::uint16_t kVersionNeeded = 45;                          // 4.5: ZIP64
constexpr std::uint16_t kVersionMadeBy = (3U << 8) | kVersionNeeded;  // Unix, 4.5
constexpr std::uint16_t kDosTime = 0;                                 // 00:00:00
constexpr std::uint16_t kDosDate = (0U << 9) | (1U << 5) | 1U;        // 1980-01-01
constexpr std::uint32_t kExternalAttributes = 0100644U << 16;         // a regular file, rw-r--r--
constexpr std::uint16_t kUtf8NameFlag = 1U << 11;
constexpr std::uint16_t kZipAlignExtraId = 0xD935;      // Android zipalign
constexpr std::size_t kZipAlignExtraMin = 6;            // id, length, 16-bit alignment
constexpr std::size_t kLocalZip64ExtraSize = 4 + 16;    // uncompressed, compressed
constexpr std::size_t kCentralZip64ExtraSize = 4 + 24;  // uncompressed, compressed, offset
// NumPy leaves room for the length of the first axis to grow to this many
// digits (numpy.lib.format.GROWTH_AXIS_MAX_DIGITS) before padding.
constexpr std::size_t kGrowthAxisMaxDigits = 21;
constexpr std::size_t kNpyAlign = 64;  // numpy.lib.format.ARRAY_ALIGN

void put16(std::string& out, std::uint16_t v) {
  out += static_cast<char>(v & 0xFF);
  out += static_cast<char>(v >> 8);
}
void put32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((v >> (8 * i)) & 0xFF);
}
void put64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out += static_cast<char>((v >> (8 * i)) & 0xFF);
}

/// The .npy header numpy.lib.format.write_array writes for a 1-D C-order
/// array of `count` elements: format 1.0, the dict with sorted keys, room
/// for the first axis to grow, then spaces and a newline up to a multiple
/// of 64 bytes.
std::string npy_header(NpyType type, std::size_t count) {
  std::string dict = "{'descr': '" + std::string(npy_descr(type)) + "', 'fortran_order': False, 'shape': (" +
                     std::to_string(count) + ",), }";
  dict.append(kGrowthAxisMaxDigits - std::to_string(count).size(), ' ');
  const std::size_t prefix = kNpyMagic.size() + 2 + 2;
  const std::size_t padding = kNpyAlign - (prefix + dict.size() + 1) % kNpyAlign;
  dict.append(padding, ' ');
  dict += '\n';
  std::string header(kNpyMagic);
  header += '\x01';
  header += '\x00';
  put16(header, static_cast<std::uint16_t>(dict.size()));
  return header + dict;
}

/// The CRC-32 of a member: its .npy header, then its array data. (Given a
/// null buffer, libdeflate_crc32 returns the initial value, not `crc`: an
/// empty column, whose data may be null, adds nothing.)
std::uint32_t member_crc(const std::string& npy, const void* data, std::size_t data_size) {
  const std::uint32_t header = libdeflate_crc32(0, npy.data(), npy.size());
  return data_size == 0 ? header : libdeflate_crc32(header, data, data_size);
}

/// One member as written: its .npy header, where its local header starts,
/// its size and CRC.
struct WrittenMember {
  std::string name;  // with ".npy"
  std::uint64_t local_offset;
  std::uint64_t size;
  std::uint32_t crc;
  std::uint16_t flags;
};

/// The fields the local header and the central directory's entry share, in
/// the order both write them (APPNOTE 4.3.7 and 4.3.12, from "version needed
/// to extract" to "file name length"): stored, not compressed; the sizes
/// in the ZIP64 extra block.
void put_member_fields(std::string& out, const WrittenMember& member) {
  put16(out, kVersionNeeded);
  put16(out, member.flags);
  put16(out, 0);  // stored
  put16(out, kDosTime);
  put16(out, kDosDate);
  put32(out, member.crc);
  put32(out, kZip32Max);  // compressed size: in the ZIP64 block
  put32(out, kZip32Max);  // uncompressed size: in the ZIP64 block
  put16(out, static_cast<std::uint16_t>(member.name.size()));
}

void check_columns(const std::vector<NpzColumn>& columns) {
  std::unordered_set<std::string_view> names;
  for (const NpzColumn& column : columns) {
    if (column.name.empty()) throw std::invalid_argument("write_npz: a column has an empty name");
    if (column.name.size() > kZip16Max - kNpySuffix.size()) {
      throw std::invalid_argument("write_npz: column name too long for a ZIP member");
    }
    if (!names.insert(column.name).second) {
      throw std::invalid_argument("write_npz: column '" + std::string(column.name) + "' given twice");
    }
    if (std::find(kAllTypes.begin(), kAllTypes.end(), column.type) == kAllTypes.end()) {
      throw std::invalid_argument("write_npz: column '" + std::string(column.name) + "' has no valid NpyType");
    }
    if (column.count > std::numeric_limits<std::size_t>::max() / 2 / npy_type_size(column.type)) {
      throw std::invalid_argument("write_npz: column '" + std::string(column.name) + "' is too large");
    }
    if (column.data == nullptr && column.count > 0) {
      throw std::invalid_argument("write_npz: column '" + std::string(column.name) + "' has no data");
    }
  }
}

/// Writes the archive through `sink(std::string_view)`, in file order.
template <class Sink>
void write_archive(const std::vector<NpzColumn>& columns, Sink&& sink) {
  check_columns(columns);
  if (columns.empty()) {
    // What np.savez writes for no arrays, and np.load recognises (see the
    // design notes).
    std::string end;
    put32(end, kEndSignature);
    end.append(kEndSize - 4, '\0');
    sink(end);
    return;
  }
  // Every member's CRC first, the members in parallel (see the design notes).
  std::vector<std::uint32_t> crcs(columns.size());
  oneapi::tbb::parallel_for(std::size_t{0}, columns.size(), [&](std::size_t k) {
    const NpzColumn& column = columns[k];
    crcs[k] = member_crc(npy_header(column.type, column.count), column.data, column.count * npy_type_size(column.type));
  });
  std::uint64_t offset = 0;
  std::vector<WrittenMember> written;
  written.reserve(columns.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const NpzColumn& column = columns[k];
    const std::string npy = npy_header(column.type, column.count);
    const std::size_t data_size = column.count * npy_type_size(column.type);
    WrittenMember member;
    member.name = std::string(column.name) + std::string(kNpySuffix);
    member.local_offset = offset;
    member.size = npy.size() + data_size;
    member.crc = crcs[k];
    const bool ascii = std::all_of(member.name.begin(), member.name.end(),
                                   [](char c) { return static_cast<unsigned char>(c) < 0x80; });
    member.flags = ascii ? 0 : kUtf8NameFlag;

    // Zipalign block: the .npy bytes start at a multiple of kNpzAlignment.
    const std::uint64_t unaligned_start =
        offset + kLocalHeaderSize + member.name.size() + kLocalZip64ExtraSize + kZipAlignExtraMin;
    const std::size_t zeros =
        static_cast<std::size_t>((kNpzAlignment - unaligned_start % kNpzAlignment) % kNpzAlignment);

    std::string local;
    put32(local, kLocalHeaderSignature);
    put_member_fields(local, member);
    put16(local, static_cast<std::uint16_t>(kLocalZip64ExtraSize + kZipAlignExtraMin + zeros));
    local += member.name;
    put16(local, kZip64ExtraId);
    put16(local, 16);
    put64(local, member.size);  // uncompressed
    put64(local, member.size);  // compressed
    put16(local, kZipAlignExtraId);
    put16(local, static_cast<std::uint16_t>(2 + zeros));
    put16(local, static_cast<std::uint16_t>(kNpzAlignment));
    local.append(zeros, '\0');
    local += npy;
    sink(local);
    sink(std::string_view(static_cast<const char*>(column.data), data_size));
    offset += local.size() + data_size;
    written.push_back(std::move(member));
  }

  const std::uint64_t directory_offset = offset;
  std::string tail;
  for (const WrittenMember& member : written) {
    put32(tail, kCentralHeaderSignature);
    put16(tail, kVersionMadeBy);
    put_member_fields(tail, member);
    put16(tail, static_cast<std::uint16_t>(kCentralZip64ExtraSize));
    put16(tail, 0);  // comment length
    put16(tail, 0);  // disk number
    put16(tail, 0);  // internal attributes
    put32(tail, kExternalAttributes);
    put32(tail, kZip32Max);  // local header offset
    tail += member.name;
    put16(tail, kZip64ExtraId);
    put16(tail, 24);
    put64(tail, member.size);  // uncompressed
    put64(tail, member.size);  // compressed
    put64(tail, member.local_offset);
  }
  const std::uint64_t directory_size = tail.size();
  const std::uint64_t zip64_end_offset = directory_offset + directory_size;
  put32(tail, kZip64EndSignature);
  put64(tail, kZip64EndSize - 12);  // the record's size after this field
  put16(tail, kVersionMadeBy);
  put16(tail, kVersionNeeded);
  put32(tail, 0);  // this disk
  put32(tail, 0);  // the directory's disk
  put64(tail, written.size());
  put64(tail, written.size());
  put64(tail, directory_size);
  put64(tail, directory_offset);
  put32(tail, kZip64LocatorSignature);
  put32(tail, 0);  // the ZIP64 end record's disk
  put64(tail, zip64_end_offset);
  put32(tail, 1);  // disks in all
  put32(tail, kEndSignature);
  put16(tail, 0);          // this disk
  put16(tail, 0);          // the directory's disk
  put16(tail, kZip16Max);  // entries on this disk: in the ZIP64 record
  put16(tail, kZip16Max);  // entries: in the ZIP64 record
  put32(tail, kZip32Max);  // directory size: in the ZIP64 record
  put32(tail, kZip32Max);  // directory offset: in the ZIP64 record
  put16(tail, 0);          // comment length
  sink(tail);
}

}  // namespace

void write_npz(OutputFile& out, const std::vector<NpzColumn>& columns) {
  if (out.direct()) {
    write_archive(columns, [&](std::string_view bytes) { out.write(bytes); });
    return;
  }
  // A file under a temporary name: every piece goes to its offset, the
  // large ones in slices on every thread. Writing new page-cache pages is
  // bound by allocating and filling them, which one thread does slowly on a
  // VM that hands free memory back to its host
  // (docs/decisions/0027-writing-the-binary-scene-files.md).
  constexpr std::size_t kSlice = std::size_t{8} << 20;
  struct Piece {
    std::uint64_t offset;
    std::string_view bytes;
  };
  std::deque<std::string> copies;  // the headers: the sink's strings are temporaries
  std::vector<Piece> pieces;
  std::uint64_t offset = 0;
  write_archive(columns, [&](std::string_view bytes) {
    // Only a member's data reaches a slice's size, and it is the caller's.
    if (bytes.size() < kSlice) bytes = copies.emplace_back(bytes);
    for (std::size_t at = 0; at < bytes.size(); at += kSlice) {
      pieces.push_back(Piece{offset + at, bytes.substr(at, kSlice)});
    }
    offset += bytes.size();
  });
  oneapi::tbb::parallel_for(std::size_t{0}, pieces.size(),
                            [&](std::size_t k) { out.write_at(pieces[k].offset, pieces[k].bytes); });
}

std::string format_npz(const std::vector<NpzColumn>& columns) {
  check_columns(columns);
  // One allocation: the data, plus a generous bound on the headers of each
  // member (local and central, with padding) and the end records.
  std::size_t bound = 128;
  for (const NpzColumn& column : columns) {
    bound += column.count * npy_type_size(column.type) + 2 * column.name.size() + 512;
  }
  std::string archive;
  archive.reserve(bound);
  write_archive(columns, [&](std::string_view bytes) { archive.append(bytes); });
  return archive;
}

}  // namespace collide
