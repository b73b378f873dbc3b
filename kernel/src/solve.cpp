// solve.cpp - the driver: walks the schedule, gathers contacts and bodies into
// lanes, runs the kernel body of contact_kernel.hpp, scatters the results.
//
// Design notes
// ------------
// * Batches run one after another; inside a batch no movable body appears
//   twice, so blocks of a batch run on any thread and contacts in any lane.
//   The result of a contact depends only on its own two bodies, so the thread
//   count and the block size cannot change a single bit.
// * A block is processed W contacts at a time; the last (block size mod W)
//   contacts of a batch run through the same kernel instantiated for W = 1.
//   Same operations, same order, no FMA: the tail is bitwise what a lane
//   would have produced.
// * Contiguous batches (every scene without shared movable bodies, like the
//   pairs scene) load contact fields as vectors; only the first index of
//   each group is read from `order`.
// * Immovable bodies are gathered but never written: many lanes may read the
//   one ground body at once, none writes it.
// * Nothing here allocates: the Solver owns its task_arena, the Schedule owns
//   the order.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/solve.hpp"
#include "contact_kernel.hpp"

namespace collide {
namespace detail {
namespace {

/// Where the W contacts of a group come from: consecutive indices starting at
/// `first` (contiguous batch) or the W indices at `index`.
struct ContactGroup {
  bool contiguous;
  std::uint32_t first;
  const std::uint32_t* index;
};

template <class V, class T>
COLLIDE_LANE_INLINE V contact_field(const T* field, const ContactGroup& g) {
  return g.contiguous ? load<V>(field + g.first) : gather<V>(field, g.index);
}

template <class V, class T>
COLLIDE_LANE_INLINE void gather_body(const BodyView<T>& bodies, const BodyIndex* ids, BodyLanes<V>& out) {
  out.inv_mass = gather<V>(bodies.inv_mass, ids);
  out.inv_inertia = {gather<V>(bodies.inv_inertia.x, ids), gather<V>(bodies.inv_inertia.y, ids),
                     gather<V>(bodies.inv_inertia.z, ids)};
  out.rotation = rotation(gather<V>(bodies.q.w, ids), gather<V>(bodies.q.x, ids), gather<V>(bodies.q.y, ids),
                          gather<V>(bodies.q.z, ids));
  out.p = {gather<V>(bodies.p.x, ids), gather<V>(bodies.p.y, ids), gather<V>(bodies.p.z, ids)};
  out.v = {gather<V>(bodies.v.x, ids), gather<V>(bodies.v.y, ids), gather<V>(bodies.v.z, ids)};
  out.w = {gather<V>(bodies.w.x, ids), gather<V>(bodies.w.y, ids), gather<V>(bodies.w.z, ids)};
}

template <class V, class T>
COLLIDE_LANE_INLINE void scatter_body(const BodyLanes<V>& body, const BodyView<T>& bodies, const BodyIndex* ids) {
  const auto movable = body.inv_mass != V(0);
  scatter(body.v.x, bodies.v.x, ids, movable);
  scatter(body.v.y, bodies.v.y, ids, movable);
  scatter(body.v.z, bodies.v.z, ids, movable);
  scatter(body.w.x, bodies.w.x, ids, movable);
  scatter(body.w.y, bodies.w.y, ids, movable);
  scatter(body.w.z, bodies.w.z, ids, movable);
}

/// The streaming-pairs layout: contact l of the group joins bodies
/// first + 2l and first + 2l + 1, so both sides come from 2W consecutive
/// bodies (two vector loads and a deinterleave per field, instead of 2W
/// scalar loads). This is how a caller lays out independent pairs, and how
/// the pairs scene is built; any other layout takes the general gather.
template <std::size_t W>
COLLIDE_LANE_INLINE bool is_paired_layout(const BodyIndex* ia, const BodyIndex* ib) {
  bool paired = true;
  for (std::size_t l = 0; l < W; ++l) {
    paired &= (ia[l] == ia[0] + 2 * l) & (ib[l] == ia[l] + 1);
  }
  return paired;
}

template <class V, class T>
COLLIDE_LANE_INLINE void load_pair_field(const T* field, BodyIndex first, V& a, V& b) {
  load_deinterleaved<V>(field + first, a, b);
}

template <class V, class T>
COLLIDE_LANE_INLINE void gather_paired(const BodyView<T>& bodies, BodyIndex first, BodyLanes<V>& a, BodyLanes<V>& b) {
  load_pair_field(bodies.inv_mass, first, a.inv_mass, b.inv_mass);
  load_pair_field(bodies.inv_inertia.x, first, a.inv_inertia.x, b.inv_inertia.x);
  load_pair_field(bodies.inv_inertia.y, first, a.inv_inertia.y, b.inv_inertia.y);
  load_pair_field(bodies.inv_inertia.z, first, a.inv_inertia.z, b.inv_inertia.z);
  V qwa, qxa, qya, qza, qwb, qxb, qyb, qzb;
  load_pair_field(bodies.q.w, first, qwa, qwb);
  load_pair_field(bodies.q.x, first, qxa, qxb);
  load_pair_field(bodies.q.y, first, qya, qyb);
  load_pair_field(bodies.q.z, first, qza, qzb);
  a.rotation = rotation(qwa, qxa, qya, qza);
  b.rotation = rotation(qwb, qxb, qyb, qzb);
  load_pair_field(bodies.p.x, first, a.p.x, b.p.x);
  load_pair_field(bodies.p.y, first, a.p.y, b.p.y);
  load_pair_field(bodies.p.z, first, a.p.z, b.p.z);
  load_pair_field(bodies.v.x, first, a.v.x, b.v.x);
  load_pair_field(bodies.v.y, first, a.v.y, b.v.y);
  load_pair_field(bodies.v.z, first, a.v.z, b.v.z);
  load_pair_field(bodies.w.x, first, a.w.x, b.w.x);
  load_pair_field(bodies.w.y, first, a.w.y, b.w.y);
  load_pair_field(bodies.w.z, first, a.w.z, b.w.z);
}

template <class V, class T>
COLLIDE_LANE_INLINE void scatter_paired(const BodyLanes<V>& a, const BodyLanes<V>& b, const BodyView<T>& bodies,
                                        BodyIndex first) {
  store_interleaved(a.v.x, b.v.x, bodies.v.x + first);
  store_interleaved(a.v.y, b.v.y, bodies.v.y + first);
  store_interleaved(a.v.z, b.v.z, bodies.v.z + first);
  store_interleaved(a.w.x, b.w.x, bodies.w.x + first);
  store_interleaved(a.w.y, b.w.y, bodies.w.y + first);
  store_interleaved(a.w.z, b.w.z, bodies.w.z + first);
}

/// Resolves one group of V::size() contacts.
template <class V, bool kFriction, class T>
COLLIDE_LANE_INLINE void solve_group(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                        const ContactGroup& g) {
  constexpr std::size_t W = V::size();
  BodyIndex ia[W];
  BodyIndex ib[W];
  for (std::size_t l = 0; l < W; ++l) {
    const std::uint32_t k = g.contiguous ? g.first + static_cast<std::uint32_t>(l) : g.index[l];
    ia[l] = contacts.a[k];
    ib[l] = contacts.b[k];
    assert(ia[l] < bodies.count && ib[l] < bodies.count && ia[l] != ib[l]);
  }
  // Only the SIMD path looks for the paired layout; the scalar path (W = 1)
  // would gain nothing. The arithmetic is the same either way.
  const bool paired = W > 1 && is_paired_layout<W>(ia, ib);
  BodyLanes<V> a;
  BodyLanes<V> b;
  if (paired) {
    gather_paired(bodies, ia[0], a, b);
  } else {
    gather_body(bodies, ia, a);
    gather_body(bodies, ib, b);
  }

  ContactLanes<V> c;
  c.c = {contact_field<V>(contacts.c.x, g), contact_field<V>(contacts.c.y, g), contact_field<V>(contacts.c.z, g)};
  c.n = {contact_field<V>(contacts.n.x, g), contact_field<V>(contacts.n.y, g), contact_field<V>(contacts.n.z, g)};
  c.e = contacts.e ? contact_field<V>(contacts.e, g) : V(contacts.uniform_e);
  if constexpr (kFriction) c.mu = contact_field<V>(contacts.mu, g);

  const ContactResult<V> r = resolve_contacts<V, kFriction>(a, b, c);

  // An immovable body is never written, not even with its own value: another
  // thread may be reading it (the ground is in many contacts of a batch).
  if (paired && stdx::all_of((a.inv_mass != V(0)) && (b.inv_mass != V(0)))) {
    scatter_paired(a, b, bodies, ia[0]);
  } else {
    scatter_body(a, bodies, ia);
    scatter_body(b, bodies, ib);
  }
  if (g.contiguous) {
    store(r.j.x, impulses.j.x + g.first);
    store(r.j.y, impulses.j.y + g.first);
    store(r.j.z, impulses.j.z + g.first);
  } else {
    const auto all = V(0) == V(0);
    scatter(r.j.x, impulses.j.x, g.index, all);
    scatter(r.j.y, impulses.j.y, g.index, all);
    scatter(r.j.z, impulses.j.z, g.index, all);
  }
}

/// Contacts [begin, end) of the schedule's order, all inside one batch.
template <class V, bool kFriction, class T>
void solve_range(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const std::uint32_t* order, bool contiguous, std::size_t begin, std::size_t end) {
  using Tail = ScalarLanes<T>;
  constexpr std::size_t W = V::size();
  std::size_t i = begin;
  for (; i + W <= end; i += W) {
    solve_group<V, kFriction>(bodies, contacts, impulses, ContactGroup{contiguous, order[i], order + i});
  }
  for (; i < end; ++i) {
    solve_group<Tail, kFriction>(bodies, contacts, impulses, ContactGroup{contiguous, order[i], order + i});
  }
}

template <class V, class T>
void solve_range_any(bool friction, const BodyView<T>& bodies, const ContactView<T>& contacts,
                     const ImpulseView<T>& impulses, const std::uint32_t* order, bool contiguous, std::size_t begin,
                     std::size_t end) {
  if (friction) {
    solve_range<V, true>(bodies, contacts, impulses, order, contiguous, begin, end);
  } else {
    solve_range<V, false>(bodies, contacts, impulses, order, contiguous, begin, end);
  }
}

}  // namespace
}  // namespace detail

struct Solver::Impl {
  SolverOptions options;
  tbb::task_arena arena;

