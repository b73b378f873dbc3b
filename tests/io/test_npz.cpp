// test_npz.cpp - the .npy header parser (npy_header.cpp), the archive reader
// (npz_read.cpp) and the writer (npz_write.cpp).
//
// The archives the refusal tests need (a deflated member, a local header
// whose extra field differs from the central entry's, ZIP64 fields, an end
// record behind a comment...) are built here byte by byte by ZipBuilder, so
// each test states the one thing that is wrong. NumPy itself is the judge of
// compatibility: the last tests run Python to load what the writer wrote
// (and compare it with numpy.lib.format.write_array's bytes) and to write
// archives the reader must accept or refuse.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "collide/io/npz.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene_io.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using collide::NpyType;
using collide::NpzArchive;
using collide::NpzColumn;
using collide::NpzMember;
using collide::SceneError;

namespace {

// ---------------------------------------------------------------------------
// Sample columns: one formula per type, which the Python side repeats.
// ---------------------------------------------------------------------------
std::vector<float> sample_f4(std::size_t n) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<float>(i) * 0.25f - 7.0f;
  return v;
}
std::vector<double> sample_f8(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<double>(i) * 0.5 - 1e6;
  return v;
}
std::vector<std::uint32_t> sample_u4(std::size_t n) {
  std::vector<std::uint32_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint32_t>(i * 2654435761u);
  return v;
}
std::vector<std::int32_t> sample_i4(std::size_t n) {
  std::vector<std::int32_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = 5 - 3 * static_cast<std::int32_t>(i);
  return v;
}
std::vector<std::uint64_t> sample_u8(std::size_t n) {
  std::vector<std::uint64_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL;
  return v;
}
std::vector<std::int64_t> sample_i8(std::size_t n) {
  std::vector<std::int64_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = 12345 - static_cast<std::int64_t>(i) * (std::int64_t(1) << 40);
  return v;
}

/// One column of every type, with sizes that cover the empty array, a single
/// element, and a column over the writer's 1 MiB CRC chunk.
struct SampleColumns {
  std::vector<float> f4 = sample_f4(1000);
  std::vector<double> f8 = sample_f8(300000);
  std::vector<std::uint32_t> u4 = sample_u4(7);
  std::vector<std::int32_t> i4 = sample_i4(1);
  std::vector<std::uint64_t> u8 = sample_u8(0);
  std::vector<std::int64_t> i8 = sample_i8(33);

  [[nodiscard]] std::vector<NpzColumn> columns() const {
    return {{"m", NpyType::f4, f4.data(), f4.size()},     {"big_f8", NpyType::f8, f8.data(), f8.size()},
            {"ids", NpyType::u4, u4.data(), u4.size()},   {"one", NpyType::i4, i4.data(), i4.size()},
            {"empty", NpyType::u8, u8.data(), u8.size()}, {"i8", NpyType::i8, i8.data(), i8.size()}};
  }
};

std::string bytes_of(const void* data, std::size_t size) {
  return size == 0 ? std::string() : std::string(static_cast<const char*>(data), size);
}

template <class T>
void expect_member(const NpzArchive& archive, std::string_view name, NpyType type, const std::vector<T>& values) {
  const NpzMember* m = archive.find(name);
  ASSERT_NE(m, nullptr) << name;
  EXPECT_EQ(m->type, type) << name;
  ASSERT_EQ(m->count, values.size()) << name;
  EXPECT_EQ(bytes_of(m->data, m->count * sizeof(T)), bytes_of(values.data(), values.size() * sizeof(T))) << name;
}

void expect_samples(const NpzArchive& archive, const SampleColumns& s) {
  expect_member(archive, "m", NpyType::f4, s.f4);
  expect_member(archive, "big_f8", NpyType::f8, s.f8);
  expect_member(archive, "ids", NpyType::u4, s.u4);
  expect_member(archive, "one", NpyType::i4, s.i4);
  expect_member(archive, "empty", NpyType::u8, s.u8);
  expect_member(archive, "i8", NpyType::i8, s.i8);
}

/// Whether `text` contains `part`, showing both when it does not.
::testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

template <class F>
SceneError expect_scene_error(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a SceneError: " << e.what();
    return SceneError("none", "none");
  }
  ADD_FAILURE() << "no SceneError thrown";
  return SceneError("none", "none");
}

template <class F>
std::string npy_error(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return {};
}

// ---------------------------------------------------------------------------
// Hand-made .npy and ZIP bytes
// ---------------------------------------------------------------------------
void put16(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 2; ++i) s += static_cast<char>((v >> (8 * i)) & 0xFF);
}
void put32(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 4; ++i) s += static_cast<char>((v >> (8 * i)) & 0xFF);
}
void put64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s += static_cast<char>((v >> (8 * i)) & 0xFF);
}

/// .npy bytes with the dictionary text as given (newline included by the
/// caller), in format `major`.0, followed by `data`.
std::string npy_with_dict(const std::string& dict, int major = 1, const std::string& data = "") {
  std::string s = "\x93NUMPY";
  s += static_cast<char>(major);
  s += '\0';
  if (major == 1) {
    put16(s, static_cast<std::uint32_t>(dict.size()));
  } else {
    put32(s, dict.size());
  }
  return s + dict + data;
}

