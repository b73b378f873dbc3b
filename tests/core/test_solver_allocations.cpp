// test_solver_allocations.cpp - a reused Solver allocates nothing once its
// buffers are sized, and reports the solve that sized them
// (SolveStats::allocate_seconds).
//
// What this proves
// ----------------
// * A second solve of the same scene on the same Solver performs no heap
//   allocation: no call of the global operator new (replaced in this binary
//   to count its calls) and none of detail::allocate_large (its own count),
//   in the input and the colour order, with one pass and four (the stepped
//   path of prepared_contacts.hpp), in float and double, on SoA input solved
//   in place and packed into the solver's buffer (a pile of 20,000 contacts;
//   and one of 600,000, whose arrays take huge pages, in the colour order
//   with four passes, packed). Nor does a smaller solve after it, or the
//   same size again after the smaller one.
// * The counts can fail: the first solve of a fresh Solver in the colour
//   order, or packed, does allocate (its prepared contacts, its records).
// * allocate_seconds is finite and positive for a solve that sized the
//   buffers, and exactly 0 for the solves that found them sized.
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <initializer_list>
#include <new>
#include <string>

#include <gtest/gtest.h>

#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/large_allocator.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"

namespace {

std::atomic<std::size_t> g_news{0};

void* counted_new(std::size_t n) {
  g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}

void* counted_aligned_new(std::size_t n, std::align_val_t align) {
  g_news.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (std::max<std::size_t>(n, 1) + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}

}  // namespace

// The replaceable global allocation functions, counting every call. (The
// nothrow forms of libstdc++ call these.)
void* operator new(std::size_t n) { return counted_new(n); }
void* operator new[](std::size_t n) { return counted_new(n); }
void* operator new(std::size_t n, std::align_val_t a) { return counted_aligned_new(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_aligned_new(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace collide::test {
namespace {

/// Calls of operator new and of allocate_large so far.
struct Allocations {
  std::size_t news = g_news.load();
  std::size_t large = detail::large_allocation_count();

  /// The calls since this count was taken.
  [[nodiscard]] std::size_t since() const {
    return (g_news.load() - news) + (detail::large_allocation_count() - large);
  }
};

/// A pile of about `contacts` contacts, generated once per size.
template <class T, std::size_t kContacts>
const Scene<T>& pile_of() {
  static const Scene<T> scene = [] {
    GenerateOptions o;
    o.seed = 3;
    return generate_pile<T>(pile_side_for_contacts(kContacts), o);
  }();
  return scene;
}

/// About 600,000 contacts: prepared arrays of megabytes, past the huge-page
/// size of allocate_large.
template <class T>
const Scene<T>& pile() {
  return pile_of<T, 600000>();
}

/// About 20,000 contacts: every buffer of the solver, in arrays below the
/// huge-page size. Allocations are counted the same way at either size, so
/// the choices of order, passes and layout are walked on this one, and the
/// large pile checks the huge-page arrays in one choice (its solves are
/// most of this test's time, under the sanitizers most of all).
template <class T>
const Scene<T>& small_pile() {
  return pile_of<T, 20000>();
}

std::string describe(Order order, int passes, BodyLayout layout) {
  return std::string(to_string(order)) + " order, " + std::to_string(passes) + " pass(es), " + to_string(layout);
}

template <class T>
void check_reuse_allocates_nothing(const Scene<T>& original, std::initializer_list<Order> orders,
                                   std::initializer_list<int> pass_counts, std::initializer_list<BodyLayout> layouts) {
  for (const Order order : orders) {
    for (const int passes : pass_counts) {
      for (const BodyLayout layout : layouts) {
        SCOPED_TRACE(describe(order, passes, layout));
        Scene<T> scene = original;
        const ContactView<T> contacts = scene.contacts.view();
        const BodyView<T> bodies = scene.bodies.view();
        ImpulseBuffer<T> impulses(scene.contacts.size());
        Schedule schedule(order);
        schedule.build(contacts, bodies);
        // The schedule of a smaller solve: the first half of the contacts.
        ContactView<T> half = contacts;
        half.count = contacts.count / 2;
        ImpulseView<T> half_j = impulses.view();
        half_j.count = half.count;
        Schedule half_schedule(order);
        half_schedule.build(half, bodies);

        SolverOptions options;
        options.passes = passes;
        options.layout = layout;
        const Solver solver(options);

        const Allocations before_first;
        const SolveStats first = solver.solve(bodies, contacts, impulses.view(), schedule);
        const std::size_t first_allocations = before_first.since();
        EXPECT_TRUE(std::isfinite(first.allocate_seconds));
        EXPECT_GE(first.allocate_seconds, 0.0);
        // Colour-order solves of a pile copy their contacts into the
        // solver's arrays, packed ones their bodies: both are new.
        if (order == Order::colour || layout == BodyLayout::packed) {
          EXPECT_GT(first_allocations, 0u);
          EXPECT_GT(first.allocate_seconds, 0.0);
        }

        const Allocations before_second;
        const SolveStats second = solver.solve(bodies, contacts, impulses.view(), schedule);
        EXPECT_EQ(before_second.since(), 0u) << "the second solve allocated";
        EXPECT_EQ(second.allocate_seconds, 0.0);

        const Allocations before_smaller;
        const SolveStats smaller = solver.solve(bodies, half, half_j, half_schedule);
        EXPECT_EQ(before_smaller.since(), 0u) << "the smaller solve allocated";
        EXPECT_EQ(smaller.allocate_seconds, 0.0);

        const Allocations before_again;
        const SolveStats again = solver.solve(bodies, contacts, impulses.view(), schedule);
        EXPECT_EQ(before_again.since(), 0u) << "the full size after the smaller one allocated";
        EXPECT_EQ(again.allocate_seconds, 0.0);
      }
    }
  }
}

template <class T>
void check_reuse_allocates_nothing() {
  {
    SCOPED_TRACE("a pile of 20,000 contacts");
    check_reuse_allocates_nothing(small_pile<T>(), {Order::input, Order::colour}, {1, 4},
                                  {BodyLayout::soa, BodyLayout::packed});
  }
  SCOPED_TRACE("a pile of 600,000 contacts");
  check_reuse_allocates_nothing(pile<T>(), {Order::colour}, {4}, {BodyLayout::packed});
}

TEST(SolverAllocations, ASecondSolveAllocatesNothingInFloat) { check_reuse_allocates_nothing<float>(); }

TEST(SolverAllocations, ASecondSolveAllocatesNothingInDouble) { check_reuse_allocates_nothing<double>(); }

TEST(SolverAllocations, TheOneShotSolveReportsItsAllocatePhase) {
  Scene<float> scene = pile<float>();
  ImpulseBuffer<float> impulses(scene.contacts.size());
  const SolveStats stats = solve(scene.bodies.view(), scene.contacts.view(), impulses.view(), {}, Order::colour);
  EXPECT_TRUE(std::isfinite(stats.allocate_seconds));
  EXPECT_GT(stats.allocate_seconds, 0.0);
}

}  // namespace
}  // namespace collide::test
