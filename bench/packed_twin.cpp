// bench/packed_twin.cpp - see packed_twin.hpp.
#include "packed_twin.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

namespace collide_bench {
namespace {
// A value the compiler cannot prove zero, so the adds are not folded away.
volatile double g_packed_zero = 0;
// Where the loaded values end up, so that the loads are not dropped.
volatile double g_packed_sink = 0;

/// 16 bytes of T as one vector (GCC/Clang vector extension; SSE2 registers in
/// the baseline build).
template <class T>
struct RowOf;
template <>
struct RowOf<float> {
  typedef float type __attribute__((vector_size(16)));  // NOLINT(modernize-use-using): attribute on a typedef
};
template <>
struct RowOf<double> {
  typedef double type __attribute__((vector_size(16)));  // NOLINT(modernize-use-using): attribute on a typedef
};
// Contacts ahead whose records are requested: the kernel's kPrefetchAhead,
// set by the build (COLLIDE_PREFETCH_AHEAD, cmake/options.cmake).
constexpr std::size_t kAhead = COLLIDE_PREFETCH_AHEAD;
constexpr std::size_t kBlock = 1024;
constexpr std::size_t kGroup = 16;  // contacts whose loads precede their stores: the kernel's float lanes on AVX-512
}  // namespace

template <class Record>
void packed_twin_pass(oneapi::tbb::task_arena& arena, const collide::PackedView<Record>& records,
                      const collide::ContactView<typename collide::PackedValue<Record>::type>& contacts,
                      const collide::ImpulseView<typename collide::PackedValue<Record>::type>& impulses,
                      const collide::Schedule& schedule) {
  using T = typename collide::PackedValue<Record>::type;
  // The values the kernel reads (v first, as every record starts) and writes.
  using Row = typename RowOf<T>::type;
  constexpr std::size_t kRows = sizeof(Record) / sizeof(Row);
  static_assert(sizeof(Record) % sizeof(Row) == 0 && alignof(Record) >= sizeof(Row));
  constexpr std::size_t kWritten = kWrittenValues<Record>;
  const T zero = static_cast<T>(g_packed_zero);
  const std::uint32_t* order = schedule.solve_order();
  const collide::ContactView<T>& c = contacts;
  const collide::ImpulseView<T>& j = impulses;
  Record* bodies = records.bodies;
  arena.execute([&] {
    // As the kernel (kernel/loops.hpp, solve_groups): a contact's own lines
    // (its body indices, fields and J) are requested 2 kAhead contacts
    // ahead, its records kAhead ahead (reading the indices the first
    // request brought in, not missing on them).
    auto prefetch_contact = [&](std::size_t p) {
      const std::uint32_t k = order[p];
      __builtin_prefetch(c.a + k, 0, 2);
      __builtin_prefetch(c.b + k, 0, 2);
      for (const T* f : {c.c.x, c.c.y, c.c.z, c.n.x, c.n.y, c.n.z}) __builtin_prefetch(f + k, 0, 2);
      if (c.e != nullptr) __builtin_prefetch(c.e + k, 0, 2);
      if (c.mu != nullptr) __builtin_prefetch(c.mu + k, 0, 2);
      for (T* f : {j.j.x, j.j.y, j.j.z}) __builtin_prefetch(f + k, 1, 2);
    };
    auto prefetch_records = [&](std::size_t p) {
      const std::uint32_t k = order[p];
      for (const std::uint32_t i : {c.a[k], c.b[k]}) {
        const char* r = reinterpret_cast<const char*>(bodies + i);
        for (std::size_t off = 0; off < sizeof(Record); off += 64) __builtin_prefetch(r + off, 0, 2);
        if constexpr (std::is_same_v<Record, collide::PackedRigid<T>>) __builtin_prefetch(records.inv_mass + i, 0, 2);
      }
    };
    auto run = [&](std::size_t begin, std::size_t end) {
      // The records are read as 16-byte rows into one accumulator per row
      // (every line of the record, as the kernel's row loads): short,
      // independent add chains of vector adds, so the loop waits on memory
      // and not on arithmetic, and a twin is a ceiling only if it is not
      // slower than the kernel it bounds.
      //
      // Contacts go in groups of kGroup, as the kernel's lanes: every load
      // of a group (indices, fields, both records, the inverse masses) comes
      // before its stores, so that no store's address, which waits on an
      // inverse-mass load, holds the next contact's loads back.
      Row acc[kRows] = {};
      Record spare{};
      for (std::size_t p = begin; p < std::min(end, begin + 2 * kAhead); ++p) prefetch_contact(p);
      for (std::size_t p = begin; p < std::min(end, begin + kAhead); ++p) prefetch_records(p);
      for (std::size_t g = begin; g < end; g += kGroup) {
        const std::size_t n = std::min(kGroup, end - g);
        for (std::size_t p = g + 2 * kAhead; p < std::min(end, g + n + 2 * kAhead); ++p) prefetch_contact(p);
        for (std::size_t p = g + kAhead; p < std::min(end, g + n + kAhead); ++p) prefetch_records(p);
        T* write_a[kGroup];
        T* write_b[kGroup];
        T sum[kGroup];
        std::uint32_t contact[kGroup];
        for (std::size_t l = 0; l < n; ++l) {
          const std::uint32_t k = order[g + l];
          const std::uint32_t ia = c.a[k];
          const std::uint32_t ib = c.b[k];
          contact[l] = k;
          T x = c.c.x[k] + c.c.y[k] + c.c.z[k] + c.n.x[k] + c.n.y[k] + c.n.z[k];
          if (c.e) x += c.e[k];
          if (c.mu) x += c.mu[k];
          sum[l] = x;
          const auto* ra = reinterpret_cast<const Row*>(bodies + ia);
          const auto* rb = reinterpret_cast<const Row*>(bodies + ib);
          for (std::size_t r = 0; r < kRows; ++r) acc[r] += ra[r] + rb[r];
          // As the kernel: v and w of movable bodies only (the ground body
          // is in a quarter of the contacts and is never written). Stores of
          // an immovable body go to a record of this thread's own (a select,
          // not a branch: the ground side is random). The values are the
          // record's, v first (collide/packed.hpp: standard layout).
          write_a[l] = collide::packed_inv_mass(records, ia) != 0 ? reinterpret_cast<T*>(bodies + ia)
                                                                  : reinterpret_cast<T*>(&spare);
          write_b[l] = collide::packed_inv_mass(records, ib) != 0 ? reinterpret_cast<T*>(bodies + ib)
                                                                  : reinterpret_cast<T*>(&spare);
        }
        // v and w (or v) are the first kWritten values: written as whole
        // 16-byte rows, as the kernel writes a record with one masked row
        // store (the row's other values are rewritten unchanged: within a
        // batch no other contact touches a movable body; adding zero keeps
        // every finite value but -0).
        constexpr std::size_t kWrittenRows = (kWritten * sizeof(T) + sizeof(Row) - 1) / sizeof(Row);
        for (std::size_t l = 0; l < n; ++l) {
          const T d = zero * sum[l];
          Row* ra = reinterpret_cast<Row*>(write_a[l]);
          Row* rb = reinterpret_cast<Row*>(write_b[l]);
          for (std::size_t r = 0; r < kWrittenRows; ++r) ra[r] += d;
          for (std::size_t r = 0; r < kWrittenRows; ++r) rb[r] -= d;
          const std::uint32_t k = contact[l];
          j.j.x[k] = d, j.j.y[k] = d, j.j.z[k] = d;
        }
      }
      Row total = {};
      for (const Row& x : acc) total += x;
      g_packed_sink = static_cast<double>(total[0]);
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
  });
}

template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedRigid<float>>&,
                               const collide::ContactView<float>&, const collide::ImpulseView<float>&,
                               const collide::Schedule&);
template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedRigid<double>>&,
                               const collide::ContactView<double>&, const collide::ImpulseView<double>&,
                               const collide::Schedule&);
template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedSphere<float>>&,
                               const collide::ContactView<float>&, const collide::ImpulseView<float>&,
                               const collide::Schedule&);
template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedSphere<double>>&,
                               const collide::ContactView<double>&, const collide::ImpulseView<double>&,
                               const collide::Schedule&);
template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedParticle<float>>&,
                               const collide::ContactView<float>&, const collide::ImpulseView<float>&,
                               const collide::Schedule&);
template void packed_twin_pass(oneapi::tbb::task_arena&, const collide::PackedView<collide::PackedParticle<double>>&,
                               const collide::ContactView<double>&, const collide::ImpulseView<double>&,
                               const collide::Schedule&);

}  // namespace collide_bench
