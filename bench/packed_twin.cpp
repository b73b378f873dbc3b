// bench/packed_twin.cpp - see packed_twin.hpp.
#include "packed_twin.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include "ordered_contacts.hpp"

namespace collide_bench {
namespace {
// A value the compiler cannot prove zero, so the adds are not folded away.
volatile double g_packed_zero = 0;
// Where the loaded values end up, so that the loads are not dropped.
volatile double g_packed_sink = 0;
constexpr std::size_t kAhead = 32;  // contacts; as the kernel (COLLIDE_PREFETCH_AHEAD)
constexpr std::size_t kBlock = 1024;
}  // namespace

template <class T>
void packed_twin_pass(oneapi::tbb::task_arena& arena, const collide::PackedView<collide::PackedRigid<T>>& records,
                      const collide::ContactView<T>& contacts, const collide::ImpulseView<T>& impulses,
                      const collide::Schedule& schedule) {
  static collide::detail::OrderedContacts<T> ordered;  // grown once, reused (the bench is one thread)
  const T zero = static_cast<T>(g_packed_zero);
  const std::size_t n = contacts.count;
  collide::PackedRigid<T>* bodies = records.bodies;
  arena.execute([&] {
    const collide::ContactView<T> c = ordered.gather(contacts, schedule.order());
    const collide::ImpulseView<T> j = ordered.impulses(n);
    auto prefetch = [&](std::size_t k) {
      for (const std::uint32_t i : {c.a[k], c.b[k]}) {
        const char* p = reinterpret_cast<const char*>(bodies + i);
        for (std::size_t off = 0; off < sizeof(collide::PackedRigid<T>); off += 64) __builtin_prefetch(p + off, 0, 2);
      }
    };
    auto run = [&](std::size_t begin, std::size_t end) {
      // One accumulator per record value: the loads feed short, independent
      // add chains, so the loop waits on memory and not on a chain of adds
      // (a single running sum made the twin slower than the kernel).
      T acc[17] = {};
      for (std::size_t k = begin; k < std::min(end, begin + kAhead); ++k) prefetch(k);
      for (std::size_t k = begin; k < end; ++k) {
        if (k + kAhead < end) prefetch(k + kAhead);
        collide::PackedRigid<T>& a = bodies[c.a[k]];
        collide::PackedRigid<T>& b = bodies[c.b[k]];
        T sum = c.c.x[k] + c.c.y[k] + c.c.z[k] + c.n.x[k] + c.n.y[k] + c.n.z[k];
        if (c.e) sum += c.e[k];
        if (c.mu) sum += c.mu[k];
        const T* va = a.v;  // the 17 values, v first
        const T* vb = b.v;
        for (std::size_t f = 0; f < 17; ++f) acc[f] += va[f] + vb[f];
        // As the kernel: v and w of movable bodies only (the ground body is
        // in a quarter of the contacts and is never written).
        if (a.inv_mass != 0) {
          for (std::size_t f = 0; f < 3; ++f) a.v[f] += zero * sum, a.w[f] += zero * sum;
        }
        if (b.inv_mass != 0) {
          for (std::size_t f = 0; f < 3; ++f) b.v[f] -= zero * sum, b.w[f] -= zero * sum;
        }
        j.j.x[k] = zero * sum, j.j.y[k] = zero * sum, j.j.z[k] = zero * sum;
      }
      T total = 0;
      for (const T x : acc) total += x;
      g_packed_sink = static_cast<double>(total);
    };
    for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
      const std::size_t begin = schedule.batch_begin(k);
      const std::size_t end = schedule.batch_begin(k + 1);
      const std::size_t blocks = (end - begin + kBlock - 1) / kBlock;
      oneapi::tbb::parallel_for(
          oneapi::tbb::blocked_range<std::size_t>(0, blocks, 1),
          [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
            for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
              run(begin + bi * kBlock, std::min(end, begin + (bi + 1) * kBlock));
            }
          },
          oneapi::tbb::simple_partitioner());
    }
    ordered.scatter(j, impulses, schedule.order());
  });
}

template void packed_twin_pass<float>(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedRigid<float>>&,
                                      const collide::ContactView<float>&, const collide::ImpulseView<float>&,
                                      const collide::Schedule&);
template void packed_twin_pass<double>(oneapi::tbb::task_arena&,
                                       const collide::PackedView<collide::PackedRigid<double>>&,
                                       const collide::ContactView<double>&, const collide::ImpulseView<double>&,
                                       const collide::Schedule&);

}  // namespace collide_bench
