// body_table.cpp - body tables in physical units and what the kernels take:
// BodyTable's rows, the rules screened column by column (bodies_ok,
// first_body_defect), the inverses (to_body_buffer, inverses_of) and back
// (to_body_table) (collide/io/scene_io.hpp).
//
// Design notes
// ------------
// * The rules are rules.hpp's. bodies_ok gives body_ok's verdict for a range
//   of rows without a branch per value, so that its loops vectorise; only a
//   range it refuses is scanned again, body by body in order, with
//   body_defect, so the body named does not depend on threads.
// * Rows in parallel (tbb) over disjoint ranges: no thread writes an element
//   another one writes, so the result is the same for any thread count.
#include "collide/io/scene_io.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include "collide/rules.hpp"
#include "screen_chunks.hpp"

namespace collide {

template <class T>
BodyRecord<T> BodyTable<T>::record(std::size_t i) const {
  return columns_of(*this).record(i);
}

template <class T>
void BodyTable<T>::push_back(const BodyRecord<T>& body) {
  column[m].push_back(body.m);
  for (int k = 0; k < 3; ++k) column[Ix + k].push_back(body.I[k]);
  for (int k = 0; k < 4; ++k) column[qw + k].push_back(body.q[k]);
  for (int k = 0; k < 3; ++k) column[px + k].push_back(body.p[k]);
  for (int k = 0; k < 3; ++k) column[vx + k].push_back(body.v[k]);
  for (int k = 0; k < 3; ++k) column[wx + k].push_back(body.w[k]);
}

/// The least positive T whose reciprocal is finite: for x > 0, 1/x is
/// finite exactly when x >= it (1/x does not increase with x). Found once,
/// from 1/max by stepping through neighbouring values, in the arithmetic
/// the rule uses (1/x overflows, so not at compile time).
template <class T>
T least_with_finite_inverse() {
  static const T least = [] {
    constexpr T max = std::numeric_limits<T>::max();
    const auto finite_inverse = [](T x) { return T(1) / x <= max; };
    T x = T(1) / max;
    while (finite_inverse(std::nextafter(x, T(0)))) x = std::nextafter(x, T(0));
    while (!finite_inverse(x)) x = std::nextafter(x, max);
    return x;
  }();
  return least;
}

template <class T>
bool bodies_ok(const BodyColumns<T>& columns, std::size_t i0, std::size_t i1) noexcept {
  // The rules of body_ok (collide/rules.hpp), one column at a time and
  // without a branch per value, defects OR-ed into an integer so that the
  // loops vectorise: x - x == 0 exactly when x is finite.
  const auto finite = [](T x) { return (x - x) == T(0); };  // NOLINT(misc-redundant-expression): NaN for inf, NaN
  unsigned bad = 0;
  // m and the moments: > 0 with a finite inverse (inf is allowed), that is
  // x >= the least value with a finite inverse (NaN compares false),
  // without a division per value.
  const T least = least_with_finite_inverse<T>();
  for (std::size_t k = 0; k < 4; ++k) {
    const T* x = columns.column[k];
    for (std::size_t i = i0; i < i1; ++i) bad |= static_cast<unsigned>(!(x[i] >= least));
  }
  for (std::size_t k = 4; k < columns.column.size(); ++k) {
    const T* x = columns.column[k];
    for (std::size_t i = i0; i < i1; ++i) bad |= static_cast<unsigned>(!finite(x[i]));
  }
  const T *qw = columns.column[4], *qx = columns.column[5], *qy = columns.column[6], *qz = columns.column[7];
  for (std::size_t i = i0; i < i1; ++i) {
    const T q2 = quaternion_square(qw[i], qx[i], qy[i], qz[i]);  // quaternion_normalisable, without a branch
    bad |= static_cast<unsigned>(!finite(q2)) | static_cast<unsigned>(!(q2 >= std::numeric_limits<T>::min()));
  }
  return bad == 0;
}

template <class T>
std::optional<RowDefect> first_body_defect(const BodyColumns<T>& columns) {
  const std::size_t n = columns.size();
  if (detail::screen_chunks(n, [&](std::size_t i0, std::size_t i1) { return bodies_ok(columns, i0, i1); })) {
    return std::nullopt;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (std::optional<Defect> defect = body_defect(columns.record(i))) return RowDefect{i, std::move(*defect)};
  }
  return std::nullopt;  // not reached: bodies_ok gives body_ok's verdicts
}

template <class T>
BodyBuffer<T> to_body_buffer(const BodyColumns<T>& table) {
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  // The rules first, in parallel and without messages; the first body that
  // breaks one goes through set(), which names its defect as it always has.
  if (const std::optional<RowDefect> bad = first_body_defect(table)) {
    BodyBuffer<T>(bad->row + 1).set(bad->row, table.record(bad->row));  // throws
  }
  BodyBuffer<T> bodies(table.size());
  // Column by column: q, p, v and w are copied as they are, m and I
  // inverted (inverses_of). Disjoint row ranges, so threads never share an
  // element.
  BodyView<T> v = bodies.view();
  T* const copied[13] = {v.q.w, v.q.x, v.q.y, v.q.z, v.p.x, v.p.y, v.p.z, v.v.x, v.v.y, v.v.z, v.w.x, v.w.y, v.w.z};
  oneapi::tbb::parallel_for(Range(0, table.size(), 1 << 16), [&](const Range& r) {
    const std::size_t i0 = r.begin(), n = r.size();
    for (std::size_t k = 0; k < 13; ++k) std::memcpy(copied[k] + i0, table.column[4 + k] + i0, n * sizeof(T));
  });
  inverses_of(table, v.inv_mass, v.inv_inertia);
  return bodies;
}

namespace {

/// The inverses of bodies [i0, i1): as BodyBuffer::set, 1/inf = 0, and an
/// immovable body has no inverse moments whatever its I (the law). Column
/// by column through restrict pointers, so that each loop vectorises without
/// run-time alias checks. 1/inf is +0, so the inverse mass needs no select.
template <class T>
void inverses_in(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia, std::size_t i0,
                 std::size_t i1) {
  const T inf = std::numeric_limits<T>::infinity();
  const T* __restrict const m = columns.column[0];
  T* __restrict const im = inv_mass;
  for (std::size_t i = i0; i < i1; ++i) im[i] = T(1) / m[i];
  T* const out[3] = {inv_inertia.x, inv_inertia.y, inv_inertia.z};
  for (std::size_t k = 0; k < 3; ++k) {
    const T* __restrict const moment = columns.column[1 + k];
    T* __restrict const inverse = out[k];
    for (std::size_t i = i0; i < i1; ++i) inverse[i] = m[i] == inf ? T(0) : T(1) / moment[i];
  }
}

}  // namespace

template <class T>
void inverses_of(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia) {
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  oneapi::tbb::parallel_for(Range(0, columns.count, 1 << 16),
                            [&](const Range& r) { inverses_in(columns, inv_mass, inv_inertia, r.begin(), r.end()); });
}

template <class T>
bool screened_solve_arrays(const BodyColumns<T>& columns, T* inv_mass, const Vec3Array<T>& inv_inertia,
                           const Vec3Array<T>& v, const Vec3Array<T>& w) {
  using Range = oneapi::tbb::blocked_range<std::size_t>;
  // Chunks of 8192 bodies: the seventeen columns of a float chunk (544 KiB)
  // stay in a core's L2 between the screen, which reads them all, and the
  // inverses and copies, which read ten of them again. Apart, each pass
  // read its columns from memory (or from the file's pages).
  constexpr std::size_t kChunk = std::size_t{1} << 13;
  std::atomic<bool> ok{true};
  T* const copies[6] = {v.x, v.y, v.z, w.x, w.y, w.z};
  oneapi::tbb::parallel_for(Range(0, columns.count, kChunk), [&](const Range& r) {
    for (std::size_t i0 = r.begin(); i0 < r.end(); i0 += kChunk) {
      const std::size_t i1 = std::min(r.end(), i0 + kChunk);
      if (!bodies_ok(columns, i0, i1)) {
        ok.store(false, std::memory_order_relaxed);
        return;
      }
      inverses_in(columns, inv_mass, inv_inertia, i0, i1);
      for (std::size_t k = 0; k < 6; ++k) {
        std::memcpy(copies[k] + i0, columns.column[11 + k] + i0, (i1 - i0) * sizeof(T));
      }
    }
  });
  return ok.load(std::memory_order_relaxed);
}

template <class T>
BodyTable<T> to_body_table(const BodyView<const T>& bodies) {
  using Table = BodyTable<T>;
  Table table;
  table.resize(bodies.count);
  // 1/x with 1/0 = inf, as BodyBuffer::record reads a body back.
  auto physical = [](T x) { return x == T(0) ? std::numeric_limits<T>::infinity() : T(1) / x; };
  const T* from[Table::kCount] = {
      bodies.inv_mass, bodies.inv_inertia.x, bodies.inv_inertia.y, bodies.inv_inertia.z, bodies.q.w, bodies.q.x,
      bodies.q.y,      bodies.q.z,           bodies.p.x,           bodies.p.y,           bodies.p.z, bodies.v.x,
      bodies.v.y,      bodies.v.z,           bodies.w.x,           bodies.w.y,           bodies.w.z};
  oneapi::tbb::parallel_for(oneapi::tbb::blocked_range<std::size_t>(0, bodies.count, 1 << 14),
                            [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t k = 0; k < Table::kCount; ++k) {
                                T* to = table.column[k].data();
                                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                                  to[i] = k <= Table::Iz ? physical(from[k][i]) : from[k][i];
                                }
                              }
                            });
  return table;
}

#define COLLIDE_BODY_TABLE_INSTANTIATE(T)                                                                   \
  template struct BodyTable<T>;                                                                             \
  template BodyBuffer<T> to_body_buffer<T>(const BodyColumns<T>&);                                          \
  template bool bodies_ok<T>(const BodyColumns<T>&, std::size_t, std::size_t) noexcept;                     \
  template std::optional<RowDefect> first_body_defect<T>(const BodyColumns<T>&);                            \
  template void inverses_of<T>(const BodyColumns<T>&, std::add_pointer_t<T>, const Vec3Array<T>&);          \
  template bool screened_solve_arrays<T>(const BodyColumns<T>&, std::add_pointer_t<T>, const Vec3Array<T>&, \
                                         const Vec3Array<T>&, const Vec3Array<T>&);                         \
  template BodyTable<T> to_body_table<T>(const BodyView<const T>&);

COLLIDE_BODY_TABLE_INSTANTIATE(float)
COLLIDE_BODY_TABLE_INSTANTIATE(double)

#undef COLLIDE_BODY_TABLE_INSTANTIATE

}  // namespace collide