template <class T>
std::string npy_array(const std::string& descr, const std::vector<T>& values) {
  return npy_with_dict(
      "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + std::to_string(values.size()) + ",), }\n", 1,
      bytes_of(values.data(), values.size() * sizeof(T)));
}

/// One member of a hand-made archive. By default a stored, unencrypted
/// member whose local and central headers agree.
struct Entry {
  std::string name;
  std::string content;
  std::uint16_t method = 0;
  std::uint16_t flags = 0;
  std::optional<std::uint64_t> compressed;    // default: content.size()
  std::optional<std::uint64_t> uncompressed;  // default: content.size()
  std::optional<std::string> local_name;      // default: name
  std::string local_extra;
  std::string central_extra;                  // blocks appended after the ZIP64 block, if any
  bool zip64_sizes = false;                   // central sizes 0xFFFFFFFF, values in the ZIP64 block
  bool zip64_offset = false;                  // central offset 0xFFFFFFFF, value in the ZIP64 block
  std::optional<std::uint64_t> local_offset;  // default: where the local header is
};

struct Archive {
  std::vector<Entry> entries;
  bool zip64_end = false;  // ZIP64 end record and locator, sentinels in the end record
  std::string comment;
  std::optional<std::uint64_t> claimed_entries;
};

std::string build_zip(const Archive& a) {
  std::string out;
  std::vector<std::uint64_t> offsets;
  for (const Entry& e : a.entries) {
    offsets.push_back(out.size());
    const std::string local_name = e.local_name.value_or(e.name);
    put32(out, 0x04034b50);
    put16(out, 20);
    put16(out, e.flags);
    put16(out, e.method);
    put16(out, 0);
    put16(out, 0x21);
    put32(out, 0);  // CRC: not checked by the reader
    put32(out, e.compressed.value_or(e.content.size()));
    put32(out, e.uncompressed.value_or(e.content.size()));
    put16(out, static_cast<std::uint32_t>(local_name.size()));
    put16(out, static_cast<std::uint32_t>(e.local_extra.size()));
    out += local_name + e.local_extra + e.content;
  }
  const std::uint64_t cd_offset = out.size();
  for (std::size_t k = 0; k < a.entries.size(); ++k) {
    const Entry& e = a.entries[k];
    const std::uint64_t compressed = e.compressed.value_or(e.content.size());
    const std::uint64_t uncompressed = e.uncompressed.value_or(e.content.size());
    const std::uint64_t offset = e.local_offset.value_or(offsets[k]);
    std::string extra;
    if (e.zip64_sizes || e.zip64_offset) {
      std::string data;
      if (e.zip64_sizes) {
        put64(data, uncompressed);
        put64(data, compressed);
      }
      if (e.zip64_offset) put64(data, offset);
      put16(extra, 1);
      put16(extra, static_cast<std::uint32_t>(data.size()));
      extra += data;
    }
    extra += e.central_extra;
    put32(out, 0x02014b50);
    put16(out, 0x0314);
    put16(out, 20);
    put16(out, e.flags);
    put16(out, e.method);
    put16(out, 0);
    put16(out, 0x21);
    put32(out, 0);
    put32(out, e.zip64_sizes ? 0xFFFFFFFF : compressed);
    put32(out, e.zip64_sizes ? 0xFFFFFFFF : uncompressed);
    put16(out, static_cast<std::uint32_t>(e.name.size()));
    put16(out, static_cast<std::uint32_t>(extra.size()));
    put16(out, 0);
    put16(out, 0);
    put16(out, 0);
    put32(out, 0);
    put32(out, e.zip64_offset ? 0xFFFFFFFF : offset);
    out += e.name + extra;
  }
  const std::uint64_t cd_size = out.size() - cd_offset;
  const std::uint64_t entries = a.claimed_entries.value_or(a.entries.size());
  if (a.zip64_end) {
    const std::uint64_t zip64_at = out.size();
    put32(out, 0x06064b50);
    put64(out, 44);
    put16(out, 45);
    put16(out, 45);
    put32(out, 0);
    put32(out, 0);
    put64(out, entries);
    put64(out, entries);
    put64(out, cd_size);
    put64(out, cd_offset);
    put32(out, 0x07064b50);
    put32(out, 0);
    put64(out, zip64_at);
    put32(out, 1);
  }
  put32(out, 0x06054b50);
  put16(out, 0);
  put16(out, 0);
  put16(out, a.zip64_end ? 0xFFFF : entries);
  put16(out, a.zip64_end ? 0xFFFF : entries);
  put32(out, a.zip64_end ? 0xFFFFFFFF : cd_size);
  put32(out, a.zip64_end ? 0xFFFFFFFF : cd_offset);
  put16(out, static_cast<std::uint32_t>(a.comment.size()));
  return out + a.comment;
}

const std::vector<double> kThree = {1.5, -2.0, 4.25};

Entry entry(std::string name, std::string content) {
  Entry e;
  e.name = std::move(name);
  e.content = std::move(content);
  return e;
}

Entry good_entry(const std::string& name = "m.npy") { return entry(name, npy_array("<f8", kThree)); }

/// parse() of `archive`, expected to fail for member `column`; the message.
std::string member_refusal(const Archive& archive, const std::string& column) {
  const std::string bytes = build_zip(archive);
  const SceneError e = expect_scene_error([&] { (void)NpzArchive::parse(bytes, "t.npz"); });
  EXPECT_EQ(e.file(), "t.npz");
  EXPECT_EQ(e.column(), column) << e.what();
  EXPECT_EQ(e.os_error(), 0);
  EXPECT_TRUE(contains(std::string(e.what()), "t.npz: column '" + column + "': "));
  return e.what();
}