  explicit Impl(const SolverOptions& o)
      : options(o), arena(o.threads > 0 ? o.threads : tbb::task_arena::automatic) {}
};

Solver::Solver(const SolverOptions& options) : impl_(std::make_unique<Impl>(options)) {
  if (options.threads < 0) throw std::invalid_argument("collide::Solver: threads must be >= 0");
  impl_->arena.initialize();
}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

const SolverOptions& Solver::options() const { return impl_->options; }

template <class T>
SolveStats Solver::solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  assert(schedule.contact_count() == contacts.count);
  assert(schedule.body_count() == bodies.count);
  assert(impulses.count == contacts.count);

  const SolverOptions& opt = impl_->options;
  const bool friction = contacts.mu != nullptr;
  const bool simd = opt.path == Path::simd;
  const std::size_t width = simd ? detail::SimdLanes<T>::size() : 1;
  const std::size_t block = std::max<std::size_t>(width, (opt.block + width - 1) / width * width);
  const std::uint32_t* order = schedule.order();

  auto run = [&](bool contiguous, std::size_t begin, std::size_t end) {
    if (simd) {
      detail::solve_range_any<detail::SimdLanes<T>>(friction, bodies, contacts, impulses, order, contiguous, begin,
                                                    end);
    } else {
      detail::solve_range_any<detail::ScalarLanes<T>>(friction, bodies, contacts, impulses, order, contiguous, begin,
                                                      end);
    }
  };

