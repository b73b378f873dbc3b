// iteration_scratch.cpp - the scratch of iteration_scratch.hpp.
#include "iteration_scratch.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_reduce.h>
#include <oneapi/tbb/partitioner.h>

#include "collide/validate.hpp"
#include "first_touch.hpp"

namespace collide::detail {
namespace {

/// Contacts per task: long stretches that stream.
constexpr std::size_t kContactsPerTask = 16384;

struct Largest {
  double change = 0;  ///< largest |J - J saved|
  double total = 0;   ///< largest |J|
};

double length(double x, double y, double z) { return std::sqrt(x * x + y * y + z * z); }

}  // namespace

template <class T>
bool IterationScratch<T>::allocate(tbb::task_arena& arena, std::size_t contacts, bool totals, bool friction,
                                   bool residual) {
  FirstTouch touch;
  bool grew = false;
  if (totals) {
    grew |= touch.resize(normal_, contacts);
    grew |= touch.resize(target_, contacts);
    if (friction) {
      for (ScratchVector<T>& f : friction_) grew |= touch.resize(f, contacts);
    }
  }
  if (residual) {
    for (ScratchVector<T>& s : saved_) grew |= touch.resize(s, contacts);
  }
  touch.run(arena);
  return grew;
}

template <class T>
AccumulatedView<T> IterationScratch<T>::totals(bool friction) {
  AccumulatedView<T> view;
  view.normal = normal_.data();
  view.target = target_.data();
  if (friction) {
    for (int k = 0; k < 3; ++k) view.friction[k] = friction_[k].data();
  }
  return view;
}

template <class T>
void IterationScratch<T>::warm(tbb::task_arena& arena, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                               const std::uint32_t* order, bool friction, bool save) {
  assert(normal_.size() >= contacts.count && (!save || saved_[0].size() >= contacts.count));
  const std::size_t none = contacts.count;
  const std::size_t bad = arena.execute([&] {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, contacts.count, kContactsPerTask), none,
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t first_bad) {
          for (std::size_t p = r.begin(); p < r.end(); ++p) {
            const std::size_t k = order != nullptr ? order[p] : p;
            const T jx = impulses.j.x[k];
            const T jy = impulses.j.y[k];
            const T jz = impulses.j.z[k];
            const T nx = contacts.n.x[k];
            const T ny = contacts.n.y[k];
            const T nz = contacts.n.z[k];
            // lambda n is J's part along n; G = lambda n - J the rest, kept
            // only where friction can act on it (mu > 0).
            const T along = jx * nx + jy * ny + jz * nz;
            const T lambda = std::max(along / (nx * nx + ny * ny + nz * nz), T(0));
            const bool kept = friction && contacts.mu[k] > T(0);
            normal_[p] = lambda;
            target_[p] = T(0);  // the target visit reads it with the totals, then measures it
            if (friction) {
              friction_[0][p] = kept ? nx * lambda - jx : T(0);
              friction_[1][p] = kept ? ny * lambda - jy : T(0);
              friction_[2][p] = kept ? nz * lambda - jz : T(0);
            }
            if (save) {
              saved_[0][p] = jx;
              saved_[1][p] = jy;
              saved_[2][p] = jz;
            }
            const T j[3] = {jx, jy, jz};
            const T n[3] = {nx, ny, nz};
            if (!warm_start_accepted(j, n) && k < first_bad) first_bad = k;
          }
          return first_bad;
        },
        [](std::size_t x, std::size_t y) { return std::min(x, y); }, tbb::static_partitioner());
  });
  if (bad == none) return;
  std::ostringstream at;
  at << std::setprecision(std::numeric_limits<T>::max_digits10) << "impulses.j[" << bad << "] = (" << impulses.j.x[bad]
     << ", " << impulses.j.y[bad] << ", " << impulses.j.z[bad] << ")";
  const ImpulseView<const T> warm{impulses.count, {impulses.j.x, impulses.j.y, impulses.j.z}};
  throw std::invalid_argument("collide::Solver::solve: warm start " + at.str() + " " +
                              warm_start_refusal(contacts, warm, bad));
}

template <class T>
void IterationScratch<T>::save(tbb::task_arena& arena, const ImpulseView<T>& impulses) {
  assert(saved_[0].size() >= impulses.count);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, impulses.count, kContactsPerTask),
        [&](const tbb::blocked_range<std::size_t>& r) {
          std::copy(impulses.j.x + r.begin(), impulses.j.x + r.end(), saved_[0].data() + r.begin());
          std::copy(impulses.j.y + r.begin(), impulses.j.y + r.end(), saved_[1].data() + r.begin());
          std::copy(impulses.j.z + r.begin(), impulses.j.z + r.end(), saved_[2].data() + r.begin());
        },
        tbb::static_partitioner());
  });
}

template <class T>
double IterationScratch<T>::residual(tbb::task_arena& arena, const ImpulseView<T>& impulses) const {
  const Largest largest = arena.execute([&] {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, impulses.count, kContactsPerTask), Largest{},
        [&](const tbb::blocked_range<std::size_t>& r, Largest m) {
          for (std::size_t k = r.begin(); k < r.end(); ++k) {
            const double x = impulses.j.x[k];
            const double y = impulses.j.y[k];
            const double z = impulses.j.z[k];
            // A NaN compares false: it never becomes the largest.
            const double change = length(x - double(saved_[0][k]), y - double(saved_[1][k]), z - double(saved_[2][k]));
            if (change > m.change) m.change = change;
            const double total = length(x, y, z);
            if (total > m.total) m.total = total;
          }
          return m;
        },
        [](Largest p, const Largest& q) {
          p.change = std::max(p.change, q.change);
          p.total = std::max(p.total, q.total);
          return p;
        },
        tbb::static_partitioner());
  });
  return largest.total > 0 ? largest.change / largest.total : 0.0;
}

template class IterationScratch<float>;
template class IterationScratch<double>;

}  // namespace collide::detail