/// parse() of `bytes`, expected to fail for the whole file; the message.
std::string file_refusal(const std::string& bytes) {
  const SceneError e = expect_scene_error([&] { (void)NpzArchive::parse(bytes, "t.npz"); });
  EXPECT_EQ(e.file(), "t.npz");
  EXPECT_TRUE(e.column().empty()) << e.what();
  return e.what();
}

// ---------------------------------------------------------------------------
// The .npy header
// ---------------------------------------------------------------------------
TEST(NpyHeader, TypesAndSizes) {
  EXPECT_EQ(collide::npy_type_size(NpyType::f4), 4u);
  EXPECT_EQ(collide::npy_type_size(NpyType::f8), 8u);
  EXPECT_EQ(collide::npy_type_size(NpyType::u4), 4u);
  EXPECT_EQ(collide::npy_type_size(NpyType::i4), 4u);
  EXPECT_EQ(collide::npy_type_size(NpyType::u8), 8u);
  EXPECT_EQ(collide::npy_type_size(NpyType::i8), 8u);
  EXPECT_EQ(collide::npy_descr(NpyType::f4), "<f4");
  EXPECT_EQ(collide::npy_descr(NpyType::i8), "<i8");
}

TEST(NpyHeader, ParsesWhatNumPyWrites) {
  // numpy.lib.format.write_array's header for np.zeros(3, '<f4').
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }";
  dict.append(118 - dict.size() - 1, ' ');
  dict += '\n';
  const std::string npy = npy_with_dict(dict);
  ASSERT_EQ(npy.size(), 128u);
  const collide::NpyHeader h = collide::parse_npy_header(npy);
  EXPECT_EQ(h.type, NpyType::f4);
  EXPECT_EQ(h.count, 3u);
  EXPECT_EQ(h.header_bytes, 128u);
}

TEST(NpyHeader, VersionsOrderSpacingAndQuotes) {
  for (const int major : {1, 2, 3}) {
    const std::string dict = "{ \"shape\" :(12 ,) ,'fortran_order':True,\t'descr':'<i8'}\n";
    const std::string npy = npy_with_dict(dict, major);
    const collide::NpyHeader h = collide::parse_npy_header(npy);
    EXPECT_EQ(h.type, NpyType::i8);
    EXPECT_EQ(h.count, 12u);  // Fortran order means nothing in 1-D
    EXPECT_EQ(h.header_bytes, (major == 1 ? 10u : 12u) + dict.size());
  }
  const collide::NpyHeader scalar =
      collide::parse_npy_header(npy_with_dict("{'descr': '<u4', 'fortran_order': False, 'shape': (), }\n"));
  EXPECT_EQ(scalar.type, NpyType::u4);
  EXPECT_EQ(scalar.count, 1u);  // a 0-D array holds one element
  const collide::NpyHeader empty =
      collide::parse_npy_header(npy_with_dict("{'descr': '<i4', 'fortran_order': False, 'shape': (0,)}  \n"));
  EXPECT_EQ(empty.count, 0u);
  // The header is read from `bytes` alone; what follows does not matter.
  const std::string with_data = npy_with_dict("{'descr':'<f8','fortran_order':False,'shape':(+2,),}\n") + "xxxx";
  EXPECT_EQ(collide::parse_npy_header(with_data).count, 2u);
}

