// scene_error.cpp - SceneError (collide/io/scene_io.hpp): the message of a
// scene file that cannot be read or written, formed from its location
// ("bodies.csv:5: row 3, column 'm': ...").
#include "collide/io/scene_io.hpp"

#include <string>
#include <utility>

namespace collide {
namespace {

std::string located_message(const std::string& file, std::size_t line, std::size_t row, const std::string& column,
                            const std::string& reason) {
  std::string msg = file;
  if (line != 0) {
    // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive,
    // GCC bug 105329) about ":" + std::to_string(line) inlined here.
    msg += ':';
    msg += std::to_string(line);
  }
  msg += ": ";
  if (row != SceneError::kNoRow) {
    msg += "row " + std::to_string(row) + ", ";
  } else if (line != 0) {
    msg += "header, ";
  }
  if (!column.empty()) msg += "column '" + column + "': ";
  msg += reason;
  return msg;
}

}  // namespace

SceneError::SceneError(std::string file, std::size_t line, std::size_t row, std::string column, std::string reason)
    : std::runtime_error(located_message(file, line, row, column, reason)),
      file_(std::move(file)),
      line_(line),
      row_(row),
      column_(std::move(column)),
      reason_(std::move(reason)) {}

SceneError::SceneError(std::string file, std::string reason)
    : std::runtime_error(located_message(file, 0, kNoRow, std::string(), reason)),
      file_(std::move(file)),
      reason_(std::move(reason)) {}

SceneError::SceneError(std::string file, std::string reason, int os_error)
    : SceneError(std::move(file), std::move(reason)) {
  os_error_ = os_error;
}

}  // namespace collide
