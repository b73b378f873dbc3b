// bench/memory_twin.cpp - the memory-only twin of a body model's kernel
// (design notes in memory_twin.hpp).
#include "memory_twin.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <vector>

#include "collide/eval/traffic.hpp"
#include "lanes.hpp"

namespace collide_bench {

namespace {

// A runtime zero the compiler cannot fold: x + zero * acc is a real read and
// a real write of x.
volatile double g_zero = 0;

/// The arrays of one model, in the order the kernel reads them
/// (solve.cpp, read_bodies and solve_group).
template <class T>
struct TwinArrays {
  std::vector<const T*> body_read;
  std::vector<T*> body_written;
  std::vector<const T*> contact_read;
};

template <class T>
TwinArrays<T> arrays_of(collide::Model model, const collide::BodyView<T>& b, const collide::ContactView<T>& c) {
  using collide::Model;
  TwinArrays<T> a;
  a.body_read.push_back(b.inv_mass);
  if (model == Model::rigid) {
    a.body_read.insert(a.body_read.end(),
                       {b.inv_inertia.x, b.inv_inertia.y, b.inv_inertia.z, b.q.w, b.q.x, b.q.y, b.q.z});
  } else if (model == Model::sphere) {
    a.body_read.push_back(b.inv_inertia.x);
  }
  if (model != Model::particle) a.body_read.insert(a.body_read.end(), {b.p.x, b.p.y, b.p.z});
  a.body_read.insert(a.body_read.end(), {b.v.x, b.v.y, b.v.z});
  a.body_written.insert(a.body_written.end(), {b.v.x, b.v.y, b.v.z});
  if (model != Model::particle) {
    a.body_read.insert(a.body_read.end(), {b.w.x, b.w.y, b.w.z});
    a.body_written.insert(a.body_written.end(), {b.w.x, b.w.y, b.w.z});
  }
  if (model != Model::particle) a.contact_read.insert(a.contact_read.end(), {c.c.x, c.c.y, c.c.z});
  a.contact_read.insert(a.contact_read.end(), {c.n.x, c.n.y, c.n.z});
  if (c.e) a.contact_read.push_back(c.e);
  if (c.mu) a.contact_read.push_back(c.mu);
  // The same arrays that collide/eval/traffic.hpp counts for the model, or the
  // twin's GB/s would not be comparable with the kernel's.
  const std::size_t contact_values = (model == Model::particle ? 0 : 3) + 3 + (c.e ? 1 : 0) + (c.mu ? 1 : 0);
  if (a.body_read.size() != collide::body_values_read(model) ||
      a.body_written.size() != collide::body_values_written(model) || a.contact_read.size() != contact_values) {
    throw std::logic_error("memory_twin: the twin's arrays differ from collide/eval/traffic.hpp's count");
  }
  return a;
}

}  // namespace

template <class T>
void memory_twin_pass(collide::Model model, oneapi::tbb::task_arena& arena, const collide::BodyView<T>& bodies,
                      const collide::ContactView<T>& contacts, const collide::ImpulseView<T>& impulses) {
  constexpr std::size_t kBlock = 1024;  // contacts per task, as SolverOptions::block
  const TwinArrays<T> arrays = arrays_of(model, bodies, contacts);
  const T zero = static_cast<T>(g_zero);
  const std::size_t n = contacts.count;

  using V = collide::detail::SimdLanes<T>;
  constexpr std::size_t W = V::size();
  // One group of W contacts from k, with the lane layer's own loads and
  // stores (lanes.hpp): the twin touches memory exactly as the kernel's
  // paired-layout path does, with one add per value in place of the law.
  auto group = [&](std::size_t k) {
    V acc = V(static_cast<T>(contacts.a[k] + contacts.b[k + W - 1]));
    V acc_even(0), acc_odd(0);
    // Pairs layout: the group's bodies are the 2W from the first a.
    const std::size_t first = contacts.a[k];
    assert(first + 2 * W <= bodies.count);
    for (const T* f : arrays.body_read) {
      V even, odd;
      collide::detail::load_deinterleaved(f + first, even, odd);
      acc_even += even;
      acc_odd += odd;
    }
    for (const T* f : arrays.contact_read) acc += collide::detail::load<V>(f + k);
    for (T* f : arrays.body_written) {
      V even, odd;
      collide::detail::load_deinterleaved(f + first, even, odd);
      collide::detail::store_interleaved(even + zero * acc_even, odd + zero * acc_odd, f + first);
    }
    for (T* f : {impulses.j.x, impulses.j.y, impulses.j.z}) collide::detail::store(zero * (acc + acc_even), f + k);
  };
  auto run_block = [&](std::size_t begin, std::size_t end) {
    std::size_t k = begin;
    for (; k + W <= end; k += W) group(k);
    // The kernel's scalar tail; the pairs scenes of the grid have none.
    for (; k < end; ++k) {
      T sum = 0;
      const std::size_t first = contacts.a[k];
      for (const T* f : arrays.body_read) sum += f[first] + f[first + 1];
      for (const T* f : arrays.contact_read) sum += f[k];
      for (T* f : arrays.body_written) {
        f[first] += zero * sum;
        f[first + 1] += zero * sum;
      }
      for (T* f : {impulses.j.x, impulses.j.y, impulses.j.z}) f[k] = zero * sum;
    }
  };

  arena.execute([&] {
    const std::size_t blocks = (n + kBlock - 1) / kBlock;
    oneapi::tbb::parallel_for(
        oneapi::tbb::blocked_range<std::size_t>(0, blocks, 1),
        [&](const oneapi::tbb::blocked_range<std::size_t>& r) {
          for (std::size_t bi = r.begin(); bi != r.end(); ++bi) run_block(bi * kBlock, std::min(n, (bi + 1) * kBlock));
        },
        oneapi::tbb::simple_partitioner());
  });
}

template void memory_twin_pass<float>(collide::Model, oneapi::tbb::task_arena&, const collide::BodyView<float>&,
                                      const collide::ContactView<float>&, const collide::ImpulseView<float>&);
template void memory_twin_pass<double>(collide::Model, oneapi::tbb::task_arena&, const collide::BodyView<double>&,
                                       const collide::ContactView<double>&, const collide::ImpulseView<double>&);

}  // namespace collide_bench