TEST(NpyHeader, RefusesWithTheReason) {
  const auto refuse = [](const std::string& bytes) { return npy_error([&] { collide::parse_npy_header(bytes); }); };
  const auto dict = [](const std::string& descr, const std::string& shape, const std::string& fortran = "False") {
    return npy_with_dict("{'descr': " + descr + ", 'fortran_order': " + fortran + ", 'shape': " + shape + ", }\n");
  };
  EXPECT_TRUE(contains(refuse(""), "truncated .npy header: 0 bytes"));
  EXPECT_TRUE(contains(refuse("PK\x03\x04 not numpy"), "bad magic"));
  EXPECT_TRUE(contains(refuse("\x93NUM"), "truncated"));
  EXPECT_TRUE(contains(refuse("\x93NUMPY\x01"), "truncated"));
  EXPECT_TRUE(contains(refuse(std::string("\x93NUMPY\x02\x00\x10\x00", 10)), "truncated"));
  EXPECT_TRUE(contains(refuse(std::string("\x93NUMPY\x04\x00\x10\x00", 10)), "unsupported .npy format version 4.0"));
  EXPECT_TRUE(contains(refuse(std::string("\x93NUMPY\x01\x01\x10\x00", 10)), "unsupported .npy format version 1.1"));
  std::string cut = dict("'<f4'", "(3,)");
  cut.resize(cut.size() - 1);
  EXPECT_TRUE(contains(refuse(cut), "truncated .npy header"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4', 'fortran_order': False, 'shape': (3,)}")),
                       "does not end with a newline"));
  EXPECT_TRUE(contains(refuse(dict("'>f4'", "(3,)")), "dtype '>f4' is big-endian; collide reads little-endian arrays"));
  EXPECT_TRUE(contains(refuse(dict("'>i8'", "(3,)")), "big-endian"));
  EXPECT_TRUE(contains(refuse(dict("'|O'", "(3,)")), "dtype '|O' (Python objects) is not supported"));
  EXPECT_TRUE(contains(refuse(dict("'<f2'", "(3,)")), "dtype '<f2' is not supported"));
  EXPECT_TRUE(contains(refuse(dict("'|u1'", "(3,)")), "dtype '|u1' is not supported"));
  EXPECT_TRUE(contains(refuse(dict("'=f8'", "(3,)")), "dtype '=f8' is not supported"));
  EXPECT_TRUE(contains(refuse(dict("[('x', '<f4')]", "(3,)")), "structured dtype"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(2, 3)")), "a 2-D array (shape (2, 3)); scene columns are 1-D"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(2, 3, 4)")), "a 3-D array"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(2, 3)", "True")), "a Fortran-order 2-D array"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(-1,)")), "negative dimension -1"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(99999999999999999999999,)")), "too large"));
  EXPECT_TRUE(contains(refuse(dict("'<f8'", "(4611686018427387904,)")), "larger than memory can address"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(3)")), "not a tuple"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "[3]")), "'shape' must be a tuple"));
  EXPECT_TRUE(contains(refuse(dict("'<f4'", "(3,)", "1")), "not True or False"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4', 'shape': (3,), }\n")), "no 'fortran_order'"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'fortran_order': False, 'shape': (3,), }\n")), "no 'descr'"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4', 'fortran_order': False}\n")), "no 'shape'"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4', 'fortran_order': False, 'shape': (3,), 'x': 1}\n")),
                       "unexpected key 'x'"));
  EXPECT_TRUE(
      contains(refuse(npy_with_dict("{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (3,)}\n")),
               "'descr' given twice"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4', 'fortran_order': False, 'shape': (3,)} x\n")),
                       "text after the dictionary"));
  EXPECT_TRUE(contains(refuse(npy_with_dict("{'descr': '<f4\n")), "unterminated"));
}

// Every prefix of a header, and every header with one byte changed, is
// parsed or refused with std::runtime_error, never read past.
TEST(NpyHeader, AnyCorruptionIsAnError) {
  const std::string good = npy_array("<f8", kThree);
  for (std::size_t n = 0; n < good.size(); ++n) {
    const std::string prefix = good.substr(0, n);
    try {
      (void)collide::parse_npy_header(prefix);
    } catch (const std::runtime_error&) {
    }
  }
  for (std::size_t i = 0; i < good.size() - kThree.size() * 8; ++i) {
    for (const int delta : {1, 0x40, 0x80}) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] + delta);
      try {
        const collide::NpyHeader h = collide::parse_npy_header(bad);
        EXPECT_LE(h.header_bytes, bad.size());
      } catch (const std::runtime_error&) {
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------
TEST(NpzWrite, RoundTripOfEveryType) {
  const SampleColumns s;
  const std::string bytes = collide::format_npz(s.columns());
  const NpzArchive archive = NpzArchive::parse(bytes, "mem.npz");
  ASSERT_EQ(archive.members().size(), 6u);
  const std::vector<std::string> order = {"m", "big_f8", "ids", "one", "empty", "i8"};
  for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(archive.members()[k].name, order[k]);
  expect_samples(archive, s);
  EXPECT_EQ(archive.find("nope"), nullptr);
  EXPECT_EQ(archive.file_name(), "mem.npz");
  EXPECT_EQ(archive.bytes().data(), bytes.data());
}

TEST(NpzWrite, EveryMembersDataIsAligned) {
  const SampleColumns s;
  // Names of every length modulo 64 shift the local headers by every amount.
  std::vector<std::string> names;
  std::vector<NpzColumn> columns;
  for (std::size_t len = 1; len <= 70; ++len) names.push_back(std::string(len, static_cast<char>('a' + len % 26)));
  for (std::size_t k = 0; k < names.size(); ++k) {
    names[k] += std::to_string(k);
    columns.push_back({names[k], NpyType::f4, s.f4.data(), k % 5});
  }
  const std::string bytes = collide::format_npz(columns);
  const NpzArchive archive = NpzArchive::parse(bytes, "mem.npz");
  ASSERT_EQ(archive.members().size(), columns.size());
  for (const NpzMember& m : archive.members()) {
    const auto offset = static_cast<std::size_t>(reinterpret_cast<const char*>(m.data) - bytes.data());
    EXPECT_EQ(offset % collide::kNpzAlignment, 0u) << m.name;
  }
}

TEST(NpzWrite, SameColumnsSameBytes) {
  const SampleColumns s;
  const std::string a = collide::format_npz(s.columns());
  const SampleColumns t;  // other buffers, same values
  const std::string b = collide::format_npz(t.columns());
  EXPECT_EQ(a, b);
  // The .npy header of a 1-D array, exactly as NumPy writes it.
  const std::vector<NpzColumn> one = {{"x", NpyType::f4, s.f4.data(), 3}};
  const std::string bytes = collide::format_npz(one);
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }";
  dict.append(117 - dict.size(), ' ');
  dict += '\n';
  const std::string npy = npy_with_dict(dict);
  EXPECT_NE(bytes.find(npy), std::string::npos);
  EXPECT_EQ(bytes.find(npy) % collide::kNpzAlignment, 0u);
}

