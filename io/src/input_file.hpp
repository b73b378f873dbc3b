// input_file.hpp - a file opened for reading, with the scene readers'
// messages for what the operating system refuses (private to the library).
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "collide/io/scene_io.hpp"

namespace collide::detail {

/// An open descriptor and what fstat said of it; closed when destroyed.
/// Refuses, as a SceneError with the errno value, a path that cannot be
/// opened or stat'ed, and a directory ("cannot read: is a directory"), so
/// that the CSV and the binary readers say the same thing.
class InputFile {
 public:
  explicit InputFile(const std::string& path) : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
    if (fd_ < 0) {
      const int err = errno;
      throw SceneError(path, std::string("cannot open: ") + std::strerror(err), err);
    }
    if (::fstat(fd_, &stat_) != 0) {
      const int err = errno;
      ::close(fd_);
      throw SceneError(path, std::string("cannot stat: ") + std::strerror(err), err);
    }
    if (S_ISDIR(stat_.st_mode)) {
      ::close(fd_);
      throw SceneError(path, "cannot read: is a directory", EISDIR);
    }
  }
  ~InputFile() { ::close(fd_); }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  [[nodiscard]] int fd() const { return fd_; }
  [[nodiscard]] bool regular() const { return S_ISREG(stat_.st_mode); }
  [[nodiscard]] std::size_t size() const { return static_cast<std::size_t>(stat_.st_size); }

 private:
  int fd_;
  struct stat stat_ {};
};

}  // namespace collide::detail
