// npz_format.hpp - what the .npy header parser (npy_header.cpp), the .npz
// reader (npz_read.cpp) and the .npz writer (npz_write.cpp) share (private
// to the library): the element types, the .npy magic, the ZIP records'
// signatures, fixed sizes and limits, little-endian loads and the quoting
// of the file's text in messages.
//
// Design notes
// ------------
// * One list of the format's constants for the reader and the writer, so
//   the bytes one writes are the bytes the other looks for. The design of
//   each side is in its own file.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "collide/io/npz.hpp"

namespace collide::detail::npz {

/// Every NpyType: the dtypes a column may have.
inline constexpr std::array<NpyType, 6> kAllTypes = {NpyType::f4, NpyType::f8, NpyType::u4,
                                                     NpyType::i4, NpyType::u8, NpyType::i8};

/// The first bytes of every .npy array.
inline constexpr std::string_view kNpyMagic = "\x93NUMPY";

// ZIP records: signatures, fixed sizes (before the variable-length fields),
// the ZIP64 extra block's id, the limits of the classic fields.
inline constexpr std::uint32_t kLocalHeaderSignature = 0x04034b50;
inline constexpr std::uint32_t kCentralHeaderSignature = 0x02014b50;
inline constexpr std::uint32_t kEndSignature = 0x06054b50;
inline constexpr std::uint32_t kZip64EndSignature = 0x06064b50;
inline constexpr std::uint32_t kZip64LocatorSignature = 0x07064b50;
inline constexpr std::size_t kLocalHeaderSize = 30;
inline constexpr std::size_t kCentralHeaderSize = 46;
inline constexpr std::size_t kEndSize = 22;
inline constexpr std::size_t kZip64EndSize = 56;
inline constexpr std::size_t kZip64LocatorSize = 20;
inline constexpr std::uint16_t kZip64ExtraId = 0x0001;
inline constexpr std::uint32_t kZip32Max = 0xFFFFFFFF;
inline constexpr std::uint16_t kZip16Max = 0xFFFF;
/// The suffix of a member's name: "<column>.npy".
inline constexpr std::string_view kNpySuffix = ".npy";

/// The text of a value as quoted in a message, shortened if long, with
/// control and non-ASCII bytes escaped (the text comes from the file).
inline std::string quoted_text(std::string_view text) {
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

/// The little-endian unsigned integer of `bytes` bytes at `p`.
inline std::uint64_t load_le(const char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

}  // namespace collide::detail::npz
