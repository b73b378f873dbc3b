// collide/schedule.hpp - the order in which contacts that share bodies are applied.
//
// Design notes
// ------------
// The law applies contacts that share a body one after another, each seeing
// the velocities the earlier ones left. To run them on SIMD lanes and threads
// at once, contacts are grouped into batches in which no movable body appears
// twice; the batches run one after another, the contacts inside a batch in
// any order and on any lane or thread. The result is the law applied
// sequentially in solve_order(), the same bits for every thread count. Two orders
// exist (docs/collision-law.md, "The solve order"):
//
// Order::input, the level schedule: contact k goes to the batch one past the
// latest batch of any earlier contact that touches one of its movable
// bodies. So the contacts of every body are applied in input order, and the
// result is exactly the law applied to the contacts in input order. A pile
// is then about a thousand batches deep and a chain one batch per contact.
//
// Order::colour, an order collide chooses from the input alone, as physics
// engines do (Box2D's graph colours, Jolt's splits, Bepu's batches): the
// input is cut into windows of kColourWindow contacts, each window's
// contacts are coloured greedily in input order over their movable bodies
// (a contact takes the lowest of kMaxColours colours that no earlier contact
// of the window on one of its bodies holds; those that find none form the
// window's overflow), and the solve order is window by window, colour by
// colour, then the overflow as the law orders it. A pile or a chain is a
// few batches per window. Every body still sees its contacts of one window
// after those of the windows before, but within a window in colour order: a
// different, equally valid sequential impulse pass, which several passes
// (SolverOptions::passes) carry to the same resting state.
//
// Level windows (input order). On a scattered scene (debris: random bodies)
// the plain rule puts a contact of level 0 everywhere in the input, and of
// level 1, 2, ... too, so every batch spans the whole input and the kernel
// reads each line of the contact arrays once per batch that has a contact in
// it. So the rule has a floor: the input is cut into windows of kLevelWindow
// contacts, and when the window before was shallow (its contacts' levels span
// fewer than kShallowWindowLevels), the contacts of the next one go no lower
// than the highest level so far. A shallow window's contacts then fill a few
// batches of their own, read from one stretch of the input while it is in
// cache. A deep window (a pile swept cell by cell, a chain) sets no floor:
// its levels already follow the input. The floor only ever raises a level,
// so every body still sees its contacts in input order and the result is the
// same, bit for bit.
//
// Immovable bodies (inverse mass 0) are never written by the kernels, so they
// never conflict: a million debris contacts on one ground body form one batch.
//
// Building. A scene in which no movable body is in two contacts (independent
// pairs) is one batch in either order, found on every thread in one pass
// over the contacts and a check (one_batch.hpp). Otherwise the input order's
// levels are assigned in one sequential pass (level_pass.hpp) and grouped by
// a stable counting sort on threads (batch_sort.hpp); the colour order's
// windows are coloured and grouped in parallel (colour_pass.hpp). Passes run
// in the task arena of the calling thread (TBB's default arena unless called
// inside a tbb::task_arena::execute), on at most `threads` threads; the
// schedule is the same for every thread count, bit for bit.
//
// A schedule depends only on the contacts' body indices and on which bodies
// are immovable: a solver keeps one across frames while the contact set holds
// and rebuilds it when a or b change.
//
// Memory: 4 bytes per contact for solve_order(), 5 per batch, and scratch kept
// between builds, so a schedule rebuilt for a scene of the same size does
// not allocate: input order 1 byte per contact and per body (5 and 5 for a
// scene of 254 batches or more), colour order 1 byte per contact and 4 per
// body for each thread that colours.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/packed.hpp"
#include "collide/schedule_windows.hpp"

