// test_islands.cpp - the islands of a scene (islands.cpp), and why they
// matter: each one solved on its own gives the whole solve's bits.
//
// What this proves
// ----------------
// * Hand-made graphs get the expected islands: a chain and a pair listed
//   interleaved, labels numbered by first contact, sizes, the largest island,
//   body labels (none for a body without contacts).
// * Immovable bodies join nothing: contacts of different bodies against one
//   ground are islands of their own, a contact between two immovable bodies
//   is an island of its own, and immovable bodies have no island.
// * On random graphs (random immovable bodies, bodies without contacts) every
//   output equals a plain sequential breadth-first labelling written here.
// * The labels, sizes and body labels are the same for 1, 2, 3 and 8
//   threads, on a scene large enough to split into chunks.
// * Packed records (rigid, sphere, particle) give the islands of their SoA
//   view.
// * Bad input throws std::invalid_argument naming the contact (index out of
//   range, a == b), a null array or a negative thread count.
// * The key property: solving every island on its own (its bodies copied and
//   its indices remapped, its contacts in input order) in ascending,
//   descending or shuffled island order, gives bit for bit (memcmp) the v, w
//   and J of one solve of the whole scene, for the particle, sphere and
//   rigid models, float and double, fast and accurate mode, with and
//   without friction, on a scene of many islands sharing a ground.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <ostream>
#include <queue>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include "collide/eval/hard_scenes.hpp"
#include "collide/io/scene.hpp"
#include "collide/islands.hpp"
#include "collide/model.hpp"
#include "collide/packed.hpp"
#include "collide/rules.hpp"
#include "collide/solve.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

constexpr std::uint32_t kNone = Islands::kNone;
using Edges = std::vector<std::pair<BodyIndex, BodyIndex>>;

/// Islands of a topology: `n` bodies, immovable where `immovable` says,
/// contacts `edges` (only indices and inverse masses are read).
Islands islands_of(std::size_t n, const Edges& edges, const std::vector<bool>& immovable = {}, int threads = 0) {
  std::vector<double> inv_mass(n, 1.0);
  for (std::size_t i = 0; i < immovable.size(); ++i) {
    if (immovable[i]) inv_mass[i] = 0;
  }
  std::vector<BodyIndex> a, b;
  for (const auto& [x, y] : edges) {
    a.push_back(x);
    b.push_back(y);
  }
  ContactView<double> contacts;
  contacts.count = edges.size();
  contacts.a = a.data();
  contacts.b = b.data();
  return islands(contacts, n, inv_mass.data(), threads);
}

/// The islands by breadth-first search over movable bodies, in input order:
/// the definition of islands.hpp, sequentially.
Islands plain_islands(std::size_t n, const Edges& edges, const std::vector<bool>& immovable) {
  std::vector<std::vector<std::size_t>> by_body(n);
  for (std::size_t k = 0; k < edges.size(); ++k) {
    if (!immovable[edges[k].first]) by_body[edges[k].first].push_back(k);
    if (!immovable[edges[k].second]) by_body[edges[k].second].push_back(k);
  }
  Islands out;
  out.contact_island.assign(edges.size(), kNone);
  out.body_island.assign(n, kNone);
  for (std::size_t k = 0; k < edges.size(); ++k) {
    if (out.contact_island[k] != kNone) continue;
    const auto label = static_cast<std::uint32_t>(out.island_contacts.size());
    std::uint32_t size = 0;
    std::queue<std::size_t> todo;
    todo.push(k);
    out.contact_island[k] = label;
    while (!todo.empty()) {
      const std::size_t c = todo.front();
      todo.pop();
      ++size;
      for (const BodyIndex body : {edges[c].first, edges[c].second}) {
        if (immovable[body]) continue;
        out.body_island[body] = label;
        for (const std::size_t next : by_body[body]) {
          if (out.contact_island[next] == kNone) {
            out.contact_island[next] = label;
            todo.push(next);
          }
        }
      }
    }
    out.island_contacts.push_back(size);
    if (size > out.largest) {
      out.largest = size;
      out.largest_island = label;
    }
  }
  return out;
}

void expect_same(const Islands& x, const Islands& y) {
  EXPECT_EQ(x.contact_island, y.contact_island);
  EXPECT_EQ(x.body_island, y.body_island);
  EXPECT_EQ(x.island_contacts, y.island_contacts);
  EXPECT_EQ(x.largest, y.largest);
  EXPECT_EQ(x.largest_island, y.largest_island);
}

