// npz_read.cpp - reading an .npz archive (collide/io/npz.hpp): its ZIP
// directory read in place over the archive's bytes (NpzArchive::parse), the
// file mapped or a pipe read into memory (NpzArchive::map), and the
// archive's ownership of that memory. Each member's .npy header is read by
// npy_header.cpp; the format's constants are npz_format.hpp's.
//
// Design notes
// ------------
// * Nothing read from the file is trusted. Every range (the end records, the
//   central directory, each entry, a local header, a member's bytes) is
//   checked against the bytes held before it is touched, by comparing with
//   what is left rather than by adding lengths, so no sum can wrap; a count
//   read from the file is checked against the bytes that would have to hold
//   it before anything is reserved for it. fuzz/fuzz_npz.cpp feeds this code
//   arbitrary bytes.
// * The central directory is the authority on sizes and offsets. A local
//   header is read only for the lengths of its own name and extra field,
//   which place the data and may differ from the central entry's: NumPy's
//   local headers carry a ZIP64 block its central entries lack, and our
//   writer pads the local extra field alone.
#include "collide/io/npz.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include "collide/io/scene_io.hpp"
#include "input_file.hpp"
#include "npz_format.hpp"

namespace collide {

// Members are used in place: the file's little-endian elements must be the
// machine's.
static_assert(std::endian::native == std::endian::little, "collide reads .npy data in place: little-endian only");

namespace {

// The format's constants and helpers (npz_format.hpp).
using namespace detail::npz;

/// Little-endian fields of a byte range that the caller has checked is
/// long enough.
struct Fields {
  const char* p;
  [[nodiscard]] std::uint16_t u16(std::size_t at) const { return static_cast<std::uint16_t>(load_le(p + at, 2)); }
  [[nodiscard]] std::uint32_t u32(std::size_t at) const { return static_cast<std::uint32_t>(load_le(p + at, 4)); }
  [[nodiscard]] std::uint64_t u64(std::size_t at) const { return load_le(p + at, 8); }
};

/// True when [offset, offset + length) lies inside `size` bytes.
bool inside(std::uint64_t offset, std::uint64_t length, std::size_t size) {
  return offset <= size && length <= size - offset;
}

/// Where the central directory is, from the end records.
struct Directory {
  std::uint64_t entries;
  std::uint64_t size;
  std::uint64_t offset;
};

Directory find_directory(std::string_view bytes, const std::string& file) {
  if (bytes.size() < kEndSize) {
    throw SceneError(file, "not an .npz archive: " + std::to_string(bytes.size()) +
                               " bytes, too short for a ZIP end of central directory record");
  }
  // The end record is the last 22 bytes plus a comment of up to 65535: the
  // last candidate whose comment ends exactly at the end of the file (a
  // comment may itself contain the signature).
  const std::size_t lowest = bytes.size() - kEndSize - std::min<std::size_t>(bytes.size() - kEndSize, kZip16Max);
  std::optional<std::size_t> end;
  for (std::size_t at = bytes.size() - kEndSize + 1; at-- > lowest;) {
    const Fields f{bytes.data() + at};
    if (f.u32(0) == kEndSignature && std::size_t{f.u16(20)} == bytes.size() - kEndSize - at) {
      end = at;
      break;
    }
  }
  if (!end) throw SceneError(file, "not an .npz archive: no ZIP end of central directory record (truncated?)");
  const Fields eocd{bytes.data() + *end};
  Directory dir{eocd.u16(10), eocd.u32(12), eocd.u32(16)};
  const bool needs_zip64 =
      eocd.u16(8) == kZip16Max || eocd.u16(10) == kZip16Max || eocd.u32(12) == kZip32Max || eocd.u32(16) == kZip32Max;
  const bool has_locator =
      *end >= kZip64LocatorSize && Fields{bytes.data() + *end - kZip64LocatorSize}.u32(0) == kZip64LocatorSignature;
  if (has_locator) {
    const Fields locator{bytes.data() + *end - kZip64LocatorSize};
    if (locator.u32(4) != 0 || locator.u32(16) > 1) {
      throw SceneError(file, "a multi-disk (split) ZIP archive; collide reads single-file archives");
    }
    const std::uint64_t at = locator.u64(8);
    if (!inside(at, kZip64EndSize, *end - kZip64LocatorSize)) {
      throw SceneError(file, "truncated archive: the ZIP64 end of central directory record (offset " +
                                 std::to_string(at) + ") lies outside the file");
    }
    const Fields zip64{bytes.data() + at};
    if (zip64.u32(0) != kZip64EndSignature) {
      throw SceneError(file,
                       "corrupt archive: no ZIP64 end of central directory record at offset " + std::to_string(at));
    }
    if (zip64.u32(16) != 0 || zip64.u32(20) != 0) {
      throw SceneError(file, "a multi-disk (split) ZIP archive; collide reads single-file archives");
    }
    dir = Directory{zip64.u64(32), zip64.u64(40), zip64.u64(48)};
  } else if (needs_zip64) {
    throw SceneError(file, "corrupt archive: the end record points to ZIP64 records that are missing");
  } else if (eocd.u16(4) != 0 || eocd.u16(6) != 0) {
    throw SceneError(file, "a multi-disk (split) ZIP archive; collide reads single-file archives");
  }
  if (!inside(dir.offset, dir.size, bytes.size())) {
    throw SceneError(file, "truncated archive: the central directory (offset " + std::to_string(dir.offset) + ", " +
                               std::to_string(dir.size) + " bytes) lies past the end of the file (" +
                               std::to_string(bytes.size()) + " bytes)");
  }
  if (dir.entries > dir.size / kCentralHeaderSize) {
    throw SceneError(file, "corrupt archive: the directory claims " + std::to_string(dir.entries) +
                               " members but has room for " + std::to_string(dir.size / kCentralHeaderSize));
  }
  return dir;
}

/// A central directory entry's sizes and offset after its ZIP64 block.
struct EntryPlace {
  std::uint64_t compressed;
  std::uint64_t uncompressed;
  std::uint64_t local_offset;
};

/// Reads the ZIP64 extra block of a central entry: 8-byte values for exactly
/// the classic fields that are 0xFFFFFFFF, in the order uncompressed size,
/// compressed size, local header offset. Returns an empty string on success,
/// else the reason.
std::string apply_zip64_extra(std::string_view extra, EntryPlace& place) {
  const bool want_uncompressed = place.uncompressed == kZip32Max;
  const bool want_compressed = place.compressed == kZip32Max;
  const bool want_offset = place.local_offset == kZip32Max;
  bool found = false;
  while (!extra.empty()) {
    if (extra.size() < 4) return "corrupt extra field: " + std::to_string(extra.size()) + " stray bytes";
    const Fields f{extra.data()};
    const std::uint16_t id = f.u16(0);
    const std::size_t length = f.u16(2);
    if (length > extra.size() - 4) return "corrupt extra field: a block runs past the field's end";
    if (id == kZip64ExtraId && !found) {
      found = true;
      std::string_view data = extra.substr(4, length);
      auto take = [&](std::uint64_t& field) {
        if (data.size() < 8) return false;
        field = Fields{data.data()}.u64(0);
        data.remove_prefix(8);
        return true;
      };
      if ((want_uncompressed && !take(place.uncompressed)) || (want_compressed && !take(place.compressed)) ||
          (want_offset && !take(place.local_offset))) {
        return "corrupt ZIP64 extra field: too short for the sizes it must hold";
      }
    }
    extra.remove_prefix(4 + length);
  }
  if ((want_uncompressed || want_compressed || want_offset) && !found) {
    return "a size or offset is 0xFFFFFFFF but the entry has no ZIP64 extra field";
  }
  return {};
}

}  // namespace

NpzArchive NpzArchive::parse(std::string_view bytes, std::string file_name) {
  NpzArchive archive;
  archive.file_name_ = std::move(file_name);
  archive.bytes_ = bytes;
  const std::string& file = archive.file_name_;

  const Directory dir = find_directory(bytes, file);
  std::unordered_set<std::string_view> names;
  archive.members_.reserve(static_cast<std::size_t>(dir.entries));
  std::size_t at = static_cast<std::size_t>(dir.offset);
  const std::size_t directory_end = static_cast<std::size_t>(dir.offset + dir.size);
  for (std::uint64_t k = 0; k < dir.entries; ++k) {
    const auto entry_label = [k] { return "central directory entry " + std::to_string(k); };
    if (directory_end - at < kCentralHeaderSize) {
      throw SceneError(file, "corrupt archive: " + entry_label() + " runs past the end of the directory");
    }
    const Fields entry{bytes.data() + at};
    if (entry.u32(0) != kCentralHeaderSignature) {
      throw SceneError(file, "corrupt archive: " + entry_label() + " has no central directory signature");
    }
    const std::size_t name_length = entry.u16(28);
    const std::size_t extra_length = entry.u16(30);
    const std::size_t comment_length = entry.u16(32);
    if (directory_end - at - kCentralHeaderSize < name_length + extra_length + comment_length) {
      throw SceneError(file, "corrupt archive: " + entry_label() + " runs past the end of the directory");
    }
    const std::string_view full_name = bytes.substr(at + kCentralHeaderSize, name_length);
    const std::string_view extra = bytes.substr(at + kCentralHeaderSize + name_length, extra_length);
    const std::uint16_t flags = entry.u16(8);
    const std::uint16_t method = entry.u16(10);
    EntryPlace place{entry.u32(20), entry.u32(24), entry.u32(42)};
    at += kCentralHeaderSize + name_length + extra_length + comment_length;

    const bool is_npy =
        full_name.size() >= kNpySuffix.size() && full_name.substr(full_name.size() - kNpySuffix.size()) == kNpySuffix;
    const std::string_view name = is_npy ? full_name.substr(0, full_name.size() - kNpySuffix.size()) : full_name;
    const std::string quoted_member = quoted_text(full_name);
    auto member_error = [&](const std::string& reason) {
      return SceneError(file, 0, SceneError::kNoRow, std::string(name), reason);
    };
    if (name.empty()) throw SceneError(file, "member " + quoted_member + " has no name");
    if ((flags & 1U) != 0) throw member_error("member " + quoted_member + " is encrypted");
    if (method != 0) {
      throw member_error("member " + quoted_member + " is compressed (" +
                         (method == 8 ? std::string("deflate") : "method " + std::to_string(method)) +
                         "); scene files must be saved with np.savez, not np.savez_compressed");
    }
    if (!is_npy) throw member_error("member " + quoted_member + " is not an .npy array");
    if (!names.insert(name).second) throw member_error("member " + quoted_member + " appears twice in the archive");
    if (const std::string reason = apply_zip64_extra(extra, place); !reason.empty()) {
      std::string message = "member " + quoted_member + ": ";
      message += reason;
      throw member_error(message);
    }
    if (place.compressed != place.uncompressed) {
      throw member_error("member " + quoted_member + " is stored with " + std::to_string(place.compressed) +
                         " bytes for " + std::to_string(place.uncompressed) + " bytes of content");
    }

    // The local header: its own name and extra lengths place the data.
    if (!inside(place.local_offset, kLocalHeaderSize, bytes.size())) {
      throw member_error("member " + quoted_member + ": its local header (offset " +
                         std::to_string(place.local_offset) + ") lies past the end of the file");
    }
    const std::size_t local_at = static_cast<std::size_t>(place.local_offset);
    const Fields local{bytes.data() + local_at};
    if (local.u32(0) != kLocalHeaderSignature) {
      throw member_error("member " + quoted_member + ": no local header signature at offset " +
                         std::to_string(local_at));
    }
    const std::size_t local_name_length = local.u16(26);
    const std::size_t local_extra_length = local.u16(28);
    const std::uint64_t data_offset = place.local_offset + kLocalHeaderSize + local_name_length + local_extra_length;
    if (!inside(local_at + kLocalHeaderSize, local_name_length, bytes.size()) ||
        bytes.substr(local_at + kLocalHeaderSize, local_name_length) != full_name) {
      throw member_error("member " + quoted_member + ": its local header names another file");
    }
    if (!inside(data_offset, place.uncompressed, bytes.size())) {
      throw member_error("member " + quoted_member + ": its " + std::to_string(place.uncompressed) +
                         " bytes at offset " + std::to_string(data_offset) + " run past the end of the file (" +
                         std::to_string(bytes.size()) + " bytes)");
    }
    const std::string_view content =
        bytes.substr(static_cast<std::size_t>(data_offset), static_cast<std::size_t>(place.uncompressed));

    NpyHeader header{};
    try {
      header = parse_npy_header(content);
    } catch (const std::runtime_error& e) {
      throw member_error("member " + quoted_member + ": " + e.what());
    }
    const std::size_t expected = header.header_bytes + header.count * npy_type_size(header.type);
    if (expected != content.size()) {
      throw member_error("member " + quoted_member + " has " + std::to_string(content.size()) +
                         " bytes, but its header says " + std::to_string(header.header_bytes) + " + " +
                         std::to_string(header.count) + " x " + std::to_string(npy_type_size(header.type)) + " = " +
                         std::to_string(expected) + (expected > content.size() ? " (truncated)" : " (trailing bytes)"));
    }
    archive.members_.push_back(NpzMember{std::string(name), header.type, header.count,
                                         reinterpret_cast<const std::byte*>(content.data() + header.header_bytes)});
  }
  return archive;
}

NpzArchive NpzArchive::map(const std::string& path) {
  const detail::InputFile file(path);
  const int fd = file.fd();

  // The mapping is owned by a guard until parse() has accepted the bytes, so
  // a refused archive is unmapped on the way out.
  struct Mapping {
    void* address = MAP_FAILED;
    std::size_t size = 0;
    ~Mapping() {
      if (address != MAP_FAILED) ::munmap(address, size);
    }
  } mapping;
  std::size_t length = 0;
  if (file.regular()) {
    length = file.size();
    if (length == 0) throw SceneError(path, "empty file, not an .npz archive");
    // No MAP_POPULATE or MADV_WILLNEED: only the directory and the .npy
    // headers are read here; the data is streamed by whoever uses it.
    mapping.address = ::mmap(nullptr, length, PROT_READ, MAP_PRIVATE, fd, 0);
    if (mapping.address == MAP_FAILED) {
      const int err = errno;
      throw SceneError(path, std::string("cannot map: ") + std::strerror(err), err);
    }
    mapping.size = length;
  } else {
    // A pipe or a device (process substitution, /dev/stdin): read into an
    // anonymous mapping grown with mremap, owned like a file mapping and
    // page-aligned like one, so aligned members stay aligned.
    mapping.size = std::size_t(1) << 20;
    mapping.address = ::mmap(nullptr, mapping.size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapping.address == MAP_FAILED) {
      const int err = errno;
      throw SceneError(path, std::string("cannot allocate: ") + std::strerror(err), err);
    }
    for (;;) {
      if (length == mapping.size) {
        void* bigger = ::mremap(mapping.address, mapping.size, mapping.size * 2, MREMAP_MAYMOVE);
        if (bigger == MAP_FAILED) {
          const int err = errno;
          throw SceneError(path, std::string("cannot allocate: ") + std::strerror(err), err);
        }
        mapping.address = bigger;
        mapping.size *= 2;
      }
      const ssize_t got = ::read(fd, static_cast<char*>(mapping.address) + length, mapping.size - length);
      if (got < 0) {
        const int err = errno;
        if (err == EINTR) continue;
        throw SceneError(path, std::string("read error: ") + std::strerror(err), err);
      }
      if (got == 0) break;
      length += static_cast<std::size_t>(got);
    }
    if (length == 0) throw SceneError(path, "empty file, not an .npz archive");
    ::mprotect(mapping.address, mapping.size, PROT_READ);
  }
  NpzArchive archive = parse(std::string_view(static_cast<const char*>(mapping.address), length), path);
  archive.mapping_ = std::exchange(mapping.address, MAP_FAILED);
  archive.mapping_size_ = mapping.size;
  return archive;
}

NpzArchive::NpzArchive(NpzArchive&& other) noexcept
    : file_name_(std::move(other.file_name_)),
      bytes_(std::exchange(other.bytes_, std::string_view())),
      mapping_(std::exchange(other.mapping_, nullptr)),
      mapping_size_(std::exchange(other.mapping_size_, 0)),
      members_(std::move(other.members_)) {
  other.members_.clear();
}

NpzArchive& NpzArchive::operator=(NpzArchive&& other) noexcept {
  if (this != &other) {
    if (mapping_ != nullptr) ::munmap(mapping_, mapping_size_);
    file_name_ = std::move(other.file_name_);
    bytes_ = std::exchange(other.bytes_, std::string_view());
    mapping_ = std::exchange(other.mapping_, nullptr);
    mapping_size_ = std::exchange(other.mapping_size_, 0);
    members_ = std::move(other.members_);
    other.members_.clear();
  }
  return *this;
}

NpzArchive::~NpzArchive() {
  if (mapping_ != nullptr) ::munmap(mapping_, mapping_size_);
}

const NpzMember* NpzArchive::find(std::string_view name) const {
  for (const NpzMember& member : members_) {
    if (member.name == name) return &member;
  }
  return nullptr;
}

}  // namespace collide