TEST(NpzWrite, EmptyArchiveIsTheBareEndRecord) {
  const std::string bytes = collide::format_npz({});
  EXPECT_EQ(bytes, std::string("PK\x05\x06", 4) + std::string(18, '\0'));
  EXPECT_TRUE(NpzArchive::parse(bytes, "e.npz").members().empty());
}

TEST(NpzWrite, EveryFieldIsZip64) {
  const std::vector<float> v = sample_f4(5);
  const std::string bytes = collide::format_npz({{"x", NpyType::f4, v.data(), v.size()}});
  const std::size_t central = bytes.find("PK\x01\x02");
  ASSERT_NE(central, std::string::npos);
  EXPECT_EQ(bytes.substr(central + 20, 8), std::string(8, '\xFF'));  // sizes
  EXPECT_EQ(bytes.substr(central + 42, 4), std::string(4, '\xFF'));  // local header offset
  EXPECT_NE(bytes.find("PK\x06\x06"), std::string::npos);
  EXPECT_NE(bytes.find("PK\x06\x07"), std::string::npos);
}

TEST(NpzWrite, RefusesBadColumns) {
  const std::vector<float> v = sample_f4(3);
  EXPECT_THROW((void)collide::format_npz({{"", NpyType::f4, v.data(), 3}}), std::invalid_argument);
  EXPECT_THROW((void)collide::format_npz({{"a", NpyType::f4, v.data(), 3}, {"a", NpyType::f4, v.data(), 3}}),
               std::invalid_argument);
  EXPECT_THROW((void)collide::format_npz({{"a", NpyType::f4, nullptr, 3}}), std::invalid_argument);
  EXPECT_NO_THROW((void)collide::format_npz({{"a", NpyType::f4, nullptr, 0}}));
}

class NpzFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(COLLIDE_TEST_TMP) / ("npz_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write_text(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  fs::path dir_;
};

TEST_F(NpzFileTest, WriteNpzIsFormatNpzAndMapsAligned) {
  const SampleColumns s;
  {
    collide::OutputFile out(path("s.npz"));
    collide::write_npz(out, s.columns());
    out.commit();
  }
  EXPECT_EQ(collide::read_file(path("s.npz")), collide::format_npz(s.columns()));
  const NpzArchive archive = NpzArchive::map(path("s.npz"));
  expect_samples(archive, s);
  for (const NpzMember& m : archive.members()) {
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.data) % collide::kNpzAlignment, 0u) << m.name;
  }
}

// A file is written at offsets, members in 8 MiB slices on every thread
// (npz_write.cpp): members of several slices, one ending mid-slice, an
// empty one between them, give format_npz's bytes.
TEST_F(NpzFileTest, WriteNpzOfMembersOfManySlicesIsFormatNpz) {
  std::vector<float> f(5'000'003);
  std::vector<double> d(3'000'001);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = static_cast<float>(i) * 0.5f;
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = static_cast<double>(i) * 0.25;
  const std::vector<NpzColumn> columns = {{"f", NpyType::f4, f.data(), f.size()},
                                          {"none", NpyType::f4, f.data(), 0},
                                          {"d", NpyType::f8, d.data(), d.size()}};
  {
    collide::OutputFile out(path("big.npz"));
    collide::write_npz(out, columns);
    out.commit();
  }
  EXPECT_TRUE(collide::read_file(path("big.npz")) == collide::format_npz(columns));
}

TEST_F(NpzFileTest, MoveKeepsTheMapping) {
  const SampleColumns s;
  write_text("s.npz", collide::format_npz(s.columns()));
  NpzArchive a = NpzArchive::map(path("s.npz"));
  const std::byte* data = a.find("big_f8")->data;
  NpzArchive b(std::move(a));
  EXPECT_EQ(b.find("big_f8")->data, data);
  expect_samples(b, s);
  NpzArchive c = NpzArchive::parse(collide::format_npz({}), "e.npz");
  c = std::move(b);  // c's old archive had no mapping; b's moves in
  expect_samples(c, s);
  c = NpzArchive::map(path("s.npz"));  // a mapped archive replaced by another
  expect_samples(c, s);
}

TEST_F(NpzFileTest, OperatingSystemErrors) {
  const SceneError missing = expect_scene_error([&] { (void)NpzArchive::map(path("none.npz")); });
  EXPECT_EQ(missing.os_error(), ENOENT);
  EXPECT_EQ(missing.file(), path("none.npz"));
  const SceneError dir = expect_scene_error([&] { (void)NpzArchive::map(dir_.string()); });
  EXPECT_EQ(dir.os_error(), EISDIR);
  EXPECT_TRUE(contains(std::string(dir.what()), "is a directory"));
  write_text("empty.npz", "");
  const SceneError empty = expect_scene_error([&] { (void)NpzArchive::map(path("empty.npz")); });
  EXPECT_EQ(empty.os_error(), 0);
  EXPECT_TRUE(contains(std::string(empty.what()), "empty file, not an .npz archive"));
  write_text("text.npz", "m,Ix\n1,2\n");
  const SceneError text = expect_scene_error([&] { (void)NpzArchive::map(path("text.npz")); });
  EXPECT_TRUE(contains(std::string(text.what()), "not an .npz archive"));
}