namespace collide {

/// The order a solve applies contacts in (design notes above).
enum class Order {
  input,   ///< the law in input order: every body sees its contacts in input order
  colour,  ///< windows of contacts, each coloured over its movable bodies; colour by colour
};

/// "input" or "colour".
const char* to_string(Order order);
/// Parses the names of to_string(); throws std::invalid_argument otherwise
/// (for "color": "... did you mean 'colour'?").
Order parse_order(std::string_view name);

class Schedule {
 public:
  /// Contacts per level window of the input order (design notes above).
  static constexpr std::size_t kLevelWindow = schedule_windows::kLevelWindow;
  /// A window whose levels span fewer than this raises the floor of the next.
  static constexpr std::uint32_t kShallowWindowLevels = schedule_windows::kShallowWindowLevels;
  /// Contacts per window of the colour order.
  static constexpr std::size_t kColourWindow = schedule_windows::kColourWindow;
  /// Colours a window of the colour order may use before its overflow.
  static constexpr std::uint32_t kMaxColours = schedule_windows::kMaxColours;

  /// An empty schedule that build() fills in `order`.
  explicit Schedule(Order order = Order::input);
  ~Schedule();
  Schedule(const Schedule& other);
  Schedule& operator=(const Schedule& other);
  Schedule(Schedule&& other) noexcept;
  Schedule& operator=(Schedule&& other) noexcept;

  /// Builds the schedule in order(). Bodies with inv_mass == 0
  /// do not conflict. `bodies` is any body view (BodyView, SphereView,
  /// ParticleView): only its count and inverse masses are read. `threads`:
  /// at most this many threads; 0 means the concurrency of the calling
  /// thread's task arena. The result does not depend on it.
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

  /// The order this schedule is built in: the one owner of the choice. A
  /// Solver runs whatever schedule it is given in the schedule's order.
  [[nodiscard]] Order order() const { return order_; }
  /// Number of contacts the schedule was built for.
  [[nodiscard]] std::size_t contact_count() const { return contact_count_; }
  /// Number of bodies the schedule was built for.
  [[nodiscard]] std::size_t body_count() const { return body_count_; }
  /// Number of batches; batches run in order.
  [[nodiscard]] std::size_t batch_count() const { return batch_count_; }
  /// Contacts of batch k are solve_order()[batch_begin(k)] .. solve_order()[batch_begin(k+1) - 1].
  [[nodiscard]] std::size_t batch_begin(std::size_t k) const { return batch_begin_[k]; }
  /// Contact indices, grouped by batch, ascending inside each batch: the
  /// solve order (contact_count() of them).
  [[nodiscard]] const std::uint32_t* solve_order() const { return solve_order_; }
  /// True when batch k holds consecutive contacts, so that contact arrays can
  /// be loaded as vectors rather than gathered (a scene with no shared movable
  /// body is one such batch).
  [[nodiscard]] bool batch_is_contiguous(std::size_t k) const { return contiguous_[k] != 0; }
  /// Largest number of contacts in one batch.
  [[nodiscard]] std::size_t largest_batch() const { return largest_batch_; }
  /// Number of contact pairs that share a movable body and are consecutive in
  /// that body's contact list: the dependencies the schedule had to respect
  /// (in the colour order, those within a window).
  [[nodiscard]] std::size_t conflicts() const { return conflicts_; }
  /// The colour order: colours used by the most colourful window (0 for the
  /// input order and for no contacts).
  [[nodiscard]] std::size_t colours() const { return colours_; }
  /// The colour order: contacts in the windows' overflows (0 for the input order).
  [[nodiscard]] std::size_t overflow_contacts() const { return overflow_contacts_; }
  /// Bytes the schedule holds, its scratch included (capacity, not size).
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  /// build() with body i's inverse mass at inv_mass[i * stride].
  template <class T>
  void build_strided(const ContactView<T>& contacts, std::size_t body_count, const T* inv_mass, std::size_t stride,
                     int threads);
  /// Points the accessors at the Impl's arrays and counts.
  void publish();
  /// Empties the schedule (a build that throws leaves it so).
  void clear();

  struct Impl;
  std::unique_ptr<Impl> impl_;
  Order order_ = Order::input;
  std::size_t contact_count_ = 0;
  std::size_t body_count_ = 0;
  std::size_t batch_count_ = 0;
  std::size_t largest_batch_ = 0;
  std::size_t conflicts_ = 0;
  std::size_t colours_ = 0;
  std::size_t overflow_contacts_ = 0;
  const std::uint32_t* solve_order_ = nullptr;
  const std::uint32_t* batch_begin_ = nullptr;
  const std::uint8_t* contiguous_ = nullptr;
};

}  // namespace collide
