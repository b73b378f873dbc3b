// npy_header.cpp - the .npy header of an archive's member: the element
// types (npy_type_size, npy_descr) and the parser of the header at the start
// of a member's bytes (parse_npy_header; collide/io/npz.hpp). The header the
// writer writes is npz_write.cpp's; the constants they share are
// npz_format.hpp's.
//
// Design notes
// ------------
// * The .npy header is a Python dict literal that NumPy reads with
//   ast.literal_eval. This reader accepts the part of that language a 1-D
//   column can be written in (quoted strings, True/False, tuples of
//   integers, the three keys in any order, any whitespace, trailing commas)
//   and names what it refuses rather than guessing.
#include "collide/io/npz.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "npz_format.hpp"

namespace collide {
namespace {

// The format's constants and helpers (npz_format.hpp).
using namespace detail::npz;

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
    if (pos_ >= text_.size() || (text_[pos_] != '\'' && text_[pos_] != '"')) {
      fail("expected a quoted " + std::string(what));
    }
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

}  // namespace collide
