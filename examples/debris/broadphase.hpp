// broadphase.hpp - the contacts of one step of collide_debris: the arrays
// handed to collide, and the uniform grid that finds them from the bodies'
// overlaps.
//
// Design notes
// ------------
// * The contacts are the caller's arrays, handed to collide as a
//   ContactView each step: the grid fills them, the step (frame.cpp) solves
//   them and corrects positions from them. One set of arrays and one grid
//   serve the whole run, so that their buffers keep their capacity from
//   step to step.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <collide/bodies.hpp>
#include <collide/contacts.hpp>

#include "world.hpp"

namespace debris {

/// This step's contacts: the caller's arrays, handed to collide as a
/// ContactView.
struct Contacts {
  std::vector<collide::BodyIndex> a, b;
  std::vector<Real> cx, cy, cz, nx, ny, nz, mu;
  std::vector<Real> depth;  // overlap [m], for the position correction
  std::vector<Real> jx, jy, jz;
  std::size_t ground = 0;  // the first `ground` contacts are with the ground

  void clear() {
    for (auto* v : {&cx, &cy, &cz, &nx, &ny, &nz, &mu, &depth}) v->clear();
    a.clear();
    b.clear();
    ground = 0;
  }
  [[nodiscard]] std::size_t size() const { return a.size(); }

  /// Contact of body i (side a) with body j (side b), normal from j to i.
  void add(collide::BodyIndex i, collide::BodyIndex j, const double c[3], const double n[3], double overlap,
           double friction) {
    a.push_back(i);
    b.push_back(j);
    cx.push_back(static_cast<Real>(c[0]));
    cy.push_back(static_cast<Real>(c[1]));
    cz.push_back(static_cast<Real>(c[2]));
    nx.push_back(static_cast<Real>(n[0]));
    ny.push_back(static_cast<Real>(n[1]));
    nz.push_back(static_cast<Real>(n[2]));
    mu.push_back(static_cast<Real>(friction));
    depth.push_back(static_cast<Real>(overlap));
  }

  collide::ContactView<Real> view(double restitution) const {
    collide::ContactView<Real> v;
    v.count = size();
    v.a = a.data();
    v.b = b.data();
    v.c = {cx.data(), cy.data(), cz.data()};
    v.n = {nx.data(), ny.data(), nz.data()};
    v.uniform_e = static_cast<Real>(restitution);  // e == nullptr: one restitution for all
    v.mu = mu.data();
    return v;
  }
  collide::ImpulseView<Real> impulses() {
    jx.resize(size());
    jy.resize(size());
    jz.resize(size());
    return {size(), {jx.data(), jy.data(), jz.data()}};
  }
};

/// The broadphase: a uniform grid over the bounding box of the bodies, cells
/// at least one largest diameter wide, so overlapping bodies are in the same
/// or neighbouring cells. Bodies are bucketed by a counting sort; each body
/// then tests the bodies with larger ids in the 27 cells around it, so each
/// pair is tested once.
class UniformGrid {
 public:
  /// This step's contacts into `out`: the ground contacts first, then the
  /// pairs of overlapping bodies from the bottom of the pile upwards.
  void find_contacts(const World& w, double friction, Contacts& out);

 private:
  struct Pair {
    std::uint32_t i, j;
    float z;  // height of the lower centre
  };

  void bucket(const World& w);
  void test_pair(const World& w, std::uint32_t i, std::uint32_t j);

  [[nodiscard]] int cell_coord(double x, int axis) const {
    return std::min(dims_[axis] - 1, static_cast<int>((x - lo_[axis]) / cell_));
  }
  [[nodiscard]] std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }

  double lo_[3] = {}, hi_[3] = {}, cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::size_t> cell_of_;
  std::vector<std::uint32_t> start_, fill_, sorted_;
  std::vector<Pair> pairs_;
};

}  // namespace debris