// A pipe cannot be mapped: it is read into memory the archive owns (here
// more than the first 1 MiB buffer).
TEST_F(NpzFileTest, ReadsAPipe) {
  const SampleColumns s;
  const std::string bytes = collide::format_npz(s.columns());
  ASSERT_GT(bytes.size(), std::size_t(1) << 20);
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  std::thread writer([&] {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fds[1], bytes.data() + done, bytes.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    ::close(fds[1]);
  });
  const std::string fd_path = "/dev/fd/" + std::to_string(fds[0]);
  std::optional<NpzArchive> archive;
  try {
    archive.emplace(NpzArchive::map(fd_path));
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what();
  }
  writer.join();
  ::close(fds[0]);
  ASSERT_TRUE(archive.has_value());
  expect_samples(*archive, s);
  for (const NpzMember& m : archive->members()) {
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(m.data) % collide::kNpzAlignment, 0u) << m.name;
  }
}

// ---------------------------------------------------------------------------
// Reading hand-made archives
// ---------------------------------------------------------------------------
TEST(NpzRead, PlainArchive) {
  const std::vector<std::int32_t> ids = {7, -8, 9};
  Archive a;
  a.entries = {good_entry("q.npy"), entry("ids.npy", npy_array("<i4", ids))};
  const std::string bytes = build_zip(a);
  const NpzArchive archive = NpzArchive::parse(bytes, "t.npz");
  ASSERT_EQ(archive.members().size(), 2u);
  EXPECT_EQ(archive.members()[0].name, "q");
  EXPECT_EQ(archive.members()[1].name, "ids");
  expect_member(archive, "q", NpyType::f8, kThree);
  expect_member(archive, "ids", NpyType::i4, ids);
}

TEST(NpzRead, LocalExtraFieldDiffersFromTheCentralOne) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].local_extra = std::string("\x34\x12\x05\x00", 4) + "abcde";  // a 5-byte block of id 0x1234
  const std::string bytes = build_zip(a);
  expect_member(NpzArchive::parse(bytes, "t.npz"), "m", NpyType::f8, kThree);
}

TEST(NpzRead, Zip64FieldsInTheCentralDirectory) {
  // All three fields 0xFFFFFFFF, only the sizes, only the offset: the ZIP64
  // block holds exactly the ones that are, in order.
  for (const auto& [sizes, offset] : {std::pair{true, true}, std::pair{true, false}, std::pair{false, true}}) {
    Archive a;
    a.entries = {good_entry("a.npy"), good_entry("b.npy")};
    for (Entry& e : a.entries) {
      e.zip64_sizes = sizes;
      e.zip64_offset = offset;
      e.central_extra = std::string("\x55\x54\x05\x00\x01\x00\x00\x00\x00", 9);  // a timestamp block after it
    }
    a.zip64_end = true;
    const std::string bytes = build_zip(a);
    const NpzArchive archive = NpzArchive::parse(bytes, "t.npz");
    expect_member(archive, "a", NpyType::f8, kThree);
    expect_member(archive, "b", NpyType::f8, kThree);
  }
}

TEST(NpzRead, EndRecordBehindAComment) {
  Archive a;
  a.entries = {good_entry()};
  a.comment = std::string("a comment with PK\x05\x06 inside");
  expect_member(NpzArchive::parse(build_zip(a), "t.npz"), "m", NpyType::f8, kThree);
  a.comment = std::string(65535, 'c');
  expect_member(NpzArchive::parse(build_zip(a), "t.npz"), "m", NpyType::f8, kThree);
}

TEST(NpzRead, RefusesADeflatedMember) {
  Archive a;
  a.entries = {good_entry(), good_entry("v.npy")};
  a.entries[1].method = 8;
  const std::string msg = member_refusal(a, "v");
  EXPECT_TRUE(contains(msg, "member 'v.npy' is compressed (deflate)"));
  EXPECT_TRUE(contains(msg, "scene files must be saved with np.savez, not np.savez_compressed"));
}

TEST(NpzRead, RefusesAnEncryptedMember) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].flags = 1;
  EXPECT_TRUE(contains(member_refusal(a, "m"), "member 'm.npy' is encrypted"));
}

TEST(NpzRead, RefusesAMemberThatIsNotNpy) {
  Archive a;
  a.entries = {good_entry(), entry("notes.txt", "hello")};
  EXPECT_TRUE(contains(member_refusal(a, "notes.txt"), "member 'notes.txt' is not an .npy array"));
  a.entries = {entry("dir/", "")};
  EXPECT_TRUE(contains(member_refusal(a, "dir/"), "member 'dir/' is not an .npy array"));
}

TEST(NpzRead, RefusesADuplicateName) {
  Archive a;
  a.entries = {good_entry(), good_entry("x.npy"), good_entry()};
  EXPECT_TRUE(contains(member_refusal(a, "m"), "member 'm.npy' appears twice"));
}

TEST(NpzRead, RefusesSizesThatDiffer) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].compressed = a.entries[0].content.size() - 8;
  EXPECT_TRUE(contains(member_refusal(a, "m"), "is stored with"));
}

TEST(NpzRead, RefusesATruncatedOrPaddedMember) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].content.resize(a.entries[0].content.size() - 1);
  EXPECT_TRUE(contains(member_refusal(a, "m"), "(truncated)"));
  a.entries = {good_entry()};
  a.entries[0].content += "xyz";
  EXPECT_TRUE(contains(member_refusal(a, "m"), "(trailing bytes)"));
}

