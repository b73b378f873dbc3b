// prepared_contacts.cpp - the copies of prepared_contacts.hpp.
#include "prepared_contacts.hpp"

#include <cassert>
#include <cstdint>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include "first_touch.hpp"

namespace collide::detail {
namespace {

/// Contacts per task of a copy: long stretches, so that each thread streams
/// through its part of the prepared arrays.
constexpr std::size_t kGrain = 16384;

/// f(begin, end) over [0, n) on the arena's threads, each thread one
/// contiguous part.
template <class F>
void for_parts(tbb::task_arena& arena, std::size_t n, const F& f) {
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, kGrain),
        [&](const tbb::blocked_range<std::size_t>& r) { f(r.begin(), r.end()); }, tbb::static_partitioner());
  });
}

/// to[i] = from[order[i]] for i in [begin, end).
template <class V>
void gather(V* to, const V* from, const std::uint32_t* order, std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) to[i] = from[order[i]];
}

/// Whether the contact point is given (the model reads it): a particle
/// solve may have none.
template <class T>
bool has_point(const ContactView<T>& contacts) {
  return contacts.c.x != nullptr && contacts.c.y != nullptr && contacts.c.z != nullptr;
}

}  // namespace

template <class T>
bool PreparedContacts<T>::allocate(tbb::task_arena& arena, const KernelJob<T>& job, bool geometry) {
  const ContactView<T>& contacts = job.contacts;
  const std::size_t n = contacts.count;
  // Sized to n: a smaller solve after a larger one neither allocates nor
  // touches new pages; an array that grows is replaced by room for n.
  FirstTouch touch;
  bool grew = touch.resize(a_, n);
  grew |= touch.resize(b_, n);
  for (int k = 0; k < 3; ++k) {
    if (has_point(contacts)) grew |= touch.resize(c_[k], n);
    grew |= touch.resize(n_[k], n);
    grew |= touch.resize(j_[k], n);
  }
  if (contacts.e != nullptr) grew |= touch.resize(e_, n);
  if (contacts.mu != nullptr) grew |= touch.resize(mu_, n);
  if (geometry) {
    for (ScratchVector<T>& values : geometry_) grew |= touch.resize(values, n);
  }
  touch.run(arena);
  // The identity order: written once, for the whole storage, when it grows
  // (those writes touch its pages); a smaller size keeps the values.
  if (resize_scratch(identity_, n)) {
    grew = true;
    std::uint32_t* const identity = identity_.data();
    for_parts(arena, n, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) identity[i] = static_cast<std::uint32_t>(i);
    });
  }
  return grew;
}

template <class T>
KernelJob<T> PreparedContacts<T>::prepare(tbb::task_arena& arena, const KernelJob<T>& job, RunGeometryKernel<T> form) {
  const ContactView<T>& contacts = job.contacts;
  const std::uint32_t* order = job.order;
  const std::size_t n = contacts.count;
  const bool point = has_point(contacts);
  assert(a_.size() == n && identity_.size() == n && (form == nullptr || geometry_[0].size() == n));

  ContactView<T> v;
  v.count = n;
  v.a = a_.data();
  v.b = b_.data();
  v.n = {n_[0].data(), n_[1].data(), n_[2].data()};
  if (point) v.c = {c_[0].data(), c_[1].data(), c_[2].data()};
  v.e = contacts.e != nullptr ? e_.data() : nullptr;
  v.uniform_e = contacts.uniform_e;
  v.mu = contacts.mu != nullptr ? mu_.data() : nullptr;
  impulses_.count = n;
  impulses_.j = {j_[0].data(), j_[1].data(), j_[2].data()};
  KernelJob<T> on_prepared = job;
  on_prepared.contacts = v;
  on_prepared.impulses = impulses_;
  on_prepared.order = identity_.data();
  on_prepared.stepped = form != nullptr;
  on_prepared.geometry = {};
  if (form != nullptr) {
    GeometryView<T>& g = on_prepared.geometry;
    for (std::size_t k = 0; k < 3; ++k) {
      g.ra[k] = geometry_[k].data();
      g.rb[k] = geometry_[3 + k].data();
      g.response_a[k] = geometry_[6 + k].data();
      g.response_b[k] = geometry_[9 + k].data();
    }
    g.k_a = geometry_[12].data();
    g.k_b = geometry_[13].data();
    g.inv_mass_a = geometry_[14].data();
    g.inv_mass_b = geometry_[15].data();
  }

  for_parts(arena, n, [&](std::size_t begin, std::size_t end) {
    gather(a_.data(), contacts.a, order, begin, end);
    gather(b_.data(), contacts.b, order, begin, end);
    if (point) {
      gather(c_[0].data(), contacts.c.x, order, begin, end);
      gather(c_[1].data(), contacts.c.y, order, begin, end);
      gather(c_[2].data(), contacts.c.z, order, begin, end);
    }
    gather(n_[0].data(), contacts.n.x, order, begin, end);
    gather(n_[1].data(), contacts.n.y, order, begin, end);
    gather(n_[2].data(), contacts.n.z, order, begin, end);
    if (contacts.e != nullptr) gather(e_.data(), contacts.e, order, begin, end);
    if (contacts.mu != nullptr) gather(mu_.data(), contacts.mu, order, begin, end);
    // Positions and orientations are the bodies' as the solve starts: no
    // contact changes them, so the geometry formed now serves every pass.
    if (form != nullptr) form(on_prepared, begin, end - begin, on_prepared.geometry.from(begin));
  });
  return on_prepared;
}

template <class T>
void PreparedContacts<T>::write_back(tbb::task_arena& arena, const ImpulseView<T>& impulses,
                                     const std::uint32_t* order) const {
  for_parts(arena, impulses_.count, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t k = order[i];
      impulses.j.x[k] = impulses_.j.x[i];
      impulses.j.y[k] = impulses_.j.y[i];
      impulses.j.z[k] = impulses_.j.z[i];
    }
  });
}

template class PreparedContacts<float>;
template class PreparedContacts<double>;

}  // namespace collide::detail
