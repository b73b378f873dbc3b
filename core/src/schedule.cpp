// schedule.cpp - Schedule::build: the passes of schedule.hpp put together.
//
// The input order: one batch (one_batch.hpp), else the body table and the
// level pass in bytes (level_pass.hpp), switched to 32-bit words at the
// first contact whose level does not fit, then the stable sort by level
// (batch_sort.hpp). The colour order: one batch, else the windows' colours
// (colour_pass.hpp). The arrays behind the accessors live in Impl, with the
// passes' scratch, kept from build to build.
#include "collide/schedule.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <oneapi/tbb/task_arena.h>

#include "batch_sort.hpp"
#include "collide/labels.hpp"
#include "colour_pass.hpp"
#include "level_pass.hpp"
#include "one_batch.hpp"
#include "scratch_vector.hpp"

namespace collide {

struct Schedule::Impl {
  Labels order;
  detail::Batches batches;
  // Scratch. The input order's body table and levels: bytes, and words once
  // the levels outgrow bytes. The one-batch test uses the byte table.
  detail::ScratchVector<std::uint8_t> table8;
  detail::ScratchVector<std::uint8_t> level8;
  Labels table32;
  Labels level32;
  std::vector<std::uint32_t> slot;  // the sort's per-chunk counts; the one-batch probe's set
  detail::ColourScratch colour;

