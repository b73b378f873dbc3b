// collide/io/output_file.hpp - where a result file goes, and how it gets there.
//
// Design notes
// ------------
// * A regular file (or a path that does not exist yet) is written under a
//   hidden temporary name in the destination's directory and renamed onto
//   the destination by commit(): a failure, or an OutputFile destroyed
//   without commit, leaves the destination untouched, and a reader never
//   sees half a file. A missing directory (and its missing parents) is
//   created first, for every writer alike (`collide solve --out-bodies
//   new/ob.csv`, `collide gen --out new`, `collide.save("new/b.npz", ...)`);
//   it stays if the output is then not committed.
// * A path that exists and is not a regular file - a character device such
//   as /dev/null, a FIFO, a socket - is opened and written directly. Renaming
//   over it would replace the node itself (as root, `--out-impulses
//   /dev/null` turned /dev/null into a regular file for the whole machine;
//   a reader waiting on a FIFO never got the data). Such an output cannot be
//   atomic: what was written before a failure stays written.
// * "-" is the standard output, also written directly (and not closed); so
//   are /dev/stdout, /dev/fd/N and anything linking into /proc, whatever
//   they lead to.
// * A symbolic link to a regular file stays a link: the temporary is made
//   next to the file it leads to and renamed onto that file.
// * Opening a FIFO blocks until a reader opens it, as a shell redirection
//   does.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace collide {

/// The path that names the standard output.
inline constexpr std::string_view kStdoutPath = "-";

/// A result file: written under a temporary name next to `path` (its
/// directory created when missing) and renamed onto `path` by commit() when
/// `path` is a regular file or does not exist;
/// written directly when `path` is "-" (stdout) or an existing non-regular
/// file (device, FIFO, socket). Destroyed without commit, a renamed output
/// removes its temporary and leaves `path` as it was. Not copyable; movable.
class OutputFile {
 public:
  explicit OutputFile(std::string path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;

  void write(std::string_view bytes);
  /// Flushes and closes; a renamed output is then renamed onto its path.
  void commit();
  [[nodiscard]] const std::string& path() const { return path_; }
  /// True when the output is written in place (stdout, device, FIFO,
  /// socket): it cannot be undone, so write it after everything that can
  /// still fail.
  [[nodiscard]] bool direct() const { return temp_path_.empty(); }
  /// Writes `bytes` at byte `offset` of a renamed output (!direct()), from
  /// any thread, for ranges no other call writes; an output written this
  /// way takes no write(). Throws SceneError on a write error.
  void write_at(std::uint64_t offset, std::string_view bytes) const;

 private:
  void discard() noexcept;
  std::string path_;
  std::string dest_;       // what the temporary is renamed to: path_, or the file a link leads to
  std::string temp_path_;  // empty for a direct output
  std::FILE* file_ = nullptr;
  bool is_stdout_ = false;
};

}  // namespace collide
