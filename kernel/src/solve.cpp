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
// * Nothing here allocates: the Solver owns its task_arena (or borrows the
//   caller's, collide/tbb.hpp), the Schedule owns the order.
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include "collide/solve.hpp"
#include "collide/tbb.hpp"
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

/// The public view each model reads.
template <class M, class T>
struct ViewOf;
template <class T>
struct ViewOf<RigidModel, T> {
  using type = BodyView<T>;
};
template <class T>
struct ViewOf<SphereModel, T> {
  using type = SphereView<T>;
};
template <class T>
struct ViewOf<ParticleModel, T> {
  using type = ParticleView<T>;
};
template <class M, class T>
using ViewOfT = typename ViewOf<M, T>::type;

/// The quaternion lanes of a rigid body, turned into its rotation once read.
template <class V>
struct QuatLanes {
  V w, x, y, z;
};

/// Calls f(field, lane_of_a, lane_of_b) for every input field of the model,
/// so that the index gather and the paired load share one field list.
template <class M, class V, class T, class F>
COLLIDE_LANE_INLINE void read_bodies(const ViewOfT<M, T>& view, BodyLanes<M, V>& a, BodyLanes<M, V>& b, F&& f) {
  f(view.inv_mass, a.inv_mass, b.inv_mass);
  if constexpr (std::is_same_v<M, RigidModel>) {
    f(view.inv_inertia.x, a.inv_inertia.x, b.inv_inertia.x);
    f(view.inv_inertia.y, a.inv_inertia.y, b.inv_inertia.y);
    f(view.inv_inertia.z, a.inv_inertia.z, b.inv_inertia.z);
    QuatLanes<V> qa;
    QuatLanes<V> qb;
    f(view.q.w, qa.w, qb.w);
    f(view.q.x, qa.x, qb.x);
    f(view.q.y, qa.y, qb.y);
    f(view.q.z, qa.z, qb.z);
    a.rotation = rotation(qa.w, qa.x, qa.y, qa.z);
    b.rotation = rotation(qb.w, qb.x, qb.y, qb.z);
  } else if constexpr (std::is_same_v<M, SphereModel>) {
    f(view.inv_inertia, a.inv_inertia.x, b.inv_inertia.x);
  }
  if constexpr (kRotates<M>) {
    f(view.p.x, a.p.x, b.p.x);
    f(view.p.y, a.p.y, b.p.y);
    f(view.p.z, a.p.z, b.p.z);
  }
  f(view.v.x, a.v.x, b.v.x);
  f(view.v.y, a.v.y, b.v.y);
  f(view.v.z, a.v.z, b.v.z);
  if constexpr (kRotates<M>) {
    f(view.w.x, a.w.x, b.w.x);
    f(view.w.y, a.w.y, b.w.y);
    f(view.w.z, a.w.z, b.w.z);
  }
}

