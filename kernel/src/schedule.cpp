// schedule.cpp - the level schedule of schedule.hpp.
//
// One pass in input order gives each contact its batch: one past the latest
// batch of its movable bodies. A stable counting sort then groups contacts by
// batch, ascending inside each. O(contacts + bodies + batches), sequential:
// the level of contact k depends on every earlier contact, and the pass costs
// a small fraction of one solve (bench: BM_ScheduleBuild).
#include <algorithm>
#include <cassert>

#include "collide/schedule.hpp"

namespace collide {

template <class T>
void Schedule::build(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass) {
  const std::size_t n = contacts.count;
  contact_count_ = n;
  body_count_ = body_count;
  conflicts_ = 0;
  level_.resize(n);
  body_next_.assign(body_count, 0);

  std::uint32_t levels = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const BodyIndex a = contacts.a[k];
    const BodyIndex b = contacts.b[k];
    assert(a < body_count && b < body_count);
    const bool movable_a = inv_mass[a] != T(0);
    const bool movable_b = inv_mass[b] != T(0);
    const std::uint32_t after_a = movable_a ? body_next_[a] : 0;
    const std::uint32_t after_b = movable_b ? body_next_[b] : 0;
    conflicts_ += static_cast<std::size_t>(after_a > 0) + static_cast<std::size_t>(after_b > 0);
    const std::uint32_t level = std::max(after_a, after_b);
    level_[k] = level;
    if (movable_a) body_next_[a] = level + 1;
    if (movable_b) body_next_[b] = level + 1;
    levels = std::max(levels, level + 1);
  }

  // Stable counting sort by level. batch_begin_[L + 1] counts level L, the
  // prefix sum turns counts into starts, and filling advances
  // batch_begin_[L] to the end of level L; shifting by one restores starts.
  batch_begin_.assign(static_cast<std::size_t>(levels) + 1, 0);
  for (std::size_t k = 0; k < n; ++k) ++batch_begin_[level_[k] + 1];
  for (std::size_t L = 1; L <= levels; ++L) batch_begin_[L] += batch_begin_[L - 1];
  order_.resize(n);
  for (std::size_t k = 0; k < n; ++k) order_[batch_begin_[level_[k]]++] = static_cast<std::uint32_t>(k);
  for (std::size_t L = levels; L > 0; --L) batch_begin_[L] = batch_begin_[L - 1];
  batch_begin_[0] = 0;

  contiguous_.assign(levels, 0);
  largest_batch_ = 0;
  for (std::size_t L = 0; L < levels; ++L) {
    const std::size_t begin = batch_begin_[L];
    const std::size_t end = batch_begin_[L + 1];
    largest_batch_ = std::max(largest_batch_, end - begin);
    // Ascending and distinct, so consecutive exactly when the span fits.
    contiguous_[L] = static_cast<std::uint8_t>(order_[end - 1] - order_[begin] == end - begin - 1);
  }
}

std::size_t Schedule::memory_bytes() const {
  return order_.capacity() * sizeof(std::uint32_t) + level_.capacity() * sizeof(std::uint32_t) +
         body_next_.capacity() * sizeof(std::uint32_t) + batch_begin_.capacity() * sizeof(std::uint32_t) +
         contiguous_.capacity() * sizeof(std::uint8_t);
}

template void Schedule::build<float>(const ContactView<float>&, std::size_t, const float*);
template void Schedule::build<double>(const ContactView<double>&, std::size_t, const double*);
template void Schedule::build<long double>(const ContactView<long double>&, std::size_t, const long double*);

}  // namespace collide
