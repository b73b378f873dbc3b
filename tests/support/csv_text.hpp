// support/csv_text.hpp - scene-file text for the reader's tests.
#pragma once

#include <string>

namespace collide::test {

/// The text with a blank after every comma: sends every row down the
/// reader's careful path (the fast path takes plain numbers only).
inline std::string with_blanks(const std::string& text) {
  std::string out;
  for (const char c : text) {
    out += c;
    if (c == ',') out += ' ';
  }
  return out;
}

}  // namespace collide::test