/// Calls f(field, lane_of_a, lane_of_b) for every field the model writes.
template <class M, class V, class T, class F>
COLLIDE_LANE_INLINE void write_bodies(const ViewOfT<M, T>& view, const BodyLanes<M, V>& a, const BodyLanes<M, V>& b,
                                      F&& f) {
  f(view.v.x, a.v.x, b.v.x);
  f(view.v.y, a.v.y, b.v.y);
  f(view.v.z, a.v.z, b.v.z);
  if constexpr (kRotates<M>) {
    f(view.w.x, a.w.x, b.w.x);
    f(view.w.y, a.w.y, b.w.y);
    f(view.w.z, a.w.z, b.w.z);
  }
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

/// Resolves one group of V::size() contacts.
template <class M, class V, bool kFriction, class T>
COLLIDE_LANE_INLINE void solve_group(const ViewOfT<M, T>& bodies, const ContactView<T>& contacts,
                                     const ImpulseView<T>& impulses, const ContactGroup& g) {
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
  BodyLanes<M, V> a;
  BodyLanes<M, V> b;
  if (paired) {
    read_bodies<M, V, T>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
      load_deinterleaved(field + ia[0], la, lb);
    });
  } else {
    read_bodies<M, V, T>(bodies, a, b, [&](const T* field, V& la, V& lb) COLLIDE_LANE_LAMBDA {
      la = gather<V>(field, ia);
      lb = gather<V>(field, ib);
    });
  }

  ContactLanes<V> c;
  if constexpr (kRotates<M>) {
    c.c = {contact_field<V>(contacts.c.x, g), contact_field<V>(contacts.c.y, g), contact_field<V>(contacts.c.z, g)};
  }
  c.n = {contact_field<V>(contacts.n.x, g), contact_field<V>(contacts.n.y, g), contact_field<V>(contacts.n.z, g)};
  c.e = contacts.e ? contact_field<V>(contacts.e, g) : V(contacts.uniform_e);
  if constexpr (kFriction) c.mu = contact_field<V>(contacts.mu, g);

  const ContactResult<V> r = resolve_contacts<M, V, kFriction>(a, b, c);

  // An immovable body is never written, not even with its own value: another
  // thread may be reading it (the ground is in many contacts of a batch).
  const auto movable_a = a.inv_mass != V(0);
  const auto movable_b = b.inv_mass != V(0);
  if (paired && stdx::all_of(movable_a && movable_b)) {
    write_bodies<M, V, T>(bodies, a, b, [&](T* field, const V& la, const V& lb) COLLIDE_LANE_LAMBDA {
      store_interleaved(la, lb, field + ia[0]);
    });
  } else {
    write_bodies<M, V, T>(bodies, a, b, [&](T* field, const V& la, const V& lb) COLLIDE_LANE_LAMBDA {
      scatter(la, field, ia, movable_a);
      scatter(lb, field, ib, movable_b);
    });
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
template <class M, class V, bool kFriction, class T>
void solve_range(const ViewOfT<M, T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const std::uint32_t* order, bool contiguous, std::size_t begin, std::size_t end) {
  using Tail = ScalarLanes<T>;
  constexpr std::size_t W = V::size();
  std::size_t i = begin;
  for (; i + W <= end; i += W) {
    solve_group<M, V, kFriction, T>(bodies, contacts, impulses, ContactGroup{contiguous, order[i], order + i});
  }
  for (; i < end; ++i) {
    solve_group<M, Tail, kFriction, T>(bodies, contacts, impulses, ContactGroup{contiguous, order[i], order + i});
  }
}

template <class M, class V, class T>
void solve_range_any(bool friction, const ViewOfT<M, T>& bodies, const ContactView<T>& contacts,
                     const ImpulseView<T>& impulses, const std::uint32_t* order, bool contiguous, std::size_t begin,
                     std::size_t end) {
  if (friction) {
    solve_range<M, V, true, T>(bodies, contacts, impulses, order, contiguous, begin, end);
  } else {
    solve_range<M, V, false, T>(bodies, contacts, impulses, order, contiguous, begin, end);
  }
}

}  // namespace
}  // namespace detail

struct Solver::Impl {
  SolverOptions options;
  Isa isa;  // options.isa resolved
  std::optional<tbb::task_arena> owned;  // empty when the caller's arena is borrowed
  tbb::task_arena* arena;

  explicit Impl(const SolverOptions& o)
      // int{...}: a prvalue copy, so that the static constant
      // task_arena::automatic (which libtbb does not define) is not bound to
      // the in_place constructor's reference: unoptimised builds failed to link.
      : options(o),
        isa(resolve_isa(o.isa)),
        owned(std::in_place, o.threads > 0 ? o.threads : int{tbb::task_arena::automatic}),
        arena(&*owned) {}
  Impl(const SolverOptions& o, tbb::task_arena& borrowed) : options(o), isa(resolve_isa(o.isa)), arena(&borrowed) {}
};

namespace {
void check_options(const SolverOptions& options) {
  if (options.accuracy == Accuracy::accurate) {
    throw std::invalid_argument("collide::Solver: accuracy=accurate is not available yet");
  }
}
}  // namespace

Solver::Solver(const SolverOptions& options) {
  if (options.threads < 0) throw std::invalid_argument("collide::Solver: threads must be >= 0");
  check_options(options);
  impl_ = std::make_unique<Impl>(options);
  impl_->arena->initialize();
}
Solver::Solver(const ExternalArena& arena, const SolverOptions& options) {
  if (options.threads != 0) {
    throw std::invalid_argument("collide::Solver: threads must be 0 in a caller's arena (the arena decides)");
  }
  check_options(options);
  impl_ = std::make_unique<Impl>(options, arena.arena);
  impl_->arena->initialize();  // no-op for an arena the caller already initialised
}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

const SolverOptions& Solver::options() const { return impl_->options; }

