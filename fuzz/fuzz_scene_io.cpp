// fuzz_scene_io.cpp - libFuzzer target: the scene CSV reader on arbitrary bytes.
//
// What it asserts, for any input:
// * parse_bodies and parse_contacts (float and double) either return or
//   throw collide::SceneError - no other exception, crash, UB, leak or hang
//   (ASan, UBSan and libFuzzer's -timeout / -rss_limit_mb catch the rest);
//   a SceneError always names the file it was given;
// * what they accept is usable: to_body_buffer() converts it, every contact
//   index is < the body count and a != b, and every value docs/collision-law.md restricts
//   is in range (m, I > 0; |n| = 1 after normalisation; e in [0, 1]; mu >= 0;
//   no NaN);
// * writing accepted bodies back (format_bodies) and reading the text again
//   gives the same numbers, bit for bit: the round trip docs/collision-law.md
//   promises.
//
// Input layout: the bytes up to the first NUL are bodies.csv, the rest (or
// the same bytes, when there is no NUL) contacts.csv. The corpus seeds in
// fuzz/corpus/scene_io/ are real scenes and near-misses in that layout.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "collide/io/scene_io.hpp"

namespace {

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_scene_io: %s\n", what);
  std::abort();
}

template <class T>
bool same_bits(T x, T y) {
  return std::memcmp(&x, &y, sizeof(T)) == 0;
}

template <class T>
void check_bodies(const collide::BodyTable<T>& table) {
  using Table = collide::BodyTable<T>;
  for (std::size_t i = 0; i < table.size(); ++i) {
    for (std::size_t c = 0; c < Table::kCount; ++c) {
      const T v = table.column[c][i];
      if (std::isnan(v)) fail("accepted a NaN");
      if (c <= Table::Iz ? !(v > T(0)) : !std::isfinite(v)) fail("accepted an out-of-range body value");
    }
  }
  const collide::BodyBuffer<T> buffer = collide::to_body_buffer(table);
  const auto view = buffer.view();
  // q is stored as read (the law normalises it in the kernels), and an
  // accepted one can be normalised in T.
  for (std::size_t i = 0; i < buffer.size(); ++i) {
    if (!same_bits(view.q.w[i], table.column[Table::qw][i]) || !same_bits(view.q.x[i], table.column[Table::qx][i]) ||
        !same_bits(view.q.y[i], table.column[Table::qy][i]) || !same_bits(view.q.z[i], table.column[Table::qz][i])) {
      fail("the stored quaternion differs from the one read");
    }
    if (!collide::quaternion_normalisable(view.q.w[i], view.q.x[i], view.q.y[i], view.q.z[i])) {
      fail("an accepted quaternion cannot be normalised");
    }
  }
  // Round trip: the written text reads back to the same numbers.
  const std::string text = collide::format_bodies<T>(table, view);
  const collide::BodyTable<T> again = collide::parse_bodies<T>(text, "round-trip");
  if (again.size() != table.size()) fail("round trip changed the body count");
  for (std::size_t c = 0; c < Table::kCount; ++c) {
    for (std::size_t i = 0; i < table.size(); ++i) {
      if (!same_bits(again.column[c][i], table.column[c][i])) fail("round trip changed a number");
    }
  }
}

template <class T>
void check_contacts(const collide::ContactBuffer<T>& contacts, std::size_t body_count) {
  const auto v = contacts.view();
  for (std::size_t k = 0; k < v.count; ++k) {
    if (v.a[k] >= body_count || v.b[k] >= body_count || v.a[k] == v.b[k]) fail("accepted a bad body index");
    const T e = v.e[k];
    const T mu = v.mu ? v.mu[k] : T(0);
    if (!(e >= T(0) && e <= T(1)) || !(mu >= T(0)) || std::isnan(mu)) fail("accepted a bad e or mu");
    // n is stored as read, unit within the files' tolerance.
    const T n[3] = {v.n.x[k], v.n.y[k], v.n.z[k]};
    if (!collide::unit_length_ok(collide::length_in_double(n, 3))) fail("an accepted normal is not unit within 1e-3");
    for (const T x : {v.c.x[k], v.c.y[k], v.c.z[k]}) {
      if (!std::isfinite(x)) fail("accepted a non-finite contact point");
    }
  }
}

template <class T>
void run(std::string_view bodies_text, std::string_view contacts_text, std::size_t fallback_bodies) {
  std::size_t body_count = fallback_bodies;
  try {
    const collide::BodyTable<T> table = collide::parse_bodies<T>(bodies_text, "bodies.csv");
    check_bodies(table);
    body_count = table.size();
  } catch (const collide::SceneError& e) {
    if (e.file() != "bodies.csv") fail("a SceneError named the wrong file");
  }
  try {
    check_contacts(collide::parse_contacts<T>(contacts_text, "contacts.csv", body_count), body_count);
  } catch (const collide::SceneError& e) {
    if (e.file() != "contacts.csv") fail("a SceneError named the wrong file");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = all.find('\0');
  const std::string_view bodies = all.substr(0, nul);
  const std::string_view contacts = nul == std::string_view::npos ? all : all.substr(nul + 1);
  // Without a bodies file that parses, contact ids are checked against a
  // count taken from the input, so the range check itself is exercised.
  const std::size_t fallback = size == 0 ? 0 : data[0] % 16;
  run<float>(bodies, contacts, fallback);
  run<double>(bodies, contacts, fallback);
  return 0;
}