TEST(NpzRead, RefusesABadNpyHeaderNamingTheMember) {
  Archive a;
  a.entries = {good_entry(), entry("be.npy", npy_array(">f8", kThree))};
  EXPECT_TRUE(contains(member_refusal(a, "be"),
                       "member 'be.npy': dtype '>f8' is big-endian; collide reads little-endian arrays"));
  a.entries = {entry("two_d.npy", npy_with_dict("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }\n", 1,
                                                std::string(16, '\0')))};
  EXPECT_TRUE(contains(member_refusal(a, "two_d"), "a 2-D array (shape (2, 2)); scene columns are 1-D"));
  a.entries = {entry("csv.npy", "m,Ix\n1,2\n")};
  EXPECT_TRUE(contains(member_refusal(a, "csv"), "bad magic"));
}

TEST(NpzRead, RefusesBadLocalHeaders) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].local_offset = 1u << 20;
  EXPECT_TRUE(contains(member_refusal(a, "m"), "lies past the end of the file"));
  a.entries[0].local_offset = 4;
  EXPECT_TRUE(contains(member_refusal(a, "m"), "no local header signature"));
  a.entries[0].local_offset.reset();
  a.entries[0].local_name = "n.npy";
  EXPECT_TRUE(contains(member_refusal(a, "m"), "its local header names another file"));
  a.entries[0].local_name.reset();
  a.entries[0].local_extra = std::string(300, 'e');                // data pushed into the directory...
  a.entries[0].uncompressed = a.entries[0].compressed = 1u << 16;  // ...and sized past the end
  EXPECT_TRUE(contains(member_refusal(a, "m"), "run past the end of the file"));
}

TEST(NpzRead, RefusesCorruptZip64Fields) {
  Archive a;
  a.entries = {good_entry()};
  a.entries[0].compressed = 0xFFFFFFFF;
  a.entries[0].uncompressed = 0xFFFFFFFF;
  EXPECT_TRUE(contains(member_refusal(a, "m"), "no ZIP64 extra field"));
  a.entries[0] = good_entry();
  a.entries[0].zip64_offset = true;
  a.entries[0].compressed = a.entries[0].uncompressed = 0xFFFFFFFF;  // needs 24 bytes, the block has 8
  EXPECT_TRUE(contains(member_refusal(a, "m"), "too short"));
  a.entries[0] = good_entry();
  a.entries[0].central_extra = std::string("\x01\x00\x40\x00", 4);  // a block longer than the field
  EXPECT_TRUE(contains(member_refusal(a, "m"), "corrupt extra field"));
}

TEST(NpzRead, RefusesBrokenArchives) {
  EXPECT_TRUE(contains(file_refusal(""), "not an .npz archive"));
  EXPECT_TRUE(contains(file_refusal("PK\x03\x04"), "not an .npz archive"));
  EXPECT_TRUE(contains(file_refusal(std::string(100, 'x')), "no ZIP end of central directory record"));
  Archive a;
  a.entries = {good_entry(), good_entry("b.npy")};
  const std::string bytes = build_zip(a);
  EXPECT_TRUE(contains(file_refusal(bytes.substr(0, bytes.size() - 1)), "no ZIP end of central directory"));
  // The front cut off: the directory's offset now points past the end.
  EXPECT_TRUE(contains(file_refusal(bytes.substr(150)), "truncated archive"));
  // Room for three entries of 46 bytes, but the two hold long names.
  a.entries = {good_entry("a_member_with_a_long_name.npy"), good_entry("another_long_name_member.npy")};
  a.claimed_entries = 3;
  EXPECT_TRUE(contains(file_refusal(build_zip(a)), "runs past the end of the directory"));
  a.claimed_entries = 60000;
  EXPECT_TRUE(contains(file_refusal(build_zip(a)), "claims 60000 members"));
  a.claimed_entries.reset();
  a.entries[1].name = ".npy";
  EXPECT_TRUE(contains(file_refusal(build_zip(a)), "has no name"));
  // Sentinels in the end record, no ZIP64 records.
  std::string sentinel = build_zip(Archive{{good_entry()}, false, "", 0xFFFF});
  EXPECT_TRUE(contains(file_refusal(sentinel), "ZIP64 records that are missing"));
}

// Every prefix of a valid archive, and every archive with one byte changed,
// is accepted or refused with a SceneError; an accepted one's members lie
// inside the bytes.
TEST(NpzRead, AnyCorruptionIsASceneError) {
  const std::vector<float> v = sample_f4(4);
  const std::vector<std::int64_t> w = sample_i8(2);
  const std::string good =
      collide::format_npz({{"a", NpyType::f4, v.data(), v.size()}, {"bb", NpyType::i8, w.data(), w.size()}});
  const auto check = [](const std::string& bytes) {
    try {
      const NpzArchive archive = NpzArchive::parse(bytes, "t.npz");
      for (const NpzMember& m : archive.members()) {
        const auto* begin = reinterpret_cast<const std::byte*>(bytes.data());
        ASSERT_GE(m.data, begin);
        ASSERT_LE(m.data + m.count * collide::npy_type_size(m.type), begin + bytes.size());
      }
    } catch (const SceneError& e) {
      ASSERT_EQ(e.file(), "t.npz");
    }
  };
  for (std::size_t n = 0; n < good.size(); ++n) check(good.substr(0, n));
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const int delta : {1, 0x80, 0xFF}) {
      std::string bad = good;
      bad[i] = static_cast<char>(bad[i] + delta);
      check(bad);
    }
  }
}