  impl_->arena.execute([&] {
    for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
      const std::size_t begin = schedule.batch_begin(k);
      const std::size_t end = schedule.batch_begin(k + 1);
      const bool contiguous = schedule.batch_is_contiguous(k);
      const std::size_t n = end - begin;
      if (n < 2 * block || impl_->arena.max_concurrency() == 1) {
        run(contiguous, begin, end);
        continue;
      }
      const std::size_t blocks = (n + block - 1) / block;
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, blocks, 1),
          [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t bi = r.begin(); bi != r.end(); ++bi) {
              run(contiguous, begin + bi * block, std::min(end, begin + (bi + 1) * block));
            }
          },
          tbb::simple_partitioner());
    }
  });

  SolveStats stats;
  stats.contacts = contacts.count;
  stats.batches = schedule.batch_count();
  stats.lanes = width;
  stats.threads = impl_->arena.max_concurrency();
  stats.model = Model::rigid;
  stats.path = opt.path;
  return stats;
}

template <class T>
SolveStats solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const SolverOptions& options) {
  Schedule schedule;
  schedule.build(contacts, bodies);
  return Solver(options).solve(bodies, contacts, impulses, schedule);
}

template <class T>
std::size_t simd_width() {
  return detail::SimdLanes<T>::size();
}

const char* to_string(Path path) { return path == Path::simd ? "simd" : "scalar"; }
const char* to_string(Model model) {
  switch (model) {
    case Model::rigid:
      return "rigid";
  }
  return "?";
}

template SolveStats Solver::solve<float>(const BodyView<float>&, const ContactView<float>&, const ImpulseView<float>&,
                                         const Schedule&) const;
template SolveStats Solver::solve<double>(const BodyView<double>&, const ContactView<double>&,
                                          const ImpulseView<double>&, const Schedule&) const;
template SolveStats solve<float>(const BodyView<float>&, const ContactView<float>&, const ImpulseView<float>&,
                                 const SolverOptions&);
template SolveStats solve<double>(const BodyView<double>&, const ContactView<double>&, const ImpulseView<double>&,
                                  const SolverOptions&);
template std::size_t simd_width<float>();
template std::size_t simd_width<double>();

}  // namespace collide
