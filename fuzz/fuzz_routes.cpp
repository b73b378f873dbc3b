// fuzz_routes.cpp - libFuzzer target: one scene, one answer
// (docs/collision-law.md, "Scene values"). The bytes draw a small scene
// whose every value is written as text where the two roundings to float
// part (support/scene_value_text.hpp: halfway cases, text longer than its
// float's, subnormals, the largest floats, values beyond float, inf); the
// scene then takes every route in process, in float and double:
//
// * the CSV reader, on the plain text (its fast path) and on the text with
//   blanks (its careful path);
// * the .npz reader on a '<f8' file of each field's double (strtod: the
//   double nearest the text), rules checked by the loader, and by
//   SolveBodies for a load that leaves them to the caller;
// * narrow_bodies on those doubles (a C++ caller's double columns).
//
// What it asserts, for any input: every route accepts the bodies, or every
// one refuses them with the same row, column and reason; likewise the
// contacts (CSV and .npz); an accepted float value is the float nearest the
// field's double (scene_value), never the float nearest the text where the
// two differ; and an accepted scene solves to the same bytes of v, w and J
// by every route, fast and accurate, and in double as well.
//
// Input layout: byte 0 the body count (1 to 6), byte 1 the contact count (0
// to 8), then per body 17 fields and per contact two id bytes and 8 fields,
// a field being 4 bytes of a float's bits and a byte choosing how it is
// written. Missing bytes read as 0. The seeds in fuzz/corpus/routes/ are
// scenes of each kind of text, the one the two roundings first parted on,
// and refusals (a value beyond float, a subnormal mass).
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "collide/io/npz.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/io/scene_values.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/scene_value_text.hpp"

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz_routes: %s\n", what.c_str());
  std::abort();
}

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : p_(data), end_(data + size) {}
  std::uint8_t byte() { return p_ < end_ ? *p_++ : 0; }
  std::uint32_t u32() {
    std::uint32_t u = 0;
    for (int k = 0; k < 4; ++k) u |= static_cast<std::uint32_t>(byte()) << (8 * k);
    return u;
  }

 private:
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

/// One field's text: a float's bits and how to write it.
std::string field_text(Bytes& in) {
  const float f = std::bit_cast<float>(in.u32());
  const std::uint8_t how = in.byte();
  const bool negative = std::signbit(f);
  switch (how % 8) {
    case 5: {
      // A double at or beyond float's edge (2^128 - 2^103): no float.
      const double edge = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
      const double x = edge * (1.0 + (how >> 3) / 8.0);
      return collide::test::shortest_text(negative ? -x : x);
    }
    case 6: {
      // The largest double below the edge: float's largest.
      const double x = std::nextafter(std::ldexp(1.0, 128) - std::ldexp(1.0, 103), 0.0);
      return collide::test::shortest_text(negative ? -x : x);
    }
    case 7:
      return negative ? "-inf" : "inf";
    default:
      break;
  }
  const auto kind = static_cast<collide::test::ValueText>(how % 5);
  if (!std::isfinite(f) || std::fabs(f) == std::numeric_limits<float>::max()) {
    return collide::test::value_text(f, collide::test::ValueText::float_shortest);  // "nan", "inf" included
  }
  return collide::test::value_text(f, kind);
}

/// The text of a drawn scene, and each field's double (strtod).
struct Drawn {
  std::string bodies, contacts;
  std::vector<std::vector<double>> body_columns = std::vector<std::vector<double>>(17);
  std::vector<std::vector<double>> contact_columns = std::vector<std::vector<double>>(8);
  std::vector<std::uint32_t> a, b;
  std::vector<std::string> body_texts;  // row-major, 17 a row
};

Drawn draw(Bytes& in) {
  Drawn d;
  const std::size_t n = 1 + in.byte() % 6;
  const std::size_t m = in.byte() % 9;
  d.bodies = std::string(collide::bodies_header());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < 17; ++k) {
      const std::string t = field_text(in);
      d.body_texts.push_back(t);
      d.body_columns[k].push_back(std::strtod(t.c_str(), nullptr));
      d.bodies += t;
      d.bodies += k + 1 < 17 ? ',' : '\n';
    }
  }
  d.contacts = std::string(collide::contacts_header());
  for (std::size_t j = 0; j < m; ++j) {
    d.a.push_back(in.byte() % n);
    d.b.push_back(in.byte() % n);
    d.contacts += std::to_string(d.a.back()) + "," + std::to_string(d.b.back());
    for (std::size_t k = 0; k < 8; ++k) {
      const std::string t = field_text(in);
      d.contact_columns[k].push_back(std::strtod(t.c_str(), nullptr));
      d.contacts += "," + t;
    }
    d.contacts += '\n';
  }
  return d;
}

