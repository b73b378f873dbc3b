// input_file.cpp - the bytes of an input file (FileBuffer, input_file.hpp)
// and read_file (collide/io/scene_io.hpp): a regular file mapped from the
// page cache, anything else read into a growing buffer.
#include "input_file.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "collide/io/scene_io.hpp"

namespace collide {
namespace detail {

FileBuffer::FileBuffer(const std::string& path) {
  const InputFile file(path);
  const int fd = file.fd();
  if (file.regular() && file.size() > 0) {
    size_ = file.size();
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (p != MAP_FAILED) {
      mapped_ = p;
      return;
    }
    size_ = 0;  // fall back to reading
  }
  std::size_t capacity = std::size_t(1) << 20;
  heap_.reset(new char[capacity]);
  for (;;) {
    const ssize_t got = ::read(fd, heap_.get() + size_, capacity - size_);
    if (got < 0) {
      const int err = errno;
      if (err == EINTR) continue;
      throw SceneError(path, std::string("read error: ") + std::strerror(err), err);
    }
    if (got == 0) break;
    size_ += static_cast<std::size_t>(got);
    if (size_ == capacity) {
      capacity *= 2;
      std::unique_ptr<char[]> bigger(new char[capacity]);
      std::memcpy(bigger.get(), heap_.get(), size_);
      heap_ = std::move(bigger);
    }
  }
}

FileBuffer::~FileBuffer() {
  if (mapped_ != nullptr) ::munmap(mapped_, size_);
}

}  // namespace detail

std::string read_file(const std::string& path) {
  const detail::FileBuffer buf(path);
  return std::string(buf.view());
}

}  // namespace collide
