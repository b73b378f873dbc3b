// test_dispatch.cpp - the kernel tables (core/src/kernel_table.hpp): every
// loop of every table is reached, and a solve reaches the slots of its own
// choices and no other.
//
// Each slot of a table is swapped for a trampoline of its own that counts its
// calls and calls the loop it replaced (the tables are writable for this,
// writable_kernel_table), so the counts are the calls the driver made through
// each slot, and the library carries nothing of the test. Two tests:
//   * one solve per choice (model, precision, accuracy mode, friction,
//     layout) on each ISA this CPU has and on the scalar path: the slot of
//     that choice is called, and no other slot of the tables (the counts can
//     tell the slots apart, and a slot that two choices shared would fail);
//   * a catalogue of small scenes, every choice in both orders, on each ISA:
//     every slot of the ISA's table and of the one-lane table is called
//     (a slot that no solve reaches fails, naming the slot).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "kernel_table.hpp"
#include "support/scenes.hpp"

namespace collide::test {
namespace {

using detail::GroupLoop;
using detail::GroupLoops;
using detail::KernelLoops;
using detail::RunGeometryKernel;
using detail::RunKernel;
using detail::RunWalkKernel;

// ---------------------------------------------------------------------------
// Counting trampolines
// ---------------------------------------------------------------------------

/// Slot I of the array named by Tag: its original loop and its calls.
template <class Tag, class Fn, std::size_t I>
struct Trampoline;
template <class Tag, class R, class... A, std::size_t I>
struct Trampoline<Tag, R (*)(A...), I> {
  static inline R (*original)(A...) = nullptr;
  static inline std::atomic<std::size_t> calls{0};
  static R call(A... a) {
    calls.fetch_add(1, std::memory_order_relaxed);
    return original(a...);
  }
};

/// While alive, the N slots from `first` (an array of a table, flattened)
/// call their trampolines.
template <class Tag, class Fn, std::size_t N>
class CountedSlots {
 public:
  explicit CountedSlots(Fn* first) : first_(first) { install(std::make_index_sequence<N>{}); }
  ~CountedSlots() { restore(std::make_index_sequence<N>{}); }
  CountedSlots(const CountedSlots&) = delete;
  CountedSlots& operator=(const CountedSlots&) = delete;

  [[nodiscard]] std::array<std::size_t, N> calls() const { return counts(std::make_index_sequence<N>{}); }
  void reset() { zero(std::make_index_sequence<N>{}); }
  /// Every slot held a loop before the swap.
  [[nodiscard]] bool all_filled() const { return filled_; }

 private:
  template <std::size_t... I>
  void install(std::index_sequence<I...>) {
    filled_ = ((first_[I] != nullptr) && ...);
    ((Trampoline<Tag, Fn, I>::original = first_[I], Trampoline<Tag, Fn, I>::calls = 0,
      first_[I] = &Trampoline<Tag, Fn, I>::call),
     ...);
  }
  template <std::size_t... I>
  void restore(std::index_sequence<I...>) {
    ((first_[I] = Trampoline<Tag, Fn, I>::original), ...);
  }
  template <std::size_t... I>
  std::array<std::size_t, N> counts(std::index_sequence<I...>) const {
    return {Trampoline<Tag, Fn, I>::calls.load(std::memory_order_relaxed)...};
  }
  template <std::size_t... I>
  void zero(std::index_sequence<I...>) {
    ((Trampoline<Tag, Fn, I>::calls = 0), ...);
  }

  Fn* first_;
  bool filled_ = false;
};

/// An array's slot count and first slot.
template <class Array>
constexpr std::size_t kSlots = sizeof(Array) / sizeof(std::remove_all_extents_t<Array>);
template <class Array>
auto* first_slot(Array& a) {
  return reinterpret_cast<std::remove_all_extents_t<Array>*>(&a);
}

template <int kTable, class T, int kArray>
struct Tag {};

enum ArrayId { kSolve, kStep, kRun, kGeometry, kWalk, kAccumulate, kAccumulateStep };

/// A slot's name: the array and the choices of its index.
std::string slot_name(int array, std::size_t i) {
  static const char* const models[] = {"particle", "sphere", "rigid"};
  static const char* const arrays[] = {"solve", "step", "run", "geometry", "walk", "accumulate", "accumulate_step"};
  std::string name = std::string(arrays[array]) + "[";
  if (array == kSolve) {
    name += std::string(models[i / 8]) + (i / 4 % 2 ? ", accurate" : ", fast") +
            (i / 2 % 2 ? ", friction" : ", frictionless");
  } else if (array == kAccumulate) {
    name += std::string(models[i / 4]) + (i / 2 % 2 ? ", friction" : ", frictionless");
  } else {
    name += models[i / 2];
  }
  return name + (i % 2 ? ", packed]" : ", soa]");
}

/// What a table's slots were called: (slot name, calls) per slot.
using Calls = std::vector<std::pair<std::string, std::size_t>>;

template <int kArray, std::size_t N>
void append(Calls& out, const std::string& table, const std::array<std::size_t, N>& calls) {
  for (std::size_t i = 0; i < N; ++i) out.emplace_back(table + " " + slot_name(kArray, i), calls[i]);
}

/// Every slot of a table's group loops, counted.
template <int kTable, class T>
class CountedGroupLoops {
 public:
  explicit CountedGroupLoops(GroupLoops<T>& loops)
      : solve_(first_slot(loops.solve)),
        step_(first_slot(loops.step)),
        accumulate_(first_slot(loops.accumulate)),
        accumulate_step_(first_slot(loops.accumulate_step)) {}
  void append_to(Calls& out, const std::string& table) const {
    append<kSolve>(out, table, solve_.calls());
    append<kStep>(out, table, step_.calls());
    append<kAccumulate>(out, table, accumulate_.calls());
    append<kAccumulateStep>(out, table, accumulate_step_.calls());
  }
  [[nodiscard]] bool all_filled() const {
    return solve_.all_filled() && step_.all_filled() && accumulate_.all_filled() && accumulate_step_.all_filled();
  }