TEST(Islands, ChainAndPairInterleaved) {
  // Bodies 0-1-2 a chain, 3-4 a pair, 5 without contacts.
  const Islands s = islands_of(6, {{3, 4}, {0, 1}, {1, 2}, {4, 3}});
  EXPECT_EQ(s.count(), 2u);
  EXPECT_EQ(s.contact_island, (Labels{0, 1, 1, 0}));
  EXPECT_EQ(s.island_contacts, (Labels{2, 2}));
  EXPECT_EQ(s.body_island, (Labels{1, 1, 1, 0, 0, kNone}));
  EXPECT_EQ(s.largest, 2u);
  EXPECT_EQ(s.largest_island, 0u);

  // Two chains that a late contact joins into one island.
  const Islands j = islands_of(6, {{0, 1}, {3, 4}, {1, 2}, {4, 5}, {2, 3}});
  EXPECT_EQ(j.count(), 1u);
  EXPECT_EQ(j.contact_island, (Labels(5, 0)));
  EXPECT_EQ(j.largest, 5u);

  const Islands none = islands_of(3, {});
  EXPECT_EQ(none.count(), 0u);
  EXPECT_EQ(none.largest, 0u);
  EXPECT_EQ(none.body_island, (Labels(3, kNone)));
}

TEST(Islands, ImmovableBodiesJoinNothing) {
  // Bodies 0..3 movable, 4 and 5 immovable (a ground and a wall).
  const std::vector<bool> immovable = {false, false, false, false, true, true};
  const Islands s = islands_of(6, {{0, 4}, {1, 4}, {4, 2}, {3, 4}, {0, 4}, {4, 5}, {5, 3}}, immovable);
  // Contacts 0 and 4 share body 0; 5 is between the two immovable bodies.
  EXPECT_EQ(s.contact_island, (Labels{0, 1, 2, 3, 0, 4, 3}));
  EXPECT_EQ(s.island_contacts, (Labels{2, 1, 1, 2, 1}));
  EXPECT_EQ(s.body_island, (Labels{0, 1, 2, 3, kNone, kNone}));
  EXPECT_EQ(s.largest, 2u);
  EXPECT_EQ(s.largest_island, 0u);
  // A million-contact ground would be a million islands: here, 1000.
  Edges star;
  for (BodyIndex i = 0; i < 1000; ++i) star.emplace_back(i, 1000);
  std::vector<bool> ground(1001, false);
  ground[1000] = true;
  const Islands g = islands_of(1001, star, ground);
  EXPECT_EQ(g.count(), 1000u);
  EXPECT_EQ(g.largest, 1u);
  // The same star around a movable hub is one island.
  EXPECT_EQ(islands_of(1001, star).count(), 1u);
}

/// A random graph: `n` bodies, a fraction immovable, `m` contacts between
/// bodies of the first 90% (the rest have none), in clusters of nearby indices.
Edges random_edges(std::mt19937_64& rng, std::size_t n, std::size_t m, std::vector<bool>& immovable,
                   double immovable_share) {
  std::uniform_real_distribution<double> u(0, 1);
  immovable.assign(n, false);
  for (std::size_t i = 0; i < n; ++i) immovable[i] = u(rng) < immovable_share;
  const std::size_t reach = std::max<std::size_t>(2, n * 9 / 10);
  std::uniform_int_distribution<std::size_t> pick(0, reach - 1), near(1, 6);
  Edges edges;
  while (edges.size() < m) {
    const std::size_t x = pick(rng);
    const std::size_t y = u(rng) < 0.8 ? std::min(reach - 1, x + near(rng)) : pick(rng);
    if (x != y) edges.emplace_back(static_cast<BodyIndex>(x), static_cast<BodyIndex>(y));
  }
  return edges;
}

