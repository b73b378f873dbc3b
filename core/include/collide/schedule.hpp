// collide/schedule.hpp - the order in which contacts that share bodies are applied.
//
// Design notes
// ------------
// The law applies contacts that share a body one after another, each seeing
// the velocities the earlier ones left. To run them on SIMD lanes and threads
// at once, contacts are grouped into batches in which no movable body appears
// twice; the batches run one after another, the contacts inside a batch in
// any order and on any lane or thread.
//
// The grouping is a level schedule rather than a greedy colouring: contact k
// goes to the batch one past the latest batch of any earlier contact that
// touches one of its movable bodies. So the contacts of every body are applied
// in input order, and the result is exactly the law applied to the contacts in
// input order, the schedule that the reference and the documentation state. A
// greedy colouring would give fewer batches on some graphs, but a result that
// depends on the colouring heuristic; this one depends only on the input.
//
// Level windows. On a scattered scene (debris: random bodies) the plain rule
// puts a contact of level 0 everywhere in the input, and of level 1, 2, ...
// too, so every batch spans the whole input and the kernel reads each line of
// the contact arrays once per batch that has a contact in it. So the rule has
// a floor: the input is cut into windows of kLevelWindow contacts, and when the
// window before was shallow (its contacts' levels span fewer than
// kShallowWindowLevels), the contacts of the next one go no lower than the
// highest level so far. A
// shallow window's contacts then fill a few batches of their own, read from
// one stretch of the input while it is in cache. A deep window (a pile swept
// cell by cell, a chain) sets no floor: its levels already follow the input.
// The floor only ever raises a level, so every body still sees its contacts
// in input order and the result is the same, bit for bit; the batches depend
// on the input alone, not on the thread count.
//
// Immovable bodies (inverse mass 0) are never written by the kernels, so they
// never conflict: a million debris contacts on one ground body form one batch.
//
// Building is sequential where it must be: the batch of contact k depends on
// every earlier contact, so one pass in input order assigns batches (with the
// body words it will need prefetched, schedule.cpp). A scene in which no
// movable body is in two contacts (independent pairs) is found to be one
// batch on every thread instead, in one pass over the contacts and a check
// (schedule.cpp, "One batch"). Grouping contacts by
// batch is a stable counting sort that runs on threads, in the task arena of
// the calling thread (TBB's default arena unless called inside a
// tbb::task_arena::execute), or on at most `threads` threads. The schedule is
// the same for every thread count, bit for bit.
//
// Memory: 4 bytes per contact for `order`, 1 per contact and 1 per body of
// scratch (4 and 4 for a scene of 254 batches or more), 5 per batch, and when
// the sort runs on more than one thread at most 1 byte per contact of
// per-thread counts. Buffers are kept
// between builds, so a schedule rebuilt for a scene of the same size does not
// allocate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/labels.hpp"
#include "collide/packed.hpp"

namespace collide {

class Schedule {
 public:
  /// Contacts per level window (design notes above).
  static constexpr std::size_t kLevelWindow = std::size_t{1} << 16;
  /// A window whose levels span fewer than this raises the floor of the next.
  static constexpr std::uint32_t kShallowWindowLevels = 16;