/// The text with a blank before every comma: the reader's careful path.
std::string with_blanks(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == ',') out += ' ';
    out += c;
  }
  return out;
}

/// A file in memory that the loaders open by name (/proc/self/fd/N).
class MemoryFile {
 public:
  explicit MemoryFile(const std::string& bytes) : fd_(::memfd_create("fuzz_routes.npz", 0)) {
    if (fd_ < 0) fail("memfd_create failed");
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t w = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (w <= 0) fail("write to the memory file failed");
      done += static_cast<std::size_t>(w);
    }
  }
  ~MemoryFile() { ::close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  [[nodiscard]] std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

std::string bodies_npz(const Drawn& d) {
  std::vector<collide::NpzColumn> cols;
  for (std::size_t k = 0; k < 17; ++k) {
    cols.push_back(
        {collide::kBodyColumns[k], collide::NpyType::f8, d.body_columns[k].data(), d.body_columns[k].size()});
  }
  return collide::format_npz(cols);
}

std::string contacts_npz(const Drawn& d) {
  std::vector<collide::NpzColumn> cols = {{"a", collide::NpyType::u4, d.a.data(), d.a.size()},
                                          {"b", collide::NpyType::u4, d.b.data(), d.b.size()}};
  for (std::size_t k = 0; k < 8; ++k) {
    cols.push_back({collide::kContactColumns[k + 2], collide::NpyType::f8, d.contact_columns[k].data(),
                    d.contact_columns[k].size()});
  }
  return collide::format_npz(cols);
}

/// A route's verdict: accepted, or refused at (row, column) with a reason.
struct Verdict {
  bool accepted = false;
  std::size_t row = 0;
  std::string column, reason;
};

bool operator==(const Verdict& x, const Verdict& y) {
  return x.accepted == y.accepted && (x.accepted || (x.row == y.row && x.column == y.column && x.reason == y.reason));
}

std::string describe(const Verdict& v) {
  return v.accepted ? std::string("accepted") : "row " + std::to_string(v.row) + ", '" + v.column + "': " + v.reason;
}

template <class F>
Verdict verdict_of(const F& f) {
  try {
    f();
    return {true, 0, {}, {}};
  } catch (const collide::SceneError& e) {
    return {false, e.row(), e.column(), e.reason()};
  }
}

/// v, w and J of a solve, as bytes.
template <class T>
std::vector<T> solve_bytes(const collide::BodyView<T>& bodies, const collide::ContactView<T>& contacts,
                           collide::Accuracy accuracy) {
  collide::SolverOptions options;
  options.accuracy = accuracy;
  options.threads = 1;
  collide::Schedule schedule;
  schedule.build(contacts, bodies);
  collide::ImpulseBuffer<T> j(contacts.count);
  collide::Solver(options).solve(collide::choose_model(bodies, contacts), bodies, contacts, j.view(), schedule);
  std::vector<T> out;
  for (const T* x : {bodies.v.x, bodies.v.y, bodies.v.z, bodies.w.x, bodies.w.y, bodies.w.z}) {
    out.insert(out.end(), x, x + bodies.count);
  }
  const auto jv = j.view();
  for (const T* x : {jv.j.x, jv.j.y, jv.j.z}) out.insert(out.end(), x, x + contacts.count);
  return out;
}

template <class T>
bool same_bits(const std::vector<T>& x, const std::vector<T>& y) {
  return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(T)) == 0);
}