TEST(Islands, RandomGraphsMatchBreadthFirstSearch) {
  std::mt19937_64 rng(11);
  for (const std::size_t n : {2, 3, 10, 100, 5000}) {  // n = 2: every contact joins bodies 0 and 1
    for (const double share : {0.0, 0.1, 0.5, 1.0}) {
      for (const double density : {0.3, 0.6, 1.2}) {
        SCOPED_TRACE("n " + std::to_string(n) + " immovable " + std::to_string(share) + " density " +
                     std::to_string(density));
        std::vector<bool> immovable;
        const Edges edges = random_edges(rng, n, static_cast<std::size_t>(density * double(n)) + 1, immovable, share);
        expect_same(islands_of(n, edges, immovable), plain_islands(n, edges, immovable));
      }
    }
  }
}

TEST(Islands, SameForEveryThreadCount) {
  // Room for 8 threads on a 2-core machine, as test_determinism does.
  const tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 8);
  std::mt19937_64 rng(5);
  std::vector<bool> immovable;
  const std::size_t n = 400000;
  const Edges edges = random_edges(rng, n, 300000, immovable, 0.05);
  const Islands one = islands_of(n, edges, immovable, 1);
  ASSERT_GT(one.count(), 1000u);
  ASSERT_GT(one.largest, 10u);
  expect_same(one, plain_islands(n, edges, immovable));
  for (const int threads : {0, 2, 3, 8}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    for (int repeat = 0; repeat < 3; ++repeat) expect_same(islands_of(n, edges, immovable, threads), one);
  }
}

// Contacts whose movable bodies are in no other contact are each an island
// (islands.cpp, single_contact_islands): independent pairs, some bodies
// immovable or without contacts, some contacts between two immovable
// bodies; and the same with one body repeated after the first look at the
// scene, within a chunk, across chunks, and in the last two contacts, which
// the general passes then label.
TEST(Islands, IndependentContactsAreEachAnIsland) {
  const tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, 8);
  const std::size_t m = 100000;
  const std::size_t n = 2 * m + 7;  // the last bodies have no contact
  std::vector<bool> immovable(n, false);
  Edges pairs;
  for (std::size_t k = 0; k < m; ++k) {
    pairs.emplace_back(static_cast<BodyIndex>(2 * k), static_cast<BodyIndex>(2 * k + 1));
    if (k % 7 == 3) immovable[2 * k] = true;
    if (k % 11 == 5) immovable[2 * k + 1] = true;
  }
  std::vector<Edges> scenes{pairs};
  for (const auto& [earlier, later] : std::vector<std::pair<std::size_t, std::size_t>>{
           {5000, 20000}, {10000, 90000}, {99998, 99999}, {60001, 60000}}) {
    Edges shared = pairs;
    // A movable body of the earlier contact in place of the later's b.
    const BodyIndex body = immovable[pairs[earlier].first] ? pairs[earlier].second : pairs[earlier].first;
    ASSERT_FALSE(immovable[body]);
    shared[later].second = body;
    scenes.push_back(shared);
  }
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const Islands want = plain_islands(n, scenes[s], immovable);
    EXPECT_EQ(want.count(), s == 0 ? m : m - 1) << "scene " << s;
    for (const int threads : {1, 2, 3, 8}) {
      SCOPED_TRACE("scene " + std::to_string(s) + ", threads " + std::to_string(threads));
      expect_same(islands_of(n, scenes[s], immovable, threads), want);
    }
  }
}

// ---------------------------------------------------------------------------
// Scenes with many islands, and solving them island by island.
// ---------------------------------------------------------------------------