// ---------------------------------------------------------------------------
// NumPy's view
// ---------------------------------------------------------------------------
bool numpy_available() {
  static const bool available =
      std::system((std::string(COLLIDE_TEST_PYTHON) + " -c 'import numpy' >/dev/null 2>&1").c_str()) == 0;
  return available;
}

/// Python that builds the sample columns as SampleColumns does.
const char* const kPythonSamples = R"(
import sys, io, zipfile, struct
import numpy as np

def samples():
    return {
        'm': (np.arange(1000) * 0.25 - 7).astype('<f4'),
        'big_f8': (np.arange(300000) * 0.5 - 1e6).astype('<f8'),
        'ids': ((np.arange(7, dtype=np.uint64) * np.uint64(2654435761)) & np.uint64(0xFFFFFFFF)).astype('<u4'),
        'one': (5 - 3 * np.arange(1)).astype('<i4'),
        'empty': np.zeros(0, dtype='<u8'),
        'i8': (12345 - np.arange(33, dtype=np.int64) * (1 << 40)).astype('<i8'),
    }
)";

collide::test::RunResult run_python(const fs::path& dir, const std::string& body,
                                    const std::vector<std::string>& args) {
  const fs::path script = dir / "check.py";
  std::ofstream(script) << kPythonSamples << body;
  std::vector<std::string> all = {script.string()};
  all.insert(all.end(), args.begin(), args.end());
  return collide::test::run_program(COLLIDE_TEST_PYTHON, dir, all);
}

TEST_F(NpzFileTest, NumPyLoadsWhatWeWrite) {
  if (!numpy_available()) GTEST_SKIP() << COLLIDE_TEST_PYTHON << " cannot import numpy";
  const SampleColumns s;
  {
    collide::OutputFile out(path("ours.npz"));
    collide::write_npz(out, s.columns());
    out.commit();
  }
  write_text("empty.npz", collide::format_npz({}));
  const collide::test::RunResult r = run_python(dir_, R"(
path, empty = sys.argv[1], sys.argv[2]
expected = samples()
with zipfile.ZipFile(path) as zf:
    assert zf.testzip() is None, 'CRC mismatch'
    assert [i.filename for i in zf.infolist()] == [k + '.npy' for k in expected], zf.namelist()
    raw = open(path, 'rb').read()
    for info in zf.infolist():
        assert info.compress_type == zipfile.ZIP_STORED
        assert info.file_size == info.compress_size
        # The member's bytes are numpy.lib.format.write_array's, byte for byte.
        buf = io.BytesIO()
        np.lib.format.write_array(buf, expected[info.filename[:-4]], allow_pickle=False)
        assert zf.read(info) == buf.getvalue(), info.filename
        # Its array data starts at a multiple of 64 in the file.
        off = info.header_offset
        name_len, extra_len = struct.unpack('<HH', raw[off + 26:off + 30])
        data = off + 30 + name_len + extra_len + 128
        assert data % 64 == 0, (info.filename, data)
with np.load(path) as npz:
    assert sorted(npz.files) == sorted(expected), npz.files
    for name, want in expected.items():
        got = npz[name]
        assert got.dtype == want.dtype, (name, got.dtype, want.dtype)
        assert got.shape == want.shape, (name, got.shape)
        assert np.array_equal(got, want), name
with np.load(empty) as npz:
    assert npz.files == []
print('ok')
)",
                                                {path("ours.npz"), path("empty.npz")});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "ok\n") << r.err;
}

TEST_F(NpzFileTest, WeReadWhatNumPyWrites) {
  if (!numpy_available()) GTEST_SKIP() << COLLIDE_TEST_PYTHON << " cannot import numpy";
  const collide::test::RunResult r = run_python(dir_, R"(
d = samples()
# Members in an order of NumPy's choosing: the keywords as given, then the
# positional arrays (arr_0); a 0-D array is one element.
np.savez(sys.argv[1], d['i8'], z=d['ids'], scalar=np.float64(2.5), **{k: d[k] for k in ['one', 'big_f8', 'm', 'empty']})
np.savez_compressed(sys.argv[2], m=d['m'])
print('ok')
)",
                                                {path("numpy.npz"), path("compressed.npz")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const SampleColumns s;
  const NpzArchive archive = NpzArchive::map(path("numpy.npz"));
  std::vector<std::string> names;
  for (const NpzMember& m : archive.members()) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"z", "scalar", "one", "big_f8", "m", "empty", "arr_0"}));
  expect_member(archive, "arr_0", NpyType::i8, s.i8);
  expect_member(archive, "z", NpyType::u4, s.u4);
  expect_member(archive, "scalar", NpyType::f8, std::vector<double>{2.5});
  expect_member(archive, "one", NpyType::i4, s.i4);
  expect_member(archive, "big_f8", NpyType::f8, s.f8);
  expect_member(archive, "m", NpyType::f4, s.f4);
  expect_member(archive, "empty", NpyType::u8, s.u8);

  const SceneError e = expect_scene_error([&] { (void)NpzArchive::map(path("compressed.npz")); });
  EXPECT_EQ(e.file(), path("compressed.npz"));
  EXPECT_EQ(e.column(), "m");
  EXPECT_TRUE(contains(std::string(e.what()),
                       "member 'm.npy' is compressed (deflate); scene files must be saved "
                       "with np.savez, not np.savez_compressed"));
}

}  // namespace
