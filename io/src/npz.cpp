// npz.cpp - NumPy .npy arrays in an uncompressed .npz (ZIP) archive: the
// directory of an archive read in place, an archive written in one pass.
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
// * The .npy header is a Python dict literal that NumPy reads with
//   ast.literal_eval. This reader accepts the part of that language a 1-D
//   column can be written in (quoted strings, True/False, tuples of
//   integers, the three keys in any order, any whitespace, trailing commas)
//   and names what it refuses rather than guessing.
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
// * The writer never seeks, so the CRC-32 that the local header holds must
//   be known before the data is written: every member's is computed first,
//   the members in parallel, each by libdeflate (carry-less multiplication
//   where the CPU has it, about four times zlib's speed), and
//   the data is then written straight from the caller's array.
#include "collide/io/npz.hpp"

#include <fcntl.h>
#include <libdeflate.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

#include <oneapi/tbb/parallel_for.h>

#include "collide/io/scene_io.hpp"
#include "input_file.hpp"

namespace collide {

// Members are used in place: the file's little-endian elements must be the
// machine's.
static_assert(std::endian::native == std::endian::little, "collide reads .npy data in place: little-endian only");

namespace {

constexpr std::array<NpyType, 6> kAllTypes = {NpyType::f4, NpyType::f8, NpyType::u4,
                                              NpyType::i4, NpyType::u8, NpyType::i8};
constexpr std::string_view kSupportedDtypes = "'<f4', '<f8', '<u4', '<i4', '<u8' or '<i8'";

}  // namespace

std::size_t npy_type_size(NpyType type) {
  switch (type) {
    case NpyType::f4:
    case NpyType::u4:
    case NpyType::i4:
      return 4;
    case NpyType::f8:
    case NpyType::u8:
    case NpyType::i8:
      return 8;
  }
  throw std::invalid_argument("npy_type_size: not an NpyType");
}

std::string_view npy_descr(NpyType type) {
  switch (type) {
    case NpyType::f4:
      return "<f4";
    case NpyType::f8:
      return "<f8";
    case NpyType::u4:
      return "<u4";
    case NpyType::i4:
      return "<i4";
    case NpyType::u8:
      return "<u8";
    case NpyType::i8:
      return "<i8";
  }
  throw std::invalid_argument("npy_descr: not an NpyType");
}

// ---------------------------------------------------------------------------
// The .npy header
// ---------------------------------------------------------------------------
namespace {

constexpr std::string_view kNpyMagic = "\x93NUMPY";

/// The text of a value as quoted in a message, shortened if long, with
/// control and non-ASCII bytes escaped (the text comes from the file).
std::string quoted_text(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
    } else {
      constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (text.size() > kMax) out += "...";
  out += "'";
  return out;
}

/// A reader of the header dictionary: the Python literal subset described in
/// the design notes. Every failure throws std::runtime_error.
class HeaderLiteral {
 public:
  explicit HeaderLiteral(std::string_view text) : text_(text) {}