/// Clusters of 1 to 8 movable bodies (and one of 120 bodies, a large
/// island), contacts inside each cluster, a fifth of them against an
/// immovable ground (body 0), a few between the ground and an immovable
/// wall (body 1); contacts of all clusters interleaved at random. Shaped
/// for `model` as collide/eval/hard_scenes.hpp shapes its families: sphere
/// bodies have three equal moments, particle bodies infinite moments and no
/// spin (the ground and the wall too).
template <class T>
Scene<T> island_scene(Model model, bool friction, std::uint64_t seed) {
  SceneRng rng(seed);
  SceneRecords<T> s;
  const auto shape = [&](BodyRecord<T> body) {
    if (model == Model::sphere) body.I[1] = body.I[2] = body.I[0];
    if (model == Model::particle) {
      for (int k = 0; k < 3; ++k) {
        body.I[k] = std::numeric_limits<T>::infinity();
        body.w[k] = T(0);
      }
    }
    return body;
  };
  for (int k = 0; k < 2; ++k) {
    BodyRecord<T> g = shape(random_body<T>(rng, {0.0, -6.0 + 12.0 * k, 0.0}));
    g.m = std::numeric_limits<T>::infinity();
    s.bodies.push_back(g);
  }
  std::vector<ContactRecord<T>> contacts;
  const auto contact = [&](BodyIndex ia, BodyIndex ib) {
    const BodyRecord<T>& a = s.bodies[ia];
    const auto d = rng.unit_vector();
    const double len = rng.uniform(0.1, 1.5);
    const std::array<double, 3> c{double(a.p[0]) + len * d[0], double(a.p[1]) + len * d[1],
                                  double(a.p[2]) + len * d[2]};
    ContactRecord<T> r = random_contact<T>(rng, ia, ib, c, friction);
    make_approach(a, s.bodies[ib], r);
    contacts.push_back(r);
  };
  std::size_t clusters = 0;
  while (s.bodies.size() < 2500) {
    const std::size_t size = clusters++ == 40 ? 120 : 1 + rng.index(8);
    const std::size_t first = s.bodies.size();
    const auto centre = rng.in_box(50);
    for (std::size_t i = 0; i < size; ++i) {
      const auto offset = rng.in_box(2);
      const std::array<double, 3> p{centre[0] + offset[0], centre[1] + offset[1], centre[2] + offset[2]};
      s.bodies.push_back(shape(random_body<T>(rng, p)));
    }
    const std::size_t count = size == 1 ? 1 : size + rng.index(size);
    for (std::size_t k = 0; k < count; ++k) {
      const auto ia = static_cast<BodyIndex>(first + rng.index(size));
      BodyIndex ib = 0;
      if (size > 1 && !rng.chance(0.2)) {
        do {
          ib = static_cast<BodyIndex>(first + rng.index(size));
        } while (ib == ia);
      }
      contact(ia, ib);
    }
  }
  for (int k = 0; k < 5; ++k) contact(0, 1);
  // Interleave the clusters: a seeded shuffle of the contacts.
  std::mt19937_64 g(seed);
  std::shuffle(contacts.begin(), contacts.end(), g);
  s.contacts = std::move(contacts);
  return s.scene();
}

/// The arrays of a contact set: the view's optional arrays kept optional.
template <class T>
struct ContactArrays {
  std::vector<BodyIndex> a, b;
  std::vector<T> cx, cy, cz, nx, ny, nz, e, mu;
  bool has_e = false, has_mu = false;
  T uniform_e = 1;

  [[nodiscard]] ContactView<T> view() const {
    ContactView<T> v;
    v.count = a.size();
    v.a = a.data();
    v.b = b.data();
    v.c = {cx.data(), cy.data(), cz.data()};
    v.n = {nx.data(), ny.data(), nz.data()};
    v.e = has_e ? e.data() : nullptr;
    v.uniform_e = uniform_e;
    v.mu = has_mu ? mu.data() : nullptr;
    return v;
  }
};

