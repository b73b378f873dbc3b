// ordered_contacts.hpp - the contacts of a scattered scene copied into
// schedule order, so that the kernel streams them.
//
// Why: in a scene whose contacts share bodies (debris), a batch holds every
// k-th contact or so, in input order; the kernel then reads each contact's
// ten fields and writes its J from lines that hold no other contact of the
// batch: a dozen cache lines per contact besides the bodies' records, read
// while the kernel waits. Copying the contacts into schedule order first is
// one parallel pass whose loads the hardware overlaps freely (no arithmetic
// between them), after which every batch is a contiguous range: vector loads
// and stores in the kernel, and J scattered back into input order in one more
// parallel pass. The law does not see any of this: each contact gets the same
// operands, and the batches run in the same order (solve.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>

#include "collide/contacts.hpp"
#include "scratch_records.hpp"

namespace collide::detail {

template <class T>
class OrderedContacts {
 public:
  /// Copies contacts[order[p]] to position p, p < contacts.count; returns
  /// the copy (its mu / e null where the input's are). Runs in the calling
  /// thread's arena.
  ContactView<T> gather(const ContactView<T>& in, const std::uint32_t* order) {
    const std::size_t n = in.count;
    BodyIndex* a = a_.reserve(n);
    BodyIndex* b = b_.reserve(n);
    T* f[8];
    for (std::size_t i = 0; i < 8; ++i) f[i] = values_[i].reserve(n);
    const T* src[8] = {in.c.x, in.c.y, in.c.z, in.n.x, in.n.y, in.n.z, in.e, in.mu};
    parallel(n, [&](std::size_t p) {
      const std::uint32_t k = order[p];
      a[p] = in.a[k];
      b[p] = in.b[k];
      for (std::size_t i = 0; i < 8; ++i) {
        if (src[i] != nullptr) f[i][p] = src[i][k];
      }
    });
    ContactView<T> out = in;
    out.a = a;
    out.b = b;
    out.c = {f[0], f[1], f[2]};
    out.n = {f[3], f[4], f[5]};
    out.e = in.e != nullptr ? f[6] : nullptr;
    out.mu = in.mu != nullptr ? f[7] : nullptr;
    return out;
  }

  /// Where the kernel writes J in schedule order.
  ImpulseView<T> impulses(std::size_t n) { return {n, {j_[0].reserve(n), j_[1].reserve(n), j_[2].reserve(n)}}; }

  /// J back into input order: out[order[p]] = ordered[p].
  void scatter(const ImpulseView<T>& ordered, const ImpulseView<T>& out, const std::uint32_t* order) {
    parallel(ordered.count, [&](std::size_t p) {
      const std::uint32_t k = order[p];
      out.j.x[k] = ordered.j.x[p];
      out.j.y[k] = ordered.j.y[p];
      out.j.z[k] = ordered.j.z[p];
    });
  }

  /// 0, 1, ..., n - 1: the schedule order of the ordered copy.
  const std::uint32_t* identity(std::size_t n) {
    std::uint32_t* id = identity_.reserve(n);
    // A larger n moves the indices to fresh, uninitialised storage: the
    // entries written before are gone, so fill from 0 again.
    if (id != identity_data_) identity_size_ = 0;
    identity_data_ = id;
    if (identity_size_ < n) {
      for (std::size_t p = identity_size_; p < n; ++p) id[p] = static_cast<std::uint32_t>(p);
      identity_size_ = n;
    }
    return id;
  }

 private:
  template <class F>
  static void parallel(std::size_t n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t p = r.begin(); p != r.end(); ++p) f(p);
    });
  }

  ScratchRecords<BodyIndex> a_, b_;
  ScratchRecords<T> values_[8];  // c.x, c.y, c.z, n.x, n.y, n.z, e, mu
  ScratchRecords<T> j_[3];
  ScratchRecords<std::uint32_t> identity_;
  const std::uint32_t* identity_data_ = nullptr;  // where identity_size_ entries are filled
  std::size_t identity_size_ = 0;
};

}  // namespace collide::detail