  void skip_space() {
    while (pos_ < text_.size() &&
           (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' || text_[pos_] == '\r')) {
      ++pos_;
    }
  }
  [[nodiscard]] bool at_end() const { return pos_ == text_.size(); }
  /// Consumes `c` after optional whitespace; false (nothing consumed but the
  /// whitespace) if the next character is another.
  bool accept(char c) {
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(char c, std::string_view where) {
    if (!accept(c)) fail(std::string("expected '") + c + "' " + std::string(where));
  }
  [[nodiscard]] char peek() {
    skip_space();
    return pos_ < text_.size() ? text_[pos_] : '\0';
  }

  /// A quoted string without escapes ('...' or "...").
  std::string_view string(std::string_view what) {
    skip_space();
    if (pos_ >= text_.size() || (text_[pos_] != '\'' && text_[pos_] != '"'))
      fail("expected a quoted " + std::string(what));
    const char quote = text_[pos_++];
    const std::size_t start = pos_;
    while (pos_ < text_.size() && text_[pos_] != quote) {
      if (text_[pos_] == '\\') fail("escape sequences are not supported in a " + std::string(what));
      if (text_[pos_] == '\n') break;
      ++pos_;
    }
    if (pos_ >= text_.size() || text_[pos_] != quote) fail("unterminated " + std::string(what));
    return text_.substr(start, pos_++ - start);
  }

  /// A bare word: True, False, or anything else the caller names in a message.
  std::string_view word() {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_')) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  /// A Python int literal in decimal with an optional sign, as a dimension:
  /// >= 0 and within size_t.
  std::size_t dimension() {
    skip_space();
    const std::size_t start = pos_;
    bool negative = false;
    if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) {
      negative = text_[pos_] == '-';
      ++pos_;
      skip_space();
    }
    const std::size_t digits = pos_;
    while (pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '9') ++pos_;
    if (pos_ == digits) fail("expected an integer dimension in 'shape'");
    const std::string_view literal = text_.substr(start, pos_ - start);
    std::size_t value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + digits, text_.data() + pos_, value);
    const bool zero = text_.find_first_not_of('0', digits) >= pos_;
    if (negative && !zero) throw std::runtime_error("negative dimension " + std::string(literal) + " in 'shape'");
    if (ec != std::errc() || end != text_.data() + pos_) {
      throw std::runtime_error("dimension " + quoted_text(literal) + " in 'shape' is too large");
    }
    return value;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("malformed .npy header dictionary: " + what + " at byte " + std::to_string(pos_) + " of " +
                             quoted_text(text_));
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

/// The element type of a descr, or the reason it is refused.
NpyType dtype_of(std::string_view descr) {
  for (const NpyType type : kAllTypes) {
    if (descr == npy_descr(type)) return type;
  }
  if (descr.size() == 3 && descr[0] == '>') {
    for (const NpyType type : kAllTypes) {
      if (descr.substr(1) == npy_descr(type).substr(1)) {
        throw std::runtime_error("dtype " + quoted_text(descr) + " is big-endian; collide reads little-endian arrays");
      }
    }
  }
  std::string reason = "dtype " + quoted_text(descr);
  if (descr.size() >= 2 && descr[1] == 'O') reason += " (Python objects)";
  throw std::runtime_error(reason + " is not supported; a scene column is " + std::string(kSupportedDtypes));
}

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

std::uint64_t load_le(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

}  // namespace

NpyHeader parse_npy_header(std::string_view bytes) {
  if (bytes.substr(0, kNpyMagic.size()) != kNpyMagic.substr(0, std::min(bytes.size(), kNpyMagic.size()))) {
    throw std::runtime_error("not a .npy array: bad magic (it does not start with \\x93NUMPY)");
  }
  if (bytes.size() < kNpyMagic.size() + 2) {
    throw std::runtime_error("truncated .npy header: " + std::to_string(bytes.size()) + " bytes");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  const int minor = static_cast<unsigned char>(bytes[7]);
  if ((major != 1 && major != 2 && major != 3) || minor != 0) {
    throw std::runtime_error("unsupported .npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                             " (collide reads 1.0, 2.0 and 3.0)");
  }
  const std::size_t length_bytes = major == 1 ? 2 : 4;
  const std::size_t prefix = kNpyMagic.size() + 2 + length_bytes;
  if (bytes.size() < prefix) {
    throw std::runtime_error("truncated .npy header: " + std::to_string(bytes.size()) + " bytes");
  }
  const std::uint64_t dict_length = load_le(bytes.data() + 8, static_cast<int>(length_bytes));
  if (dict_length > bytes.size() - prefix) {
    throw std::runtime_error("truncated .npy header: it declares " + std::to_string(dict_length) +
                             " bytes of dictionary, " + std::to_string(bytes.size() - prefix) + " follow");
  }
  const std::string_view dict = bytes.substr(prefix, static_cast<std::size_t>(dict_length));
  if (dict.empty() || dict.back() != '\n') {
    throw std::runtime_error("malformed .npy header: the dictionary does not end with a newline");
  }

  HeaderLiteral in(dict);
  std::optional<std::string_view> descr;
  std::optional<bool> fortran_order;
  std::optional<std::vector<std::size_t>> shape;
  in.expect('{', "at the start of the header");
  while (!in.accept('}')) {
    const std::string_view key = in.string("key");
    in.expect(':', "after a key");
    if (key == "descr") {
      if (descr) in.fail("'descr' given twice");
      if (in.peek() == '[') {
        throw std::runtime_error("a structured dtype is not supported; a scene column is " +
                                 std::string(kSupportedDtypes));
      }
      descr = in.string("dtype");
    } else if (key == "fortran_order") {
      if (fortran_order) in.fail("'fortran_order' given twice");
      const std::string_view value = in.word();
      if (value != "True" && value != "False") in.fail("'fortran_order' is not True or False");
      fortran_order = value == "True";
    } else if (key == "shape") {
      if (shape) in.fail("'shape' given twice");
      in.expect('(', "('shape' must be a tuple)");
      std::vector<std::size_t> dims;
      bool tuple = false;  // "(3)" is the integer 3 in Python; only "(3,)" is a tuple
      while (!in.accept(')')) {
        if (dims.size() == 64) in.fail("'shape' has more than 64 dimensions");
        dims.push_back(in.dimension());
        if (in.accept(',')) {
          tuple = true;
        } else {
          in.expect(')', "after a dimension");
          break;
        }
      }
      if (dims.size() == 1 && !tuple) in.fail("'shape' is an integer in parentheses, not a tuple");
      shape = std::move(dims);
    } else {
      in.fail("unexpected key " + quoted_text(key));
    }
    if (!in.accept(',')) {
      in.expect('}', "after a value");
      break;
    }
  }
  in.skip_space();
  if (!in.at_end()) in.fail("text after the dictionary");
  if (!descr) throw std::runtime_error("malformed .npy header: no 'descr'");
  if (!fortran_order) throw std::runtime_error("malformed .npy header: no 'fortran_order'");
  if (!shape) throw std::runtime_error("malformed .npy header: no 'shape'");

  const NpyType type = dtype_of(*descr);
  if (shape->size() > 1) {
    const std::string dims = std::to_string(shape->size()) + "-D array (shape " + shape_text(*shape) + ")";
    if (*fortran_order) throw std::runtime_error("a Fortran-order " + dims + "; scene columns are 1-D");
    throw std::runtime_error("a " + dims + "; scene columns are 1-D");
  }
  const std::size_t count = shape->empty() ? 1 : shape->front();
  const std::size_t size = npy_type_size(type);
  if (count > (std::numeric_limits<std::size_t>::max() - prefix - dict.size()) / size) {
    throw std::runtime_error("an array of " + std::to_string(count) + " elements of " + std::to_string(size) +
                             " bytes is larger than memory can address");
  }
  return NpyHeader{type, count, prefix + dict.size()};
}

// ---------------------------------------------------------------------------
// Reading an archive
// ---------------------------------------------------------------------------
namespace {

constexpr std::uint32_t kLocalHeaderSignature = 0x04034b50;
constexpr std::uint32_t kCentralHeaderSignature = 0x02014b50;
constexpr std::uint32_t kEndSignature = 0x06054b50;
constexpr std::uint32_t kZip64EndSignature = 0x06064b50;
constexpr std::uint32_t kZip64LocatorSignature = 0x07064b50;
constexpr std::size_t kLocalHeaderSize = 30;
constexpr std::size_t kCentralHeaderSize = 46;
constexpr std::size_t kEndSize = 22;
constexpr std::size_t kZip64EndSize = 56;
constexpr std::size_t kZip64LocatorSize = 20;
constexpr std::uint16_t kZip64ExtraId = 0x0001;
constexpr std::uint32_t kZip32Max = 0xFFFFFFFF;
constexpr std::uint16_t kZip16Max = 0xFFFF;
constexpr std::string_view kNpySuffix = ".npy";

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
      throw member_error("member " + quoted_member + ": " + reason);
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

// ---------------------------------------------------------------------------
// Writing an archive
// ---------------------------------------------------------------------------
namespace {

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
    put16(local, kVersionNeeded);
    put16(local, member.flags);
    put16(local, 0);  // stored
    put16(local, kDosTime);
    put16(local, kDosDate);
    put32(local, member.crc);
    put32(local, kZip32Max);  // compressed size: in the ZIP64 block
    put32(local, kZip32Max);  // uncompressed size: in the ZIP64 block
    put16(local, static_cast<std::uint16_t>(member.name.size()));
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
    put16(tail, kVersionNeeded);
    put16(tail, member.flags);
    put16(tail, 0);  // stored
    put16(tail, kDosTime);
    put16(tail, kDosDate);
    put32(tail, member.crc);
    put32(tail, kZip32Max);  // compressed size
    put32(tail, kZip32Max);  // uncompressed size
    put16(tail, static_cast<std::uint16_t>(member.name.size()));
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
  write_archive(columns, [&](std::string_view bytes) { out.write(bytes); });
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