 private:
  CountedSlots<Tag<kTable, T, kSolve>, GroupLoop<T>, kSlots<decltype(GroupLoops<T>::solve)>> solve_;
  CountedSlots<Tag<kTable, T, kStep>, GroupLoop<T>, kSlots<decltype(GroupLoops<T>::step)>> step_;
  CountedSlots<Tag<kTable, T, kAccumulate>, GroupLoop<T>, kSlots<decltype(GroupLoops<T>::accumulate)>> accumulate_;
  CountedSlots<Tag<kTable, T, kAccumulateStep>, GroupLoop<T>, kSlots<decltype(GroupLoops<T>::accumulate_step)>>
      accumulate_step_;
};

/// Every slot of an ISA's loops of one precision, counted.
template <int kTable, class T>
class CountedKernelLoops {
 public:
  explicit CountedKernelLoops(KernelLoops<T>& loops)
      : groups_(loops.groups),
        run_(first_slot(loops.run)),
        geometry_(first_slot(loops.geometry)),
        walk_(first_slot(loops.walk)) {}
  void append_to(Calls& out, const std::string& table) const {
    groups_.append_to(out, table);
    append<kRun>(out, table, run_.calls());
    append<kGeometry>(out, table, geometry_.calls());
    append<kWalk>(out, table, walk_.calls());
  }
  [[nodiscard]] bool all_filled() const {
    return groups_.all_filled() && run_.all_filled() && geometry_.all_filled() && walk_.all_filled();
  }

 private:
  CountedGroupLoops<kTable, T> groups_;
  CountedSlots<Tag<kTable, T, kRun>, RunKernel<T>, kSlots<decltype(KernelLoops<T>::run)>> run_;
  CountedSlots<Tag<kTable, T, kGeometry>, RunGeometryKernel<T>, kSlots<decltype(KernelLoops<T>::geometry)>> geometry_;
  CountedSlots<Tag<kTable, T, kWalk>, RunWalkKernel<T>, kSlots<decltype(KernelLoops<T>::walk)>> walk_;
};

/// Every slot of one ISA's table and of the one-lane table, both
/// precisions, counted from construction to destruction.
template <int kIsaTable>
class CountedTables {
 public:
  explicit CountedTables(Isa isa)
      : isa_float_(detail::writable_kernel_table(isa).loops_float),
        isa_double_(detail::writable_kernel_table(isa).loops_double),
        one_float_(detail::writable_one_lane_table().loops_float),
        one_double_(detail::writable_one_lane_table().loops_double),
        isa_name_(to_string(isa)) {}

  /// (slot, calls) for every slot: the ISA's table's, then the one-lane table's.
  [[nodiscard]] Calls isa_calls() const {
    Calls out;
    isa_float_.append_to(out, isa_name_ + " float");
    isa_double_.append_to(out, isa_name_ + " double");
    return out;
  }
  [[nodiscard]] Calls one_lane_calls() const {
    Calls out;
    one_float_.append_to(out, "one-lane float");
    one_double_.append_to(out, "one-lane double");
    return out;
  }
  [[nodiscard]] bool all_filled() const {
    return isa_float_.all_filled() && isa_double_.all_filled() && one_float_.all_filled() && one_double_.all_filled();
  }

