// csv_write.cpp - writing the scene CSV files of docs/collision-law.md and the result
// files: bodies, contacts and impulses, to an OutputFile or to a string, and
// one row or one number at a time (collide/io/scene_io.hpp).
//
// Design notes
// ------------
// * Blocks of rows are formatted in parallel with std::to_chars (shortest
//   text that reads back to the same T, csv_fields.hpp's put_number) and
//   written in order through a tbb pipeline (ordered_blocks.hpp), so memory
//   stays bounded and output is identical for any thread count.
#include "collide/io/scene_io.hpp"

#include <algorithm>
#include <charconv>
#include <string>
#include <string_view>
#include <vector>

#include "csv_fields.hpp"
#include "ordered_blocks.hpp"

namespace collide {
namespace {

using detail::kMaxIdChars;
using detail::kMaxNumberChars;
using detail::ordered_blocks;
using detail::put_number;

/// Formats rows [begin, end) with `row(p, i) -> p` appending one row of at
/// most `max_row_chars` characters.
template <class RowFn>
void format_rows(std::string& out, std::size_t begin, std::size_t end, std::size_t max_row_chars, RowFn&& row) {
  const std::size_t old = out.size();
  out.resize(old + (end - begin) * max_row_chars);
  char* p = out.data() + old;
  for (std::size_t i = begin; i < end; ++i) p = row(p, i);
  out.resize(static_cast<std::size_t>(p - out.data()));
}

/// Formats `rows` rows block by block, in parallel, and hands the text to
/// `sink` in order. At most a few blocks are in memory at once.
template <class Sink, class RowFn>
void emit_rows(Sink&& sink, std::string_view header, std::size_t rows, std::size_t max_row_chars, RowFn&& row) {
  sink(header);
  constexpr std::size_t kBlock = 16384;
  const std::size_t blocks = (rows + kBlock - 1) / kBlock;
  if (blocks <= 1) {
    std::string text;
    format_rows(text, 0, rows, max_row_chars, row);
    sink(std::string_view(text));
    return;
  }
  ordered_blocks<std::string>(
      rows, kBlock,
      [&](std::size_t begin, std::size_t end, std::string& text) {
        text.clear();
        format_rows(text, begin, end, max_row_chars, row);
      },
      [&](const std::string& text, std::size_t) { sink(std::string_view(text)); });
}

template <class T>
auto body_result_row(const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  return [&inputs, solved](char* p, std::size_t i) {
    using Table = BodyTable<T>;
    for (std::size_t k = 0; k < Table::vx; ++k) {
      p = put_number(p, inputs.column[k][i]);
      *p++ = ',';
    }
    const T out[6] = {solved.v.x[i], solved.v.y[i], solved.v.z[i], solved.w.x[i], solved.w.y[i], solved.w.z[i]};
    for (int k = 0; k < 6; ++k) {
      p = put_number(p, out[k]);
      *p++ = k == 5 ? '\n' : ',';
    }
    return p;
  };
}

template <class T>
auto body_table_row(const BodyColumns<T>& table) {
  return [&table](char* p, std::size_t i) {
    for (std::size_t k = 0; k < 17; ++k) {
      p = put_number(p, table.column[k][i]);
      *p++ = k == 16 ? '\n' : ',';
    }
    return p;
  };
}

template <class T>
auto impulse_row(const ImpulseView<const T>& impulses) {
  return [impulses](char* p, std::size_t i) {
    p = put_number(p, impulses.j.x[i]);
    *p++ = ',';
    p = put_number(p, impulses.j.y[i]);
    *p++ = ',';
    p = put_number(p, impulses.j.z[i]);
    *p++ = '\n';
    return p;
  };
}

/// One contacts.csv row from its ids and its eight values (cx .. mu).
template <class T>
char* put_contact(char* p, BodyIndex a, BodyIndex b, const T* v) {
  p = std::to_chars(p, p + kMaxIdChars, a).ptr;
  *p++ = ',';
  p = std::to_chars(p, p + kMaxIdChars, b).ptr;
  for (int k = 0; k < 8; ++k) {
    *p++ = ',';
    p = put_number(p, v[k]);
  }
  *p++ = '\n';
  return p;
}

template <class T>
auto contact_row(const ContactView<T>& contacts) {
  return [contacts](char* p, std::size_t k) {
    const T v[8] = {contacts.c.x[k],
                    contacts.c.y[k],
                    contacts.c.z[k],
                    contacts.n.x[k],
                    contacts.n.y[k],
                    contacts.n.z[k],
                    contacts.e ? contacts.e[k] : contacts.uniform_e,
                    contacts.mu ? contacts.mu[k] : T(0)};
    return put_contact(p, contacts.a[k], contacts.b[k], v);
  };
}

template <class T>
void check_same_count(const BodyColumns<T>& inputs, const BodyView<const T>& solved, const std::string& file) {
  if (inputs.size() != solved.count) {
    throw SceneError(file, "internal error: " + std::to_string(inputs.size()) + " input bodies but " +
                               std::to_string(solved.count) + " solved bodies");
  }
}

constexpr std::size_t kBodyRowChars = 17 * (kMaxNumberChars + 1);
constexpr std::size_t kImpulseRowChars = 3 * (kMaxNumberChars + 1);
constexpr std::size_t kContactRowChars = 2 * (kMaxIdChars + 1) + 8 * (kMaxNumberChars + 1);

}  // namespace

std::string_view bodies_header() { return "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"; }
std::string_view contacts_header() { return "a,b,cx,cy,cz,nx,ny,nz,e,mu\n"; }
std::string_view impulses_header() { return "jx,jy,jz\n"; }

template <class T>
void write_bodies(OutputFile& out, const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  check_same_count(inputs, solved, out.path());
  emit_rows([&](std::string_view s) { out.write(s); }, bodies_header(), inputs.size(), kBodyRowChars,
            body_result_row(inputs, solved));
}

template <class T>
void write_impulses(OutputFile& out, const ImpulseView<const T>& impulses) {
  emit_rows([&](std::string_view s) { out.write(s); }, impulses_header(), impulses.count, kImpulseRowChars,
            impulse_row(impulses));
}

template <class T>
void write_body_table(OutputFile& out, const BodyColumns<T>& table) {
  emit_rows([&](std::string_view s) { out.write(s); }, bodies_header(), table.size(), kBodyRowChars,
            body_table_row(table));
}

template <class T>
void write_contacts(OutputFile& out, const ContactView<T>& contacts) {
  emit_rows([&](std::string_view s) { out.write(s); }, contacts_header(), contacts.count, kContactRowChars,
            contact_row(contacts));
}

template <class T>
std::string format_body_table(const BodyColumns<T>& table) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, bodies_header(), table.size(), kBodyRowChars,
            body_table_row(table));
  return text;
}