/// Solves the island `contacts` (indices into `whole`, ascending) on its
/// own: its bodies copied out of `state` (bit for bit, inverses as stored),
/// indices remapped, solved, v and w of its movable bodies copied back into
/// `state` and J into `j`.
template <class T>
void solve_island(const Solver& solver, Model model, const ContactView<T>& whole, const std::vector<std::size_t>& ids,
                  BodyBuffer<T>& state, ImpulseBuffer<T>& j) {
  std::vector<BodyIndex> bodies;
  for (const std::size_t k : ids) {
    bodies.push_back(whole.a[k]);
    bodies.push_back(whole.b[k]);
  }
  std::sort(bodies.begin(), bodies.end());
  bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
  const auto local = [&](BodyIndex i) {
    return static_cast<BodyIndex>(std::lower_bound(bodies.begin(), bodies.end(), i) - bodies.begin());
  };
  BodyBuffer<T> sub(bodies.size());
  const auto from = body_arrays<T>(std::as_const(state).view());
  const BodyView<T> sv = sub.view();
  T* const to[17] = {sv.inv_mass, sv.inv_inertia.x, sv.inv_inertia.y, sv.inv_inertia.z, sv.q.w, sv.q.x,
                     sv.q.y,      sv.q.z,           sv.p.x,           sv.p.y,           sv.p.z, sv.v.x,
                     sv.v.y,      sv.v.z,           sv.w.x,           sv.w.y,           sv.w.z};
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    for (std::size_t f = 0; f < 17; ++f) to[f][i] = from[f][bodies[i]];
  }
  ContactArrays<T> c;
  c.has_e = whole.e != nullptr;
  c.has_mu = whole.mu != nullptr;
  c.uniform_e = whole.uniform_e;
  for (const std::size_t k : ids) {
    c.a.push_back(local(whole.a[k]));
    c.b.push_back(local(whole.b[k]));
    c.cx.push_back(whole.c.x[k]);
    c.cy.push_back(whole.c.y[k]);
    c.cz.push_back(whole.c.z[k]);
    c.nx.push_back(whole.n.x[k]);
    c.ny.push_back(whole.n.y[k]);
    c.nz.push_back(whole.n.z[k]);
    c.e.push_back(c.has_e ? whole.e[k] : T(0));
    c.mu.push_back(c.has_mu ? whole.mu[k] : T(0));
  }
  const ContactView<T> cv = c.view();
  Schedule schedule;
  schedule.build(cv, sub.view());
  ImpulseBuffer<T> sub_j(ids.size());
  solver.solve(model, sub.view(), cv, sub_j.view(), schedule);

  const BodyView<T> st = state.view();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (is_immovable(sv, i)) continue;  // never written: nothing to copy back
    st.v.x[bodies[i]] = sv.v.x[i];
    st.v.y[bodies[i]] = sv.v.y[i];
    st.v.z[bodies[i]] = sv.v.z[i];
    st.w.x[bodies[i]] = sv.w.x[i];
    st.w.y[bodies[i]] = sv.w.y[i];
    st.w.z[bodies[i]] = sv.w.z[i];
  }
  const ImpulseView<T> jv = j.view();
  const ImpulseView<T> sj = sub_j.view();
  for (std::size_t l = 0; l < ids.size(); ++l) {
    jv.j.x[ids[l]] = sj.j.x[l];
    jv.j.y[ids[l]] = sj.j.y[l];
    jv.j.z[ids[l]] = sj.j.z[l];
  }
}

template <class T>
void expect_islands_solve_like_the_whole(Model model, Accuracy accuracy, bool friction) {
  SCOPED_TRACE(std::string(precision_name<T>()) + " " + to_string(model) + " " + to_string(accuracy) +
               (friction ? " friction" : " frictionless"));
  const Scene<T> scene = island_scene<T>(model, friction, 21);
  const ContactView<T> contacts = scene.contacts.view();
  ASSERT_TRUE(model_misfit(model, BodyBuffer<T>(scene.bodies).view(), contacts).empty());
  ASSERT_EQ(contacts.mu != nullptr, friction);

  SolverOptions options;
  options.accuracy = accuracy;
  options.threads = 2;
  const Solver solver(options);
  BodyBuffer<T> whole = scene.bodies;
  ImpulseBuffer<T> whole_j(contacts.count);
  Schedule schedule;
  schedule.build(contacts, whole.view());
  solver.solve(model, whole.view(), contacts, whole_j.view(), schedule);
  ASSERT_GT(schedule.batch_count(), 3u);  // bodies are shared: the islands have an order inside

  const Islands s = islands(contacts, scene.bodies.view());
  ASSERT_GT(s.count(), 300u);
  ASSERT_GE(s.largest, 120u);
  std::vector<std::vector<std::size_t>> ids(s.count());
  for (std::size_t k = 0; k < contacts.count; ++k) ids[s.contact_island[k]].push_back(k);

  std::vector<std::size_t> order(s.count());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::mt19937_64 g(3);
  for (const char* name : {"ascending", "descending", "shuffled"}) {
    SCOPED_TRACE(std::string("islands in ") + name + " order");
    if (std::string(name) == "descending") std::reverse(order.begin(), order.end());
    if (std::string(name) == "shuffled") std::shuffle(order.begin(), order.end(), g);
    BodyBuffer<T> state = scene.bodies;
    ImpulseBuffer<T> j(contacts.count);
    for (const std::size_t island : order) solve_island(solver, model, contacts, ids[island], state, j);
    EXPECT_TRUE(same_bodies(whole, state));
    EXPECT_TRUE(same_impulses(whole_j, j));
    // The same bytes, compared as bytes.
    const auto wb = body_arrays<T>(std::as_const(whole).view());
    const auto sb = body_arrays<T>(std::as_const(state).view());
    for (std::size_t f = 11; f < 17; ++f) EXPECT_EQ(std::memcmp(wb[f], sb[f], whole.size() * sizeof(T)), 0) << f;
    const ImpulseView<const T> wj = std::as_const(whole_j).view();
    const ImpulseView<const T> sj = std::as_const(j).view();
    for (const auto& [x, y] : {std::pair{wj.j.x, sj.j.x}, {wj.j.y, sj.j.y}, {wj.j.z, sj.j.z}}) {
      EXPECT_EQ(std::memcmp(x, y, contacts.count * sizeof(T)), 0);
    }
  }
}