 private:
  CountedKernelLoops<kIsaTable, float> isa_float_;
  CountedKernelLoops<kIsaTable, double> isa_double_;
  CountedGroupLoops<0, float> one_float_;
  CountedGroupLoops<0, double> one_double_;
  std::string isa_name_;
};

// ---------------------------------------------------------------------------
// Scenes and solves
// ---------------------------------------------------------------------------

/// One choice of the tables' arrays.
struct Choice {
  Model model = Model::rigid;
  bool accurate = false;
  bool friction = false;
  bool packed = false;
  bool accumulates = false;  ///< Iteration::accumulate (fast mode only)
};

std::vector<Choice> every_choice() {
  std::vector<Choice> out;
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    for (const bool accurate : {false, true}) {
      for (const bool friction : {false, true}) {
        for (const bool packed : {false, true}) {
          out.push_back({model, accurate, friction, packed});
          if (!accurate) out.push_back({model, accurate, friction, packed, true});
        }
      }
    }
  }
  return out;
}

/// The slot of a choice: its array (GroupLoops::solve, or ::accumulate) and
/// its index there, flattened.
std::string choice_slot(const Choice& c) {
  const auto model = static_cast<std::size_t>(c.model);
  if (c.accumulates) return slot_name(kAccumulate, model * 4 + (c.friction ? 2 : 0) + (c.packed ? 1 : 0));
  return slot_name(kSolve, model * 8 + (c.accurate ? 4 : 0) + (c.friction ? 2 : 0) + (c.packed ? 1 : 0));
}

std::string describe(const Choice& c) {
  return std::string(to_string(c.model)) + (c.accurate ? " accurate" : " fast") +
         (c.friction ? " friction" : " frictionless") + (c.packed ? " packed" : " soa") +
         (c.accumulates ? " accumulate" : "");
}

/// `pairs` independent pairs (contact k joins bodies 2k and 2k + 1): one
/// contiguous batch, whose count is a multiple of no lane width (a tail).
template <class T>
SceneRecords<T> pairs(std::size_t count, bool friction) {
  SceneOptions o;
  o.seed = 7;
  o.friction = friction;
  return pairs_records<T>(count, o);
}

/// 40 independent pairs, and between them 40 contacts that all share one
/// movable hub body. In the input order: one batch of 41 contacts, then a
/// run of 39 one-contact batches. In the colour order: a colour of 41
/// contacts that are not consecutive in the input (so the solve prepares
/// them), 23 colours of one contact, and 16 contacts of the overflow, one
/// level each: runs of one-contact batches.
template <class T>
SceneRecords<T> pairs_and_hub(bool friction) {
  SceneRecords<T> s = pairs<T>(80, friction);
  const auto hub = static_cast<BodyIndex>(s.bodies.size());
  s.bodies.push_back(s.bodies[1]);
  for (std::size_t k = 1; k < s.contacts.size(); k += 2) s.contacts[k].b = hub;
  return s;
}

template <class T>
void solve_choice(const SceneRecords<T>& records, const Choice& c, Path path, Isa isa, Order order, int passes) {
  Scene<T> scene = records.scene();
  SolverOptions o;
  o.path = path;
  o.isa = isa;
  o.threads = 1;
  o.accuracy = c.accurate ? Accuracy::accurate : Accuracy::fast;
  o.layout = c.packed ? BodyLayout::packed : BodyLayout::soa;
  o.passes = passes;
  o.iteration = c.accumulates ? Iteration::accumulate : Iteration::repeat;
  const ContactView<T> contacts = scene.contacts.view();
  ASSERT_EQ(contacts.mu != nullptr, c.friction);
  const BodyView<T> bodies = scene.bodies.view();
  Schedule schedule(order);
  schedule.build(contacts, bodies);
  ImpulseBuffer<T> j(contacts.count);
  const Solver solver(o);
  SolveStats stats;
  switch (c.model) {
    case Model::particle:
      stats = solver.solve(particle_view(bodies), contacts, j.view(), schedule);
      break;
    case Model::sphere:
      stats = solver.solve(sphere_view(bodies), contacts, j.view(), schedule);
      break;
    case Model::rigid:
      stats = solver.solve(bodies, contacts, j.view(), schedule);
      break;
  }
  EXPECT_EQ(stats.model, c.model);
  EXPECT_EQ(stats.layout, c.packed ? BodyLayout::packed : BodyLayout::soa);
  EXPECT_EQ(stats.friction, c.friction);
  if (path == Path::simd) {
    EXPECT_EQ(stats.isa, isa);
  }
}

/// The slots of `calls` that were called, by name.
std::vector<std::string> called(const Calls& calls) {
  std::vector<std::string> out;
  for (const auto& [name, n] : calls) {
    if (n > 0) out.push_back(name);
  }
  return out;
}
std::vector<std::string> never_called(const Calls& calls) {
  std::vector<std::string> out;
  for (const auto& [name, n] : calls) {
    if (n == 0) out.push_back(name);
  }
  return out;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += "\n  " + n;
  return out.empty() ? " (none)" : out;
}

/// f.template operator()<kTable>(isa) for every concrete ISA this CPU has,
/// kTable naming the ISA's counters (the one-lane table is 0).
template <class F>
void for_each_isa(const F& f) {
  for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
    if (!isa_supported(isa)) continue;
    SCOPED_TRACE(to_string(isa));
    switch (isa) {
      case Isa::sse2:
        f.template operator()<1>(isa);
        break;
      case Isa::avx2:
        f.template operator()<2>(isa);
        break;
      default:
        f.template operator()<3>(isa);
        break;
    }
  }
}