template <class T>
std::string format_contacts(const ContactView<T>& contacts) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, contacts_header(), contacts.count, kContactRowChars,
            contact_row(contacts));
  return text;
}

template <class T>
std::string format_bodies(const BodyColumns<T>& inputs, const BodyView<const T>& solved) {
  check_same_count(inputs, solved, "<memory>");
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, bodies_header(), inputs.size(), kBodyRowChars,
            body_result_row(inputs, solved));
  return text;
}

template <class T>
std::string format_impulses(const ImpulseView<const T>& impulses) {
  std::string text;
  emit_rows([&](std::string_view s) { text.append(s); }, impulses_header(), impulses.count, kImpulseRowChars,
            impulse_row(impulses));
  return text;
}

template <class T>
void append_number(std::string& out, T value) {
  char buf[kMaxNumberChars];
  out.append(buf, put_number(buf, value));
}

template <class T>
void append_body_row(std::string& out, const BodyRecord<T>& body) {
  const T v[17] = {body.m,    body.I[0], body.I[1], body.I[2], body.q[0], body.q[1], body.q[2], body.q[3], body.p[0],
                   body.p[1], body.p[2], body.v[0], body.v[1], body.v[2], body.w[0], body.w[1], body.w[2]};
  for (std::size_t k = 0; k < 17; ++k) {
    append_number(out, v[k]);
    out += k == 16 ? '\n' : ',';
  }
}

template <class T>
void append_contact_row(std::string& out, const ContactRecord<T>& contact) {
  char buf[kContactRowChars];
  const T v[8] = {contact.c[0], contact.c[1], contact.c[2], contact.n[0],
                  contact.n[1], contact.n[2], contact.e,    contact.mu};
  out.append(buf, put_contact(buf, contact.a, contact.b, v));
}

#define COLLIDE_CSV_WRITE_INSTANTIATE(T)                                                       \
  template void write_bodies<T>(OutputFile&, const BodyColumns<T>&, const BodyView<const T>&); \
  template void write_impulses<T>(OutputFile&, const ImpulseView<const T>&);                   \
  template void write_body_table<T>(OutputFile&, const BodyColumns<T>&);                       \
  template void write_contacts<T>(OutputFile&, const ContactView<T>&);                         \
  template std::string format_body_table<T>(const BodyColumns<T>&);                            \
  template std::string format_contacts<T>(const ContactView<T>&);                              \
  template std::string format_bodies<T>(const BodyColumns<T>&, const BodyView<const T>&);      \
  template std::string format_impulses<T>(const ImpulseView<const T>&);                        \
  template void append_number<T>(std::string&, T);                                             \
  template void append_body_row<T>(std::string&, const BodyRecord<T>&);                        \
  template void append_contact_row<T>(std::string&, const ContactRecord<T>&);

COLLIDE_CSV_WRITE_INSTANTIATE(float)
COLLIDE_CSV_WRITE_INSTANTIATE(double)

#undef COLLIDE_CSV_WRITE_INSTANTIATE

}  // namespace collide
