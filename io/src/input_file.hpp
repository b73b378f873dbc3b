// input_file.hpp - input files: a file opened for reading, with the scene
// readers' messages for what the operating system refuses, and the bytes of
// a whole input file (private to the library).
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

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

/// The bytes of an input file (input_file.cpp), for the CSV readers. Regular
/// files are mapped (MAP_POPULATE): the parser reads the page cache
/// directly, where reading into a fresh buffer would first have to fault in
/// and zero as much anonymous memory as the file is large, which costs more
/// than parsing on a VM. Pipes and devices are read into a growing buffer.
/// (A mapped file truncated by another process while it is parsed raises
/// SIGBUS; inputs are not expected to change under the tool.)
class FileBuffer {
 public:
  explicit FileBuffer(const std::string& path);
  ~FileBuffer();
  FileBuffer(const FileBuffer&) = delete;
  FileBuffer& operator=(const FileBuffer&) = delete;

  [[nodiscard]] std::string_view view() const {
    return {mapped_ != nullptr ? static_cast<const char*>(mapped_) : heap_.get(), size_};
  }

 private:
  void* mapped_ = nullptr;
  std::unique_ptr<char[]> heap_;
  std::size_t size_ = 0;
};

}  // namespace collide::detail