// ---------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------

/// One solve of one choice: exactly its slots are called.
template <class T, int kTable>
void expect_only_its_slots(Isa isa, Path path) {
  const std::string precision = std::is_same_v<T, float> ? "float" : "double";
  for (const Choice& c : every_choice()) {
    SCOPED_TRACE(describe(c) + " " + precision + (path == Path::simd ? " simd" : " scalar"));
    const SceneRecords<T> scene = pairs<T>(37, c.friction);
    CountedTables<kTable> counted(isa);
    ASSERT_TRUE(counted.all_filled());
    solve_choice(scene, c, path, isa, Order::input, 1);
    const std::string slot = precision + " " + choice_slot(c);
    // SIMD: the ISA's loop of the choice, and the one-lane loop of the same
    // choice for the tail (37 is a multiple of no width); the scalar path:
    // the one-lane loop alone.
    std::vector<std::string> expected_isa;
    if (path == Path::simd) expected_isa.push_back(std::string(to_string(isa)) + " " + slot);
    EXPECT_EQ(called(counted.isa_calls()), expected_isa);
    EXPECT_EQ(called(counted.one_lane_calls()), std::vector<std::string>{"one-lane " + slot});
  }
}

TEST(KernelDispatch, ASolveCallsTheSlotsOfItsChoiceAndNoOther) {
  for_each_isa([]<int kTable>(Isa isa) {
    expect_only_its_slots<float, kTable>(isa, Path::simd);
    expect_only_its_slots<double, kTable>(isa, Path::simd);
  });
  expect_only_its_slots<float, 1>(Isa::sse2, Path::scalar);
  expect_only_its_slots<double, 1>(Isa::sse2, Path::scalar);
}

/// The catalogue of one precision on one path: every choice on the pairs
/// and the hub, in the input order with one pass and in the colour order
/// with two (where the fast frictionless law takes the velocity step on
/// its stored geometry).
template <class T>
void solve_catalogue(Isa isa, Path path) {
  for (const bool friction : {false, true}) {
    const SceneRecords<T> scene = pairs_and_hub<T>(friction);
    for (const Choice& c : every_choice()) {
      if (c.friction != friction) continue;
      SCOPED_TRACE(describe(c));
      solve_choice(scene, c, path, isa, Order::input, 1);
      solve_choice(scene, c, path, isa, Order::colour, 2);
    }
  }
}

TEST(KernelDispatch, TheCatalogueReachesEverySlot) {
  for_each_isa([]<int kTable>(Isa isa) {
    CountedTables<kTable> counted(isa);
    ASSERT_TRUE(counted.all_filled());
    solve_catalogue<float>(isa, Path::simd);
    solve_catalogue<double>(isa, Path::simd);
    const Calls isa_calls = counted.isa_calls();
    const Calls one_lane_calls = counted.one_lane_calls();
    EXPECT_EQ(isa_calls.size(), 2u * (24 + 6 + 12 + 6 + 6 + 6 + 6));
    EXPECT_EQ(one_lane_calls.size(), 2u * (24 + 6 + 12 + 6));
    EXPECT_TRUE(never_called(isa_calls).empty()) << "never called:" << joined(never_called(isa_calls));
    EXPECT_TRUE(never_called(one_lane_calls).empty()) << "never called:" << joined(never_called(one_lane_calls));
  });
}

TEST(KernelDispatch, TheScalarPathReachesEveryOneLaneSlotAndNoSimdLoop) {
  CountedTables<1> counted(Isa::sse2);
  solve_catalogue<float>(Isa::sse2, Path::scalar);
  solve_catalogue<double>(Isa::sse2, Path::scalar);
  const Calls one_lane_calls = counted.one_lane_calls();
  EXPECT_TRUE(never_called(one_lane_calls).empty()) << "never called:" << joined(never_called(one_lane_calls));
  // Of the SIMD table, only the geometry that the colour order's two passes
  // store once (in lanes) before every pass takes the velocity step in one.
  for (const std::string& name : called(counted.isa_calls())) {
    EXPECT_NE(name.find(" geometry["), std::string::npos) << name << " was called on the scalar path";
  }
}

}  // namespace
}  // namespace collide::test