namespace detail {
namespace {

template <class M>
constexpr Model model_of() {
  if constexpr (std::is_same_v<M, RigidModel>) {
    return Model::rigid;
  } else if constexpr (std::is_same_v<M, SphereModel>) {
    return Model::sphere;
  } else {
    return Model::particle;
  }
}

/// Walks the batches of the schedule; blocks of a large batch run in parallel.
template <class M, class T>
SolveStats run_schedule(const SolverOptions& opt, tbb::task_arena& arena, const ViewOfT<M, T>& bodies,
                        const ContactView<T>& contacts, const ImpulseView<T>& impulses, const Schedule& schedule) {
  assert(schedule.contact_count() == contacts.count);
  assert(schedule.body_count() == bodies.count);
  assert(impulses.count == contacts.count);

  const bool friction = contacts.mu != nullptr;
  const bool simd = opt.path == Path::simd;
  const std::size_t width = simd ? SimdLanes<T>::size() : 1;
  const std::size_t block = std::max<std::size_t>(width, (opt.block + width - 1) / width * width);
  const std::uint32_t* order = schedule.order();

  auto run = [&](bool contiguous, std::size_t begin, std::size_t end) {
    if (simd) {
      solve_range_any<M, SimdLanes<T>, T>(friction, bodies, contacts, impulses, order, contiguous, begin, end);
    } else {
      solve_range_any<M, ScalarLanes<T>, T>(friction, bodies, contacts, impulses, order, contiguous, begin, end);
    }
  };

  arena.execute([&] {
    for (std::size_t k = 0; k < schedule.batch_count(); ++k) {
      const std::size_t begin = schedule.batch_begin(k);
      const std::size_t end = schedule.batch_begin(k + 1);
      const bool contiguous = schedule.batch_is_contiguous(k);
      const std::size_t n = end - begin;
      if (n < 2 * block || arena.max_concurrency() == 1) {
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
  stats.largest_batch = schedule.largest_batch();
  stats.conflicts = schedule.conflicts();
  stats.lanes = width;
  stats.threads = arena.max_concurrency();
  stats.model = model_of<M>();
  stats.path = opt.path;
  stats.friction = friction;
#if defined(__AVX512F__)
  stats.isa = Isa::avx512;
#elif defined(__AVX2__)
  stats.isa = Isa::avx2;
#else
  stats.isa = Isa::sse2;
#endif
  stats.accuracy = opt.accuracy;
  return stats;
}

}  // namespace
}  // namespace detail

template <class T>
SolveStats Solver::solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return detail::run_schedule<detail::RigidModel, T>(impl_->options, *impl_->arena, bodies, contacts, impulses,
                                                     schedule);
}

template <class T>
SolveStats Solver::solve(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return detail::run_schedule<detail::SphereModel, T>(impl_->options, *impl_->arena, bodies, contacts, impulses,
                                                      schedule);
}

template <class T>
SolveStats Solver::solve(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                         const Schedule& schedule) const {
  return detail::run_schedule<detail::ParticleModel, T>(impl_->options, *impl_->arena, bodies, contacts, impulses,
                                                        schedule);
}

template <class T>
SolveStats Solver::solve(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts,
                         const ImpulseView<T>& impulses, const Schedule& schedule) const {
  assert(model_misfit(model, bodies, contacts).empty());
  switch (model) {
    case Model::particle:
      return solve(particle_view(bodies), contacts, impulses, schedule);
    case Model::sphere:
      return solve(sphere_view(bodies), contacts, impulses, schedule);
    case Model::rigid:
      break;
  }
  return solve(bodies, contacts, impulses, schedule);
}

template <class T>
SolveStats solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const SolverOptions& options) {
  Schedule schedule;
  schedule.build(contacts, bodies);
  return Solver(options).solve(choose_model(bodies, contacts), bodies, contacts, impulses, schedule);
}

template <class T>
std::size_t simd_width() {
  return detail::SimdLanes<T>::size();
}

template <class T>
std::size_t simd_width(Isa isa) {
  switch (resolve_isa(isa)) {
    case Isa::avx512:
      return 64 / sizeof(T);
    case Isa::avx2:
      return 32 / sizeof(T);
    default:
      return 16 / sizeof(T);
  }
}

const char* to_string(Path path) { return path == Path::simd ? "simd" : "scalar"; }

const char* to_string(Accuracy accuracy) { return accuracy == Accuracy::accurate ? "accurate" : "fast"; }

Accuracy parse_accuracy(std::string_view name) {
  if (name == "fast") return Accuracy::fast;
  if (name == "accurate") return Accuracy::accurate;
  throw std::invalid_argument("unknown accuracy '" + std::string(name) + "' (expected fast or accurate)");
}

#define COLLIDE_INSTANTIATE(T)                                                                                  \
  template SolveStats Solver::solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,        \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const SphereView<T>&, const ContactView<T>&, const ImpulseView<T>&,      \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(const ParticleView<T>&, const ContactView<T>&, const ImpulseView<T>&,    \
                                       const Schedule&) const;                                                  \
  template SolveStats Solver::solve<T>(Model, const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&, \
                                       const Schedule&) const;                                                  \
  template SolveStats solve<T>(const BodyView<T>&, const ContactView<T>&, const ImpulseView<T>&,                \
                               const SolverOptions&);                                                           \
  template std::size_t simd_width<T>();                                                                         \
  template std::size_t simd_width<T>(Isa);
COLLIDE_INSTANTIATE(float)
COLLIDE_INSTANTIATE(double)
#undef COLLIDE_INSTANTIATE

}  // namespace collide