/// One configuration of the island-by-island solve.
struct IslandCase {
  Model model;
  Accuracy accuracy;
  bool friction;
};

std::string describe(const IslandCase& c) {
  return std::string(to_string(c.model)) + "_" + to_string(c.accuracy) + (c.friction ? "_friction" : "_frictionless");
}

void PrintTo(const IslandCase& c, std::ostream* os) { *os << describe(c); }

std::vector<IslandCase> island_cases() {
  std::vector<IslandCase> cases;
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
      for (const bool friction : {false, true}) cases.push_back({model, accuracy, friction});
    }
  }
  return cases;
}

class IslandSolves : public ::testing::TestWithParam<IslandCase> {};

TEST_P(IslandSolves, EachIslandAloneGivesTheWholeSolvesBits) {
  const IslandCase c = GetParam();
  expect_islands_solve_like_the_whole<float>(c.model, c.accuracy, c.friction);
  expect_islands_solve_like_the_whole<double>(c.model, c.accuracy, c.friction);
}

INSTANTIATE_TEST_SUITE_P(AllModels, IslandSolves, ::testing::ValuesIn(island_cases()),
                         [](const auto& info) { return describe(info.param); });

TEST(Islands, PackedRecordsGiveTheIslandsOfTheirView) {
  for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
    const Scene<float> scene = island_scene<float>(model, false, 4);
    const ContactView<float> contacts = scene.contacts.view();
    const Islands soa = islands(contacts, scene.bodies.view());
    BodyBuffer<float> bodies = scene.bodies;
    if (model == Model::rigid) {
      PackedBuffer<PackedRigid<float>> records(bodies.size());
      pack(bodies.view(), packed_view(records));
      expect_same(islands(contacts, packed_view(records)), soa);
    } else if (model == Model::sphere) {
      PackedBuffer<PackedSphere<float>> records(bodies.size());
      pack(sphere_view(bodies.view()), packed_view(records));
      expect_same(islands(contacts, packed_view(records)), soa);
    } else {
      PackedBuffer<PackedParticle<float>> records(bodies.size());
      pack(particle_view(bodies.view()), packed_view(records));
      expect_same(islands(contacts, packed_view(records)), soa);
    }
  }
}

/// The message of the std::invalid_argument islands() throws, or "".
std::string refusal(std::size_t n, const Edges& edges, int threads = 0) {
  try {
    islands_of(n, edges, {}, threads);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Islands, BadInputIsRefusedNamingTheContact) {
  EXPECT_EQ(refusal(3, {{0, 1}, {1, 3}}), "collide::islands: contacts.b[1] = 3: out of range (3 bodies)");
  EXPECT_EQ(refusal(3, {{0, 1}, {1, 2}, {7, 2}}), "collide::islands: contacts.a[2] = 7: out of range (3 bodies)");
  EXPECT_EQ(refusal(3, {{2, 2}}), "collide::islands: contacts.b[0] = 2: a contact of a body with itself");
  EXPECT_EQ(refusal(3, {{0, 1}}, -1), "collide::islands: threads must be >= 0, got -1");
  ContactView<float> contacts;
  contacts.count = 2;
  const float inv_mass[2] = {1, 1};
  EXPECT_THROW(islands(contacts, 2, inv_mass), std::invalid_argument);
  const BodyIndex a[1] = {0}, b[1] = {1};
  contacts.count = 1;
  contacts.a = a;
  contacts.b = b;
  EXPECT_THROW(islands(contacts, 2, static_cast<const float*>(nullptr)), std::invalid_argument);
  EXPECT_EQ(islands(contacts, 2, inv_mass).count(), 1u);
}

}  // namespace
}  // namespace collide::test