template <class T>
void run(const Drawn& d, const MemoryFile& bnpz, const MemoryFile& cnpz) {
  const char* const p = collide::precision_name<T>();
  // The bodies: every route accepts, or refuses alike.
  std::optional<collide::BodyTable<T>> csv;
  const Verdict by_csv = verdict_of([&] { csv = collide::parse_bodies<T>(d.bodies, "bodies.csv"); });
  const Verdict by_careful = verdict_of([&] { (void)collide::parse_bodies<T>(with_blanks(d.bodies), "b"); });
  const Verdict by_npz = verdict_of([&] { (void)collide::load_bodies<T>(bnpz.path(), collide::SceneFormat::npz); });
  const Verdict by_solve_bodies = verdict_of([&] {
    const auto loaded = collide::load_bodies<T>(bnpz.path(), collide::SceneFormat::npz, collide::BodyRules::by_caller);
    const collide::SolveBodies<T> s(loaded);
  });
  collide::BodyColumns<double> wide;
  wide.count = d.body_columns[0].size();
  for (std::size_t k = 0; k < 17; ++k) wide.column[k] = d.body_columns[k].data();
  collide::BodyTable<T> narrowed;
  const std::optional<collide::RowDefect> defect = collide::narrow_bodies(wide, narrowed);
  const Verdict by_columns =
      defect ? Verdict{false, defect->row, std::string(defect->defect.column), defect->defect.reason}
             : Verdict{true, 0, {}, {}};
  for (const auto& [name, v] : {std::pair<const char*, const Verdict&>{"the careful path", by_careful},
                                {"npz", by_npz},
                                {"npz, rules by SolveBodies", by_solve_bodies},
                                {"narrow_bodies", by_columns}}) {
    if (!(v == by_csv)) {
      fail(std::string(p) + " bodies: CSV " + describe(by_csv) + ", but " + name + " " + describe(v));
    }
  }
  // Each accepted value is the field's double rounded once.
  if (csv) {
    for (std::size_t i = 0; i < csv->size(); ++i) {
      for (std::size_t k = 0; k < 17; ++k) {
        const T want = collide::scene_value<T>(d.body_columns[k][i]);
        if (std::memcmp(&csv->column[k][i], &want, sizeof(T)) != 0 ||
            std::memcmp(&narrowed.column[k][i], &want, sizeof(T)) != 0) {
          fail(std::string(p) + ": '" + d.body_texts[17 * i + k] + "' is not stored as its double rounded once");
        }
      }
    }
  }
  // The contacts: CSV and npz alike.
  const std::size_t n = d.body_columns[0].size();
  const Verdict c_csv = verdict_of([&] { (void)collide::parse_contacts<T>(d.contacts, "contacts.csv", n); });
  const Verdict c_careful = verdict_of([&] { (void)collide::parse_contacts<T>(with_blanks(d.contacts), "c", n); });
  const Verdict c_npz = verdict_of([&] { (void)collide::load_contacts<T>(cnpz.path(), collide::SceneFormat::npz, n); });
  if (!(c_careful == c_csv) || !(c_npz == c_csv)) {
    fail(std::string(p) + " contacts: CSV " + describe(c_csv) + ", careful path " + describe(c_careful) + ", npz " +
         describe(c_npz));
  }
  if (!by_csv.accepted || !c_csv.accepted) return;
  // An accepted scene solves to the same bytes by every route.
  for (const collide::Accuracy accuracy : {collide::Accuracy::fast, collide::Accuracy::accurate}) {
    collide::BodyBuffer<T> from_csv = collide::to_body_buffer(*csv);
    const collide::ContactBuffer<T> contacts = collide::parse_contacts<T>(d.contacts, "contacts.csv", n);
    const std::vector<T> want = solve_bytes(from_csv.view(), contacts.view(), accuracy);
    const auto loaded = collide::load_bodies<T>(bnpz.path(), collide::SceneFormat::npz, collide::BodyRules::by_caller);
    collide::SolveBodies<T> from_npz(loaded);
    const auto loaded_contacts = collide::load_contacts<T>(cnpz.path(), collide::SceneFormat::npz, n);
    if (!same_bits(solve_bytes(from_npz.view(), loaded_contacts.view(), accuracy), want)) {
      fail(std::string(p) + ": the npz files solve to other bytes than the CSV files");
    }
    collide::SolveBodies<T> from_columns(collide::columns_of(narrowed));
    if (!same_bits(solve_bytes(from_columns.view(), contacts.view(), accuracy), want)) {
      fail(std::string(p) + ": narrow_bodies' columns solve to other bytes than the CSV files");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Bytes in(data, size);
  const Drawn d = draw(in);
  const MemoryFile bodies(bodies_npz(d));
  const MemoryFile contacts(contacts_npz(d));
  run<float>(d, bodies, contacts);
  run<double>(d, bodies, contacts);
  return 0;
}
