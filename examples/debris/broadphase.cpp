// broadphase.cpp - the uniform grid of collide_debris (broadphase.hpp).
//
// Design notes
// ------------
// * Cells at least one largest diameter wide, so that overlapping bodies are
//   in the same or neighbouring cells, and grown until there are at most a
//   few per body, so that a body thrown far away cannot make the grid huge.
// * Pairs are listed from the bottom of the pile upwards, so that one pass
//   in input order already carries support from the ground up (debris.cpp,
//   "Contact order").
#include "broadphase.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>

namespace debris {

void UniformGrid::find_contacts(const World& w, double friction, Contacts& out) {
  out.clear();
  const std::size_t n = w.size();
  // Ground contacts: anything reaching below z = 0. The ground is side b,
  // its normal +z; the contact point is the middle of the overlap.
  for (std::size_t i = 1; i < n; ++i) {
    const Real* p = w.bodies[i].p;
    const double overlap = w.radius[i] - p[2];
    if (overlap > 0) {
      const double c[3] = {p[0], p[1], -0.5 * overlap};
      const double up[3] = {0, 0, 1};
      out.add(static_cast<collide::BodyIndex>(i), 0, c, up, overlap, friction);
    }
  }
  out.ground = out.size();

  bucket(w);
  pairs_.clear();
  for (std::size_t i = 1; i < n; ++i) {
    const Real* p = w.bodies[i].p;
    const int cx = cell_coord(p[0], 0), cy = cell_coord(p[1], 1), cz = cell_coord(p[2], 2);
    for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, dims_[2] - 1); ++z) {
      for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, dims_[1] - 1); ++y) {
        for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, dims_[0] - 1); ++x) {
          const std::size_t cell = index(x, y, z);
          for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
            const std::uint32_t j = sorted_[k];
            if (j > i) test_pair(w, static_cast<std::uint32_t>(i), j);
          }
        }
      }
    }
  }
  // Bottom of the pile first: support travels up in a single pass.
  std::sort(pairs_.begin(), pairs_.end(), [](const Pair& p, const Pair& q) { return p.z < q.z; });
  for (const Pair& pair : pairs_) {
    const Real* pi = w.bodies[pair.i].p;
    const Real* pj = w.bodies[pair.j].p;
    const double dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double overlap = w.radius[pair.i] + w.radius[pair.j] - d;
    const double nrm[3] = {dx / d, dy / d, dz / d};  // from j towards i
    const double reach = w.radius[pair.j] - 0.5 * overlap;
    const double c[3] = {pj[0] + nrm[0] * reach, pj[1] + nrm[1] * reach, pj[2] + nrm[2] * reach};
    out.add(pair.i, pair.j, c, nrm, overlap, friction);
  }
}

void UniformGrid::bucket(const World& w) {
  const std::size_t n = w.size();
  double max_radius = 0;
  for (int a = 0; a < 3; ++a) {
    lo_[a] = std::numeric_limits<double>::infinity();
    hi_[a] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 1; i < n; ++i) {
    max_radius = std::max<double>(max_radius, w.radius[i]);
    for (int a = 0; a < 3; ++a) {
      lo_[a] = std::min<double>(lo_[a], w.bodies[i].p[a]);
      hi_[a] = std::max<double>(hi_[a], w.bodies[i].p[a]);
    }
  }
  // A body thrown far away would make a dense grid huge: cells grow until
  // there are at most 8 per body (larger cells only mean more candidates).
  cell_ = 2 * max_radius;
  for (;;) {
    std::size_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      dims_[a] = static_cast<int>((hi_[a] - lo_[a]) / cell_) + 1;
      cells *= static_cast<std::size_t>(dims_[a]);
    }
    if (cells <= 8 * n + 64) break;
    cell_ *= 2;
  }
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  cell_of_.resize(n);
  start_.assign(cells + 1, 0);
  for (std::size_t i = 1; i < n; ++i) {
    const Real* p = w.bodies[i].p;
    cell_of_[i] = index(cell_coord(p[0], 0), cell_coord(p[1], 1), cell_coord(p[2], 2));
    ++start_[cell_of_[i] + 1];
  }
  std::partial_sum(start_.begin(), start_.end(), start_.begin());
  sorted_.resize(n);
  fill_ = start_;
  for (std::size_t i = 1; i < n; ++i) sorted_[fill_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
}

void UniformGrid::test_pair(const World& w, std::uint32_t i, std::uint32_t j) {
  const Real* pi = w.bodies[i].p;
  const Real* pj = w.bodies[j].p;
  const double dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
  const double r = w.radius[i] + w.radius[j];
  const double d2 = dx * dx + dy * dy + dz * dz;
  if (d2 < r * r && d2 > 0) pairs_.push_back({i, j, std::min(pi[2], pj[2])});
}

}  // namespace debris
