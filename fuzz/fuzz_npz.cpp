// fuzz_npz.cpp - libFuzzer target: the .npz reader and the .npy header parser
// on arbitrary bytes.
//
// What it asserts, for any input:
// * NpzArchive::parse either returns or throws collide::SceneError naming
//   the file it was given, and parse_npy_header either returns or throws
//   std::runtime_error - no other exception, crash, UB, leak or hang
//   (ASan, UBSan and libFuzzer's -timeout / -rss_limit_mb catch the rest);
// * what parse accepts lies inside the input: every byte of every member's
//   data is read (summed), so ASan reports a member that points past it,
//   and the range is checked explicitly too;
// * an accepted archive written back with format_npz reads back to the same
//   members (names, types, counts, bytes), with every member's data aligned
//   to kNpzAlignment in the new bytes.
//
// The seeds in fuzz/corpus/npz/ are archives written by np.savez and by
// format_npz (with ZIP64 fields, a 0-D array, an empty array, an empty
// archive) and near-misses: a deflated member, a truncated archive, a
// big-endian dtype, a 2-D array.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"

namespace {

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_npz: %s\n", what);
  std::abort();
}

std::size_t data_bytes(const collide::NpzMember& m) { return m.count * collide::npy_type_size(m.type); }

void check_archive(std::string_view input) {
  const collide::NpzArchive archive = [&] {
    try {
      return collide::NpzArchive::parse(input, "fuzz.npz");
    } catch (const collide::SceneError& e) {
      if (e.file() != "fuzz.npz") fail("a SceneError that does not name the file");
      throw;
    }
  }();
  // Every byte of every member, read: ASan sees a member past the input.
  unsigned sum = 0;
  const auto* begin = reinterpret_cast<const std::byte*>(input.data());
  for (const collide::NpzMember& m : archive.members()) {
    const std::size_t n = data_bytes(m);
    if (n > 0 && (m.data < begin || m.data > begin + input.size() ||
                  n > static_cast<std::size_t>(begin + input.size() - m.data))) {
      fail("a member's data lies outside the input");
    }
    for (std::size_t i = 0; i < n; ++i) sum += static_cast<unsigned>(m.data[i]);
  }
  volatile unsigned sink = sum;
  (void)sink;

  // Written back, read back: the same members, aligned.
  std::vector<collide::NpzColumn> columns;
  for (const collide::NpzMember& m : archive.members()) columns.push_back({m.name, m.type, m.data, m.count});
  const std::string again = collide::format_npz(columns);
  const collide::NpzArchive reread = [&] {
    try {
      return collide::NpzArchive::parse(again, "again.npz");
    } catch (const collide::SceneError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      fail("the archive written from an accepted one is refused");
    }
  }();
  if (reread.members().size() != archive.members().size()) fail("a rewritten archive lost or gained members");
  for (std::size_t k = 0; k < reread.members().size(); ++k) {
    const collide::NpzMember& a = archive.members()[k];
    const collide::NpzMember& b = reread.members()[k];
    if (a.name != b.name || a.type != b.type || a.count != b.count) fail("a rewritten member differs");
    if (data_bytes(a) > 0 && std::memcmp(a.data, b.data, data_bytes(a)) != 0) fail("rewritten data differs");
    const auto offset = static_cast<std::size_t>(reinterpret_cast<const char*>(b.data) - again.data());
    if (offset % collide::kNpzAlignment != 0) fail("a written member's data is not aligned");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  try {
    check_archive(input);
  } catch (const collide::SceneError&) {
  }
  try {
    const collide::NpyHeader header = collide::parse_npy_header(input);
    if (header.header_bytes > size) fail("an .npy header longer than the input");
  } catch (const std::runtime_error&) {
  }
  return 0;
}