  /// The input order's batches of contacts that are not one batch; returns
  /// the conflicts.
  template <class T>
  std::size_t level_schedule(const detail::ContactIndices& contacts, const detail::InverseMasses<T>& inv_mass,
                             std::size_t workers);
};

template <class T>
std::size_t Schedule::Impl::level_schedule(const detail::ContactIndices& contacts,
                                           const detail::InverseMasses<T>& inv_mass, std::size_t workers) {
  using detail::kImmovableWord;
  const std::size_t n = contacts.count;
  level8.resize(n);
  detail::fill_body_table(inv_mass, 0, contacts.body_count, table8.data());
  detail::LevelState state;
  const std::size_t stop = detail::assign_levels(contacts, 0, table8.data(), level8.data(), state);
  const bool runs = state.floor > 0;  // the level windows set floors: most neighbours share a level
  if (stop == n) {
    detail::sort_by_level(detail::LevelLabels<std::uint8_t>{level8.data(), n, state.levels}, workers, runs,
                          order.data(), batches, slot);
    return state.conflicts;
  }
  // The levels outgrew bytes at contact `stop`: words from there on.
  table32.resize(contacts.body_count);
  level32.resize(n);
  for (std::size_t i = 0; i < contacts.body_count; ++i) {
    table32[i] = table8[i] == kImmovableWord<std::uint8_t> ? kImmovableWord<std::uint32_t> : table8[i];
  }
  std::copy(level8.begin(), level8.begin() + static_cast<std::ptrdiff_t>(stop), level32.begin());
  detail::assign_levels(contacts, stop, table32.data(), level32.data(), state);
  detail::sort_by_level(detail::LevelLabels<std::uint32_t>{level32.data(), n, state.levels}, workers, runs,
                        order.data(), batches, slot);
  return state.conflicts;
}

Schedule::Schedule(Order order) : impl_(std::make_unique<Impl>()), order_(order) {}
Schedule::~Schedule() = default;

Schedule::Schedule(Schedule&& other) noexcept { *this = std::move(other); }

Schedule& Schedule::operator=(Schedule&& other) noexcept {
  if (this == &other) return *this;
  impl_ = std::move(other.impl_);
  order_ = other.order_;
  contact_count_ = std::exchange(other.contact_count_, 0);
  body_count_ = std::exchange(other.body_count_, 0);
  batch_count_ = std::exchange(other.batch_count_, 0);
  largest_batch_ = std::exchange(other.largest_batch_, 0);
  conflicts_ = std::exchange(other.conflicts_, 0);
  colours_ = std::exchange(other.colours_, 0);
  overflow_contacts_ = std::exchange(other.overflow_contacts_, 0);
  solve_order_ = std::exchange(other.solve_order_, nullptr);
  batch_begin_ = std::exchange(other.batch_begin_, nullptr);
  contiguous_ = std::exchange(other.contiguous_, nullptr);
  return *this;
}

Schedule::Schedule(const Schedule& other) : Schedule(other.order_) { *this = other; }

Schedule& Schedule::operator=(const Schedule& other) {
  if (this == &other) return *this;
  if (!impl_) impl_ = std::make_unique<Impl>();
  // The result, not the scratch.
  impl_->order.assign(other.solve_order_, other.solve_order_ + other.contact_count_);
  if (other.impl_) {
    impl_->batches = other.impl_->batches;
  } else {
    impl_->batches = detail::Batches{};
  }
  order_ = other.order_;
  contact_count_ = other.contact_count_;
  body_count_ = other.body_count_;
  conflicts_ = other.conflicts_;
  colours_ = other.colours_;
  overflow_contacts_ = other.overflow_contacts_;
  publish();
  return *this;
}

void Schedule::publish() {
  const detail::Batches& b = impl_->batches;
  batch_count_ = b.count();
  largest_batch_ = b.largest;
  solve_order_ = impl_->order.data();
  batch_begin_ = b.begin.data();
  contiguous_ = b.contiguous.data();
}

void Schedule::clear() {
  if (!impl_) impl_ = std::make_unique<Impl>();
  contact_count_ = 0;
  body_count_ = 0;
  conflicts_ = 0;
  colours_ = 0;
  overflow_contacts_ = 0;
  // order keeps its size: every entry is rewritten by a build that
  // succeeds, and clearing it made the resize write the whole array once
  // more (its cost: docs/decisions/0023-fresh-arrays-touched-where-they-are-written.md).
  impl_->batches.begin.clear();
  impl_->batches.contiguous.clear();
  impl_->batches.largest = 0;
  publish();
}

template <class T>
void Schedule::build_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass,
                             std::size_t stride, int threads) {
  clear();
  if (threads < 0) {
    throw std::invalid_argument("collide::Schedule::build: threads must be >= 0, got " + std::to_string(threads));
  }
  const std::size_t n = contacts.count;
  if (n >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error("collide::Schedule::build: " + std::to_string(n) +
                            " contacts; a schedule holds at most 2^32 - 2");
  }
  if (n > 0 && (contacts.a == nullptr || contacts.b == nullptr)) {
    throw std::invalid_argument("collide::Schedule::build: contacts.a or contacts.b is null but contacts.count = " +
                                std::to_string(n));
  }
  if (body_count > 0 && inv_mass == nullptr) {
    throw std::invalid_argument("collide::Schedule::build: bodies.inv_mass is null but bodies.count = " +
                                std::to_string(body_count));
  }
  const std::size_t workers = threads > 0
                                  ? static_cast<std::size_t>(threads)
                                  : static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  Impl& s = *impl_;
  try {
    s.order.resize(n);
    s.table8.resize(body_count);
    const detail::ContactIndices indices{contacts.a, contacts.b, n, body_count};
    const detail::InverseMasses<T> masses{inv_mass, stride};
    std::size_t conflicts = 0;
    if (detail::one_batch(indices, masses, workers, s.table8.data(), s.order.data(), s.slot)) {
      s.batches.begin.assign({std::uint32_t{0}, static_cast<std::uint32_t>(n)});
      s.batches.contiguous.assign(1, 1);
      s.batches.largest = n;
      colours_ = order_ == Order::colour ? 1 : 0;
    } else if (order_ == Order::input) {
      conflicts = s.level_schedule(indices, masses, workers);
    } else {
      const detail::ColourSummary summary =
          detail::colour_contacts(indices, masses, workers, s.colour, s.order.data(), s.batches);
      conflicts = summary.conflicts;
      colours_ = summary.colours;
      overflow_contacts_ = summary.overflow;
    }
    contact_count_ = n;
    body_count_ = body_count;
    conflicts_ = conflicts;
    publish();
  } catch (...) {
    clear();
    throw;
  }
}

std::size_t Schedule::memory_bytes() const {
  if (!impl_) return 0;  // moved from
  const Impl& s = *impl_;
  std::size_t bytes = (s.order.capacity() + s.table32.capacity() + s.level32.capacity() + s.slot.capacity() +
                       s.batches.begin.capacity()) *
                          sizeof(std::uint32_t) +
                      s.batches.contiguous.capacity() + s.table8.capacity() + s.level8.capacity() +
                      s.colour.label.capacity();
  for (const auto& v : s.colour.masks) bytes += v.capacity() * sizeof(std::uint32_t);
  for (const auto& v : s.colour.levels) bytes += v.capacity() * sizeof(std::uint32_t);
  for (const auto& v : s.colour.batches) bytes += v.capacity() * sizeof(std::uint32_t);
  return bytes;
}

template void Schedule::build_strided<float>(const ContactView<float>&, std::size_t, const float*, std::size_t, int);
template void Schedule::build_strided<double>(const ContactView<double>&, std::size_t, const double*, std::size_t, int);
template void Schedule::build_strided<long double>(const ContactView<long double>&, std::size_t, const long double*,
                                                   std::size_t, int);

}  // namespace collide
