// output_file.cpp - result files: renamed temporaries for regular files,
// direct writes for stdout, devices, FIFOs and sockets (the rules are in
// collide/io/output_file.hpp).
#include "collide/io/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>

#include "collide/io/scene_io.hpp"

namespace collide {
namespace {

/// What an existing `path` is: absent or regular (rename), a directory
/// (refused), or anything else (written in place). stat() follows symbolic
/// links, so a link to /dev/null is written in place too.
enum class Target { renamed, directory, direct };

Target classify(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Target::renamed;  // absent (or unreadable: the rename reports it)
  if (S_ISDIR(st.st_mode)) return Target::directory;
  return S_ISREG(st.st_mode) ? Target::renamed : Target::direct;
}

/// True for a path that names an open descriptor rather than a file:
/// /dev/stdout, /dev/fd/N, /proc/self/fd/N (directly or through symbolic
/// links into /proc). Renaming onto it would replace the link in /dev (or
/// fail in /proc), and the shell's redirection would never see the data, so
/// such a path is written in place even when it leads to a regular file.
bool names_a_descriptor(const std::string& path) {
  namespace fs = std::filesystem;
  auto in_proc = [](const std::string& p) { return p.rfind("/proc/", 0) == 0 || p.rfind("/dev/fd/", 0) == 0; };
  if (in_proc(path)) return true;
  fs::path p(path);
  std::error_code ec;
  for (int hop = 0; hop < 40 && fs::is_symlink(p, ec); ++hop) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return false;
    p = target.is_absolute() ? target : p.parent_path() / target;
    if (in_proc(p.string())) return true;
  }
  return false;
}

/// Where the temporary is renamed to: the file a symbolic link leads to (the
/// link itself stays a link), or the path itself.
std::string rename_target(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_symlink(path, ec)) return path;
  const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : resolved.string();
}

std::string errno_text(const char* what, int err) { return std::string(what) + ": " + std::strerror(err); }

/// Creates the directory `dir` of output `path` and its missing parents, as
/// `collide gen` creates its output directory; nothing for "" (the current
/// directory) or a directory that exists.
void create_directory(const std::string& path, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (dir.empty() || fs::is_directory(dir, ec)) return;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    const int err = ec ? ec.value() : ENOTDIR;
    throw SceneError(path, "cannot create directory '" + dir + "': " + std::strerror(err), err);
  }
}

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  if (path_ == kStdoutPath) {
    file_ = stdout;
    is_stdout_ = true;
    return;
  }
  switch (names_a_descriptor(path_) ? Target::direct : classify(path_)) {
    case Target::directory:
      throw SceneError(path_, "cannot write: is a directory", EISDIR);
    case Target::direct: {
      // No O_TRUNC or O_CREAT: the node exists and is not a file to replace.
      const int fd = ::open(path_.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
      if (fd < 0) {
        const int err = errno;
        throw SceneError(path_, errno_text("cannot open for writing", err), err);
      }
      file_ = ::fdopen(fd, "wb");
      if (file_ == nullptr) {
        const int err = errno;
        ::close(fd);
        throw SceneError(path_, errno_text("cannot open for writing", err), err);
      }
      return;
    }
    case Target::renamed:
      break;
  }
  dest_ = rename_target(path_);
  const std::filesystem::path dest(dest_);
  const std::string dir = dest.parent_path().string();
  create_directory(path_, dir);
  // Same directory as the destination, so that rename() is atomic and never
  // crosses a file system; hidden, so a crash leaves no plausible output.
  std::string templ = (dir.empty() ? std::string() : dir + "/") + "." + dest.filename().string() + ".tmp-XXXXXX";
  const int fd = ::mkstemp(templ.data());
  if (fd < 0) {
    const int err = errno;
    throw SceneError(
        path_,
        "cannot create a temporary file in '" + (dir.empty() ? std::string(".") : dir) + "': " + std::strerror(err),
        err);
  }
  temp_path_ = templ;
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    const int err = errno;
    ::close(fd);
    ::unlink(temp_path_.c_str());
    throw SceneError(path_, errno_text("cannot open a temporary file", err), err);
  }
}

OutputFile::~OutputFile() { discard(); }

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)),
      dest_(std::move(other.dest_)),
      temp_path_(std::move(other.temp_path_)),
      file_(std::exchange(other.file_, nullptr)),
      is_stdout_(other.is_stdout_) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    discard();
    path_ = std::move(other.path_);
    dest_ = std::move(other.dest_);
    temp_path_ = std::move(other.temp_path_);
    file_ = std::exchange(other.file_, nullptr);
    is_stdout_ = other.is_stdout_;
  }
  return *this;
}

void OutputFile::discard() noexcept {
  if (file_ == nullptr) return;
  if (is_stdout_) {
    std::fflush(file_);  // stdout stays open for the rest of the program
  } else {
    std::fclose(file_);
  }
  file_ = nullptr;
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
}

void OutputFile::write(std::string_view bytes) {
  if (file_ == nullptr) throw SceneError(path_, "write after commit");
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    const int err = errno;
    discard();
    throw SceneError(path_, errno_text("write error", err));
  }
}

void OutputFile::write_at(std::uint64_t offset, std::string_view bytes) const {
  if (file_ == nullptr || temp_path_.empty()) throw SceneError(path_, "positional write to a direct or closed output");
  const int fd = ::fileno(file_);
  while (!bytes.empty()) {
    const ssize_t n = ::pwrite(fd, bytes.data(), bytes.size(), static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw SceneError(path_, errno_text("write error", n < 0 ? errno : EIO));
    bytes.remove_prefix(static_cast<std::size_t>(n));
    offset += static_cast<std::uint64_t>(n);
  }
}

void OutputFile::commit() {
  if (file_ == nullptr) throw SceneError(path_, "commit without an open file");
  if (!temp_path_.empty()) {
    // mkstemp creates 0600; give the file the mode a plain fopen would.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(::fileno(file_), 0666 & ~mask);
  }
  const bool flushed = std::fflush(file_) == 0 && !std::ferror(file_);
  const int err = errno;
  const bool closed = is_stdout_ || std::fclose(file_) == 0;
  const int close_err = errno;
  file_ = nullptr;
  if (!flushed || !closed) {
    if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
    throw SceneError(path_, errno_text("write error", flushed ? close_err : err));
  }
  if (temp_path_.empty()) return;
  if (std::rename(temp_path_.c_str(), dest_.c_str()) != 0) {
    const int rerr = errno;
    ::unlink(temp_path_.c_str());
    throw SceneError(path_, errno_text("cannot rename the temporary file into place", rerr));
  }
}

}  // namespace collide