  /// Builds the schedule. Bodies with inv_mass == 0 do not conflict.
  /// `bodies` is any body view (BodyView, SphereView, ParticleView): only
  /// its count and inverse masses are read. `threads`: at most this many
  /// threads; 0 means the concurrency of the calling thread's task arena.
  /// The result does not depend on it.
  /// Checked in every build type, before an index is used: every index is
  /// < bodies.count and a != b in every contact; std::invalid_argument
  /// naming the first contact that breaks it ("collide::Schedule::build:
  /// contacts.a[17] = 40: out of range (8 bodies)"). Also
  /// std::invalid_argument if threads < 0 or contacts.a, contacts.b or the
  /// inverse masses are null with a count > 0, and std::length_error beyond
  /// 2^32 - 2 contacts. A build that throws leaves the schedule empty
  /// (contact_count(), body_count() and batch_count() are 0), so no solve of
  /// the scene can use it. The values (inverse masses, ...) are not checked:
  /// that is validate()'s.
  template <class T, template <class> class View>
  void build(const ContactView<T>& contacts, const View<T>& bodies, int threads = 0) {
    build(contacts, bodies.count, static_cast<const T*>(bodies.inv_mass), threads);
  }
  /// The same for any body model: only the inverse masses matter.
  template <class T>
  void build(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, int threads = 0) {
    build_strided(contacts, body_count, inv_mass, 1, threads);
  }
  /// The same on packed records (collide/packed.hpp): the inverse masses are
  /// read in place from the records (a rigid view's dense inv_mass array), so
  /// a caller who keeps its bodies packed needs no other copy of them.
  template <class Record>
  void build(const ContactView<typename PackedValue<Record>::type>& contacts, const PackedView<Record>& bodies,
             int threads = 0) {
    using T = typename PackedValue<Record>::type;
    const T* inv_mass = bodies.count != 0 && bodies.bodies != nullptr ? &bodies.bodies->inv_mass : nullptr;
    build_strided(contacts, bodies.count, inv_mass, sizeof(Record) / sizeof(T), threads);
  }
  template <class T>
  void build(const ContactView<T>& contacts, const PackedView<PackedRigid<T>>& bodies, int threads = 0) {
    build_strided(contacts, bodies.count, static_cast<const T*>(bodies.inv_mass), 1, threads);
  }

  /// Number of contacts the schedule was built for.
  [[nodiscard]] std::size_t contact_count() const { return contact_count_; }
  /// Number of bodies the schedule was built for.
  [[nodiscard]] std::size_t body_count() const { return body_count_; }
  /// Number of batches; batches run in order.
  [[nodiscard]] std::size_t batch_count() const { return batch_begin_.empty() ? 0 : batch_begin_.size() - 1; }
  /// Contacts of batch k are order()[batch_begin(k)] .. order()[batch_begin(k+1) - 1].
  [[nodiscard]] std::size_t batch_begin(std::size_t k) const { return batch_begin_[k]; }
  /// Contact indices, grouped by batch, ascending inside each batch.
  [[nodiscard]] const std::uint32_t* order() const { return order_.data(); }
  /// True when batch k holds consecutive contacts, so that contact arrays can
  /// be loaded as vectors rather than gathered (a scene with no shared movable
  /// body is one such batch).
  [[nodiscard]] bool batch_is_contiguous(std::size_t k) const { return contiguous_[k] != 0; }
  /// Largest number of contacts in one batch.
  [[nodiscard]] std::size_t largest_batch() const { return largest_batch_; }
  /// Number of contact pairs that share a movable body and are consecutive in
  /// that body's contact list: the dependencies the schedule had to respect.
  [[nodiscard]] std::size_t conflicts() const { return conflicts_; }
  /// Bytes the schedule holds (capacity, not size).
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  /// build() with body i's inverse mass at inv_mass[i * stride].
  template <class T>
  void build_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, std::size_t stride,
                     int threads);

  std::size_t contact_count_ = 0;
  std::size_t body_count_ = 0;
  std::size_t largest_batch_ = 0;
  std::size_t conflicts_ = 0;
  /// Passes 3 and 4 of schedule.cpp: groups contacts by level. `runs`: the
  /// level windows set a floor, so most neighbours share a level.
  template <class Level>
  void sort_by_level(const Level* level, std::uint32_t levels, std::size_t workers, bool runs);

  // Uninitialised when they grow (labels.hpp): every build writes all it
  // reads of them, and the first touch of a fresh one happens in those
  // passes, on every thread where they run on every thread.
  Labels order_;
  Labels level_;      // scratch: batch of each contact (bytes while batches < 254)
  Labels body_next_;  // scratch: first free batch of each body (bytes, likewise)
  std::vector<std::uint32_t> batch_begin_;
  std::vector<std::uint8_t> contiguous_;
  std::vector<std::uint32_t> slot_;  // scratch: per-chunk counts, then slots, of the parallel sort; the one-batch probe
};

extern template void Schedule::build<float>(const ContactView<float>&, std::size_t, const float*, int);
extern template void Schedule::build<double>(const ContactView<double>&, std::size_t, const double*, int);
extern template void Schedule::build<long double>(const ContactView<long double>&, std::size_t, const long double*,
                                                  int);

}  // namespace collide
