// test_schedule.cpp - the level schedule (schedule.cpp) and the order in which
// the solver applies contacts that share bodies.
//
// What this proves
// ----------------
// * Topologies with known answers get the expected batches: a chain and a
//   star of n contacts need n batches, a Newton's cradle listed in order needs
//   one per contact and listed interleaved needs two, a star around an
//   immovable hub needs one.
// * On random shared-body scenes the schedule is exactly the documented level
//   schedule: each contact sits one batch past the latest batch of the earlier
//   contacts of its movable bodies, so the contacts of every movable body
//   appear in strictly increasing batch order (input order preserved per
//   body); no movable body appears twice in a batch; `order` is a permutation,
//   ascending in each batch; largest_batch, conflicts and the contiguity flags
//   are what they claim.
// * The build (body table, prefetched level pass, counting sort on 1 to 8
//   threads, schedule.cpp) gives every output identical to a plain reference
//   of the level rule written here, on random scenes of every shape: debris
//   (scattered bodies, a ground under a quarter of the contacts), pairs, one
//   shared movable body, bodies made immovable at random, dense scenes of a
//   few hundred levels, and scenes too small to prefetch or to split.
// * Contacts against an immovable body never conflict: 1e5 contacts on one
//   ground body form one batch.
// * The pairs scene is one contiguous batch.
// * memory_bytes() <= 16 B per contact + 8 B per body + 8 B per batch + a
//   small constant, and a rebuild for a scene of the same size allocates
//   nothing new.
// * Built from packed records (the inverse masses read in place), the
//   schedule is the same for every record type.
// * The solver's result on a shared-body scene is the law applied in input
//   order: bit for bit what the scalar path gives when the contacts are
//   solved strictly one by one in input order, and within the error bound of
//   the long double reference (which applies them in input order).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "support/error_bound.hpp"
#include "support/scenes.hpp"
#include "support/solve_helpers.hpp"

namespace collide::test {
namespace {

/// A scene with `n` movable unit bodies (and optionally one immovable body,
/// index n) and the given contacts; only the topology matters here.
Scene<double> topology(std::size_t n, const std::vector<std::pair<BodyIndex, BodyIndex>>& edges,
                       bool immovable_last = false) {
  Scene<double> s;
  for (std::size_t i = 0; i < n; ++i) s.bodies.push_back(BodyRecord<double>{});
  if (immovable_last) {
    BodyRecord<double> g;
    g.m = std::numeric_limits<double>::infinity();
    s.bodies.push_back(g);
  }
  for (const auto& [a, b] : edges) {
    ContactRecord<double> c;
    c.a = a;
    c.b = b;
    s.contacts.push_back(c);
  }
  return s;
}

Schedule build(const Scene<double>& s) {
  Schedule schedule;
  Scene<double> copy = s;
  schedule.build(copy.contacts.view(), copy.bodies.view());
  return schedule;
}

/// The contacts of batch k, in schedule order.
std::vector<std::uint32_t> batch(const Schedule& s, std::size_t k) {
  return {s.solve_order() + s.batch_begin(k), s.solve_order() + s.batch_begin(k + 1)};
}

TEST(Schedule, ChainNeedsOneBatchPerContact) {
  std::vector<std::pair<BodyIndex, BodyIndex>> edges;
  for (BodyIndex k = 0; k < 9; ++k) edges.emplace_back(k, k + 1);
  const Schedule s = build(topology(10, edges));
  EXPECT_EQ(s.batch_count(), 9u);
  EXPECT_EQ(s.largest_batch(), 1u);
  EXPECT_EQ(s.conflicts(), 8u);
  for (std::size_t k = 0; k < 9; ++k) EXPECT_EQ(batch(s, k), std::vector<std::uint32_t>{std::uint32_t(k)});
}

TEST(Schedule, StarNeedsOneBatchPerContact) {
  std::vector<std::pair<BodyIndex, BodyIndex>> edges;
  for (BodyIndex k = 1; k < 10; ++k) edges.emplace_back(k % 2 ? 0 : k, k % 2 ? k : 0);  // hub on either side
  const Schedule s = build(topology(10, edges));
  EXPECT_EQ(s.batch_count(), 9u);
  EXPECT_EQ(s.conflicts(), 8u);
}

TEST(Schedule, StarAroundImmovableHubIsOneBatch) {
  std::vector<std::pair<BodyIndex, BodyIndex>> edges;
  for (BodyIndex k = 0; k < 9; ++k) edges.emplace_back(k % 2 ? 9 : k, k % 2 ? k : 9);  // hub = body 9
  const Schedule s = build(topology(9, edges, true));
  EXPECT_EQ(s.batch_count(), 1u);
  EXPECT_EQ(s.conflicts(), 0u);
  EXPECT_TRUE(s.batch_is_contiguous(0));
}

// Five balls in a row: contacts (0,1) (1,2) (2,3) (3,4).
TEST(Schedule, NewtonsCradle) {
  {
    const Schedule s = build(topology(5, {{0, 1}, {1, 2}, {2, 3}, {3, 4}}));
    EXPECT_EQ(s.batch_count(), 4u);
    EXPECT_EQ(s.conflicts(), 3u);
  }
  {
    const Schedule s = build(topology(5, {{3, 4}, {2, 3}, {1, 2}, {0, 1}}));  // struck from the other end
    EXPECT_EQ(s.batch_count(), 4u);
  }
  {
    // Interleaved: (0,1) and (2,3) are independent, then (1,2) and (3,4).
    const Schedule s = build(topology(5, {{0, 1}, {2, 3}, {1, 2}, {3, 4}}));
    ASSERT_EQ(s.batch_count(), 2u);
    EXPECT_EQ(batch(s, 0), (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(batch(s, 1), (std::vector<std::uint32_t>{2, 3}));
    EXPECT_TRUE(s.batch_is_contiguous(0));
    EXPECT_TRUE(s.batch_is_contiguous(1));
    EXPECT_EQ(s.largest_batch(), 2u);
  }
  {
    // Every other contact: batches {0, 2} and {1, 3} are not contiguous.
    const Schedule s = build(topology(6, {{0, 1}, {1, 2}, {3, 4}, {4, 5}}));
    ASSERT_EQ(s.batch_count(), 2u);
    EXPECT_EQ(batch(s, 0), (std::vector<std::uint32_t>{0, 2}));
    EXPECT_EQ(batch(s, 1), (std::vector<std::uint32_t>{1, 3}));
    EXPECT_FALSE(s.batch_is_contiguous(0));
    EXPECT_FALSE(s.batch_is_contiguous(1));
  }
}

// Every property of the level schedule, recomputed independently.
void expect_level_schedule(const Scene<double>& scene, const Schedule& s) {
  const ContactView<double> c = scene.contacts.view();
  const BodyView<const double> b = scene.bodies.view();
  const std::size_t n = c.count;
  ASSERT_EQ(s.contact_count(), n);
  ASSERT_EQ(s.body_count(), b.count);
  ASSERT_EQ(s.batch_begin(0), 0u);
  ASSERT_EQ(s.batch_begin(s.batch_count()), n);

  // order is a permutation, ascending inside each batch; batch of each contact.
  std::vector<std::size_t> batch_of(n, ~std::size_t(0));
  std::size_t largest = 0;
  for (std::size_t k = 0; k < s.batch_count(); ++k) {
    ASSERT_LT(s.batch_begin(k), s.batch_begin(k + 1)) << "empty batch " << k;
    largest = std::max(largest, s.batch_begin(k + 1) - s.batch_begin(k));
    const auto members = batch(s, k);
    EXPECT_TRUE(std::is_sorted(members.begin(), members.end()));
    bool contiguous = true;
    for (std::size_t i = 0; i < members.size(); ++i) {
      ASSERT_LT(members[i], n);
      ASSERT_EQ(batch_of[members[i]], ~std::size_t(0)) << "contact twice in order";
      batch_of[members[i]] = k;
      if (i > 0 && members[i] != members[i - 1] + 1) contiguous = false;
    }
    EXPECT_EQ(s.batch_is_contiguous(k), contiguous) << "batch " << k;
  }
  EXPECT_EQ(largest, s.largest_batch());

  // Level rule, per-body order, no movable body twice in a batch, conflicts.
  std::vector<std::size_t> next(b.count, 0);  // first batch free for each body
  std::vector<long> last(b.count, -1);        // batch of the body's latest contact
  std::size_t conflicts = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t level = 0;
    for (const BodyIndex i : {c.a[k], c.b[k]}) {
      if (b.inv_mass[i] == 0) continue;
      level = std::max(level, next[i]);
      conflicts += next[i] > 0;
    }
    EXPECT_EQ(batch_of[k], level) << "contact " << k;
    for (const BodyIndex i : {c.a[k], c.b[k]}) {
      if (b.inv_mass[i] == 0) continue;
      EXPECT_GT(static_cast<long>(batch_of[k]), last[i]) << "body " << i << " out of input order at contact " << k;
      last[i] = static_cast<long>(batch_of[k]);
      next[i] = level + 1;
    }
  }
  EXPECT_EQ(s.conflicts(), conflicts);
}

TEST(Schedule, RandomSharedScenesAreTheLevelSchedule) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const Scene<double> scene = shared_scene<double>(20000, seed == 3 ? 500 : 10000, SceneOptions{seed});
    const Schedule s = build(scene);
    SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(s.batch_count()) + " batches");
    EXPECT_GT(s.batch_count(), 3u);
    expect_level_schedule(scene, s);
  }
}

// A contact topology and the inverse masses: all the schedule reads.
struct Topology {
  std::string name;
  std::vector<BodyIndex> a, b;
  std::vector<float> inv_mass;
};

/// The level rule, plainly: contact k goes one batch past the latest batch of
/// the earlier contacts of its movable bodies, and no lower than its window's
/// floor: the highest level before the window, when the contacts of the
/// window before it spanned at most Schedule::kShallowWindowLevels levels
/// (else the floor stays).
/// Batches hold their contacts in input order.
struct ReferenceSchedule {
  std::vector<std::vector<std::uint32_t>> batches;
  std::size_t conflicts = 0;

  explicit ReferenceSchedule(const Topology& t) {
    std::vector<std::size_t> batch_count_of_body(t.inv_mass.size(), 0);  // batches the body is already in
    std::size_t floor = 0;
    std::size_t lowest = std::numeric_limits<std::size_t>::max();  // of the levels in the current window
    std::size_t highest = 0;
    for (std::size_t k = 0; k < t.a.size(); ++k) {
      if (k % Schedule::kLevelWindow == 0 && k > 0) {
        if (highest - lowest < Schedule::kShallowWindowLevels) floor = batches.size() - 1;
        lowest = std::numeric_limits<std::size_t>::max();
        highest = 0;
      }
      std::size_t level = floor;
      for (const BodyIndex i : {t.a[k], t.b[k]}) {
        if (t.inv_mass[i] == 0) continue;
        level = std::max(level, batch_count_of_body[i]);
        if (batch_count_of_body[i] > 0) ++conflicts;
      }
      for (const BodyIndex i : {t.a[k], t.b[k]}) {
        if (t.inv_mass[i] != 0) batch_count_of_body[i] = level + 1;
      }
      if (batches.size() <= level) batches.resize(level + 1);
      batches[level].push_back(static_cast<std::uint32_t>(k));
      lowest = std::min(lowest, level);
      highest = std::max(highest, level);
    }
  }
};

/// Every output of `s` against the reference.
void expect_reference(const Topology& t, const Schedule& s) {
  const ReferenceSchedule r(t);
  ASSERT_EQ(s.contact_count(), t.a.size());
  ASSERT_EQ(s.body_count(), t.inv_mass.size());
  ASSERT_EQ(s.batch_count(), r.batches.size());
  EXPECT_EQ(s.conflicts(), r.conflicts);
  std::size_t begin = 0, largest = 0;
  for (std::size_t k = 0; k < r.batches.size(); ++k) {
    const std::vector<std::uint32_t>& want = r.batches[k];
    ASSERT_EQ(s.batch_begin(k), begin) << "batch " << k;
    ASSERT_EQ(s.batch_begin(k + 1), begin + want.size()) << "batch " << k;
    ASSERT_EQ(batch(s, k), want) << "batch " << k;
    bool contiguous = true;
    for (std::size_t i = 1; i < want.size(); ++i) contiguous = contiguous && want[i] == want[i - 1] + 1;
    EXPECT_EQ(s.batch_is_contiguous(k), contiguous) << "batch " << k;
    largest = std::max(largest, want.size());
    begin += want.size();
  }
  EXPECT_EQ(s.largest_batch(), largest);
}

/// n contacts over n/2 movable bodies at random (a != b), the ground (the last
/// body, immovable) on side b of every fourth contact, like generate_debris;
/// `ground_either_side` puts it on side a half of the time.
Topology debris_topology(std::size_t n, std::uint64_t seed, bool ground_either_side = false) {
  std::mt19937_64 rng(seed);
  const std::size_t movable = std::max<std::size_t>(2, n / 2);
  const auto ground = static_cast<BodyIndex>(movable);
  Topology t{"debris n=" + std::to_string(n), {}, {}, std::vector<float>(movable + 1, 1.0f)};
  t.inv_mass[ground] = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<BodyIndex>(rng() % movable);
    BodyIndex j = ground;
    if (k % 4 != 3) {
      j = static_cast<BodyIndex>(rng() % (movable - 1));
      if (j >= i) ++j;
    }
    const bool swap = ground_either_side && j == ground && (rng() & 1) != 0;
    t.a.push_back(swap ? j : i);
    t.b.push_back(swap ? i : j);
  }
  return t;
}

/// n contacts at random over `bodies` bodies, a fraction of them immovable
/// (inverse mass 0 or -0, both immovable), some contacts between two
/// immovable bodies.
Topology random_topology(std::size_t n, std::size_t bodies, double immovable, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Topology t{
      "random n=" + std::to_string(n) + " bodies=" + std::to_string(bodies), {}, {}, std::vector<float>(bodies, 0.5f)};
  for (std::size_t i = 0; i < bodies; ++i) {
    if (static_cast<double>(rng() % 1000) < immovable * 1000) t.inv_mass[i] = (i % 2) ? 0.0f : -0.0f;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<BodyIndex>(rng() % bodies);
    auto j = static_cast<BodyIndex>(rng() % (bodies - 1));
    if (j >= i) ++j;
    t.a.push_back(i);
    t.b.push_back(j);
  }
  return t;
}

Topology pairs_topology(std::size_t n) {
  Topology t{"pairs n=" + std::to_string(n), {}, {}, std::vector<float>(2 * n, 1.0f)};
  for (std::size_t k = 0; k < n; ++k) {
    t.a.push_back(static_cast<BodyIndex>(2 * k));
    t.b.push_back(static_cast<BodyIndex>(2 * k + 1));
  }
  return t;
}

/// pairs_topology(n) with contact `later` joined to a body of contact
/// `earlier` instead of its own b: one movable body repeats, once.
Topology pairs_sharing(std::size_t n, std::size_t earlier, std::size_t later) {
  Topology t = pairs_topology(n);
  t.name += ", contact " + std::to_string(later) + " shares a body with " + std::to_string(earlier);
  t.b[later] = t.a[earlier];
  return t;
}

/// n contacts, each of a body of its own with the ground (the last body,
/// immovable) on side b: one batch.
Topology on_the_ground_topology(std::size_t n) {
  Topology t{"on the ground n=" + std::to_string(n), {}, {}, std::vector<float>(n + 1, 1.0f)};
  t.inv_mass[n] = 0;
  for (std::size_t k = 0; k < n; ++k) {
    t.a.push_back(static_cast<BodyIndex>(k));
    t.b.push_back(static_cast<BodyIndex>(n));
  }
  return t;
}

/// Every contact shares movable body 0 (on either side): one batch per contact.
Topology all_shared_topology(std::size_t n) {
  Topology t{"all shared n=" + std::to_string(n), {}, {}, std::vector<float>(n + 1, 1.0f)};
  for (std::size_t k = 0; k < n; ++k) {
    const auto other = static_cast<BodyIndex>(k + 1);
    t.a.push_back(k % 2 ? 0 : other);
    t.b.push_back(k % 2 ? other : 0);
  }
  return t;
}

/// A scene whose contacts double from level to level, handed over grouped by
/// level: level L joins each body i < 2^L to a new body 2^L + i, so the
/// largest batch is the last.
Topology fan_topology(std::size_t levels) {
  const std::size_t bodies = std::size_t{1} << levels;
  Topology t{"fan of " + std::to_string(levels) + " levels", {}, {}, std::vector<float>(bodies, 1.0f)};
  for (std::size_t L = 0; L + 1 <= levels; ++L) {
    for (std::size_t i = 0; i < (std::size_t{1} << L); ++i) {
      t.a.push_back(static_cast<BodyIndex>(i));
      t.b.push_back(static_cast<BodyIndex>((std::size_t{1} << L) + i));
    }
  }
  return t;
}

/// `t` with its contacts in the order of its reference schedule: grouped by
/// level, as a caller who keeps them in solve order hands them over.
Topology grouped_topology(const Topology& t) {
  Topology g{t.name + ", grouped by level", {}, {}, t.inv_mass};
  for (const std::vector<std::uint32_t>& batch : ReferenceSchedule(t).batches) {
    for (const std::uint32_t k : batch) {
      g.a.push_back(t.a[k]);
      g.b.push_back(t.b[k]);
    }
  }
  return g;
}

// Sizes: scenes of 65536 contacts and more are sorted in chunks
// on 2 threads or more (32768 per chunk at least, schedule.cpp), the smaller
// ones run on one; 16 is the prefetch distance.
TEST(Schedule, EqualsPlainLevelRuleOnEveryShapeAndThreadCount) {
  std::vector<Topology> scenes = {
      debris_topology(200000, 1),
      debris_topology(150001, 2, true),
      debris_topology(3000, 3),
      pairs_topology(100000),
      pairs_topology(10),
      // One batch is looked for on every thread (schedule.cpp, "One batch"):
      // a body repeated after the probe, within a chunk or across two (each
      // chunk's claims alone succeed), and one batch on an immovable body.
      pairs_sharing(100000, 5000, 20000),
      pairs_sharing(100000, 10000, 90000),
      pairs_sharing(100000, 99998, 99999),
      on_the_ground_topology(80000),
      all_shared_topology(5000),
      random_topology(140000, 60000, 0.2, 4),   // immovable bodies at random, ~10 contacts per body
      random_topology(70000, 700, 0.1, 5),      // dense: hundreds of batches, still split on 2 threads
      random_topology(100000, 100000, 0.5, 6),  // half the bodies immovable
      random_topology(17, 5, 0.4, 7),           // just past the prefetch distance
      random_topology(15, 8, 0.0, 8),           // shorter than it
      random_topology(1, 2, 0.0, 9),
      random_topology(0, 2, 0.0, 10),
      // Contacts already grouped by level: the schedule is the identity.
      fan_topology(12),
      grouped_topology(debris_topology(3000, 3)),
      grouped_topology(random_topology(40000, 400, 0.1, 11)),
      grouped_topology(all_shared_topology(5000)),
  };
  for (const Topology& t : scenes) {
    for (const int threads : {1, 2, 3, 8, 0}) {
      SCOPED_TRACE(t.name + ", threads " + std::to_string(threads));
      ContactView<float> view;
      view.count = t.a.size();
      view.a = t.a.data();
      view.b = t.b.data();
      Schedule s;
      s.build(view, t.inv_mass.size(), t.inv_mass.data(), threads);
      expect_reference(t, s);
      // A rebuild into used buffers, on another thread count, is the same.
      s.build(view, t.inv_mass.size(), t.inv_mass.data(), threads == 1 ? 2 : 1);
      expect_reference(t, s);
    }
  }
}

// Debris over several level windows: every batch lies within two neighbouring
// windows, so the kernel reads it from one stretch of the input; the plain rule
// (no floor) spreads the first batches over the whole input. A chain (each
// window spans all its contacts' levels) keeps one contact per batch.
TEST(Schedule, ShallowWindowsKeepTheirBatchesTogether) {
  const Topology debris = debris_topology(6 * Schedule::kLevelWindow + 123, 11);
  ContactView<float> view;
  view.count = debris.a.size();
  view.a = debris.a.data();
  view.b = debris.b.data();
  Schedule s;
  s.build(view, debris.inv_mass.size(), debris.inv_mass.data(), 2);
  ASSERT_GT(s.batch_count(), 6u);
  for (std::size_t k = 0; k < s.batch_count(); ++k) {
    const std::vector<std::uint32_t> contacts = batch(s, k);
    ASSERT_FALSE(contacts.empty()) << "batch " << k;
    EXPECT_LE(contacts.back() / Schedule::kLevelWindow - contacts.front() / Schedule::kLevelWindow, 1u)
        << "batch " << k << " spans windows " << contacts.front() / Schedule::kLevelWindow << " to "
        << contacts.back() / Schedule::kLevelWindow;
  }

  const std::size_t n = 2 * Schedule::kLevelWindow + 7;
  Topology chain{"chain", {}, {}, std::vector<float>(n + 1, 1.0f)};
  for (std::size_t k = 0; k < n; ++k) {
    chain.a.push_back(static_cast<BodyIndex>(k));
    chain.b.push_back(static_cast<BodyIndex>(k + 1));
  }
  view.count = n;
  view.a = chain.a.data();
  view.b = chain.b.data();
  s.build(view, chain.inv_mass.size(), chain.inv_mass.data(), 2);
  EXPECT_EQ(s.batch_count(), n);
  expect_reference(chain, s);

  // The chain, then debris on bodies of their own: deep windows, then shallow
  // ones whose floors start from the chain's last level. The level pass
  // switches to wide words mid-window (at contact 254) and must still cut
  // windows at their boundaries.
  Topology both = chain;
  both.name = "chain, then debris";
  const auto first = static_cast<BodyIndex>(both.inv_mass.size());
  both.inv_mass.resize(first + debris.inv_mass.size(), 1.0f);
  for (std::size_t i = 0; i < debris.inv_mass.size(); ++i) both.inv_mass[first + i] = debris.inv_mass[i];
  for (std::size_t k = 0; k < debris.a.size(); ++k) {
    both.a.push_back(first + debris.a[k]);
    both.b.push_back(first + debris.b[k]);
  }
  view.count = both.a.size();
  view.a = both.a.data();
  view.b = both.b.data();
  for (const int threads : {1, 2}) {
    s.build(view, both.inv_mass.size(), both.inv_mass.data(), threads);
    expect_reference(both, s);
  }
}

/// The records of a packed layout holding t's inverse masses (the rest zero).
template <class Record>
PackedBuffer<Record> packed_inverse_masses(const Topology& t) {
  PackedBuffer<Record> records(t.inv_mass.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    if constexpr (std::is_same_v<Record, PackedRigid<float>>) {
      records.inv_mass[i] = t.inv_mass[i];  // beside the records (collide/packed.hpp)
    } else {
      records[i].inv_mass = t.inv_mass[i];
    }
  }
  return records;
}

// The packed overload reads each record's inverse mass in place (a stride of
// the record size; a rigid view's own array): every record type gives the level schedule, on scenes
// where immovable bodies sit at random so a wrong stride reads other values.
TEST(Schedule, PackedRecordsGiveTheSameSchedule) {
  const std::vector<Topology> scenes = {debris_topology(150001, 2, true), random_topology(100000, 100000, 0.5, 6),
                                        random_topology(15, 8, 0.3, 8), random_topology(0, 2, 0.0, 10)};
  for (const Topology& t : scenes) {
    ContactView<float> view;
    view.count = t.a.size();
    view.a = t.a.data();
    view.b = t.b.data();
    for (const int threads : {1, 2}) {
      SCOPED_TRACE(t.name + ", threads " + std::to_string(threads));
      Schedule s;
      PackedBuffer<PackedRigid<float>> rigid = packed_inverse_masses<PackedRigid<float>>(t);
      s.build(view, packed_view(rigid), threads);
      expect_reference(t, s);
      PackedBuffer<PackedSphere<float>> sphere = packed_inverse_masses<PackedSphere<float>>(t);
      s.build(view, packed_view(sphere), threads);
      expect_reference(t, s);
      PackedBuffer<PackedParticle<float>> particle = packed_inverse_masses<PackedParticle<float>>(t);
      s.build(view, packed_view(particle), threads);
      expect_reference(t, s);
    }
  }
}

// A bad index past the one-batch probe, in either chunk of a scene the
// threads test for one batch: the build names the first, as validate() does,
// whatever the thread count.
TEST(Schedule, FirstBadIndexIsNamedOnEveryThreadCount) {
  for (const int threads : {1, 2, 3, 0}) {
    Topology t = pairs_topology(100000);
    t.a[90000] = static_cast<BodyIndex>(t.inv_mass.size());
    t.b[70000] = t.a[70000];
    ContactView<float> view;
    view.count = t.a.size();
    view.a = t.a.data();
    view.b = t.b.data();
    Schedule s;
    std::string message;
    try {
      s.build(view, t.inv_mass.size(), t.inv_mass.data(), threads);
    } catch (const std::invalid_argument& e) {
      message = e.what();
    }
    EXPECT_EQ(message, "collide::Schedule::build: contacts.b[70000] = 140000: a contact of a body with itself")
        << "threads " << threads;
    EXPECT_EQ(s.batch_count(), 0u);
  }
}

TEST(Schedule, NegativeThreadCountIsRejected) {
  const Topology t = pairs_topology(4);
  ContactView<float> view;
  view.count = t.a.size();
  view.a = t.a.data();
  view.b = t.b.data();
  Schedule s;
  EXPECT_THROW(s.build(view, t.inv_mass.size(), t.inv_mass.data(), -1), std::invalid_argument);
}

// 1e5 contacts of distinct movable bodies with one ground body (on side a or
// b) conflict nowhere: one batch, contiguous.
TEST(Schedule, ContactsOnOneImmovableBodyFormOneBatch) {
  const std::size_t n = 100000;
  std::vector<std::pair<BodyIndex, BodyIndex>> edges;
  const auto ground = static_cast<BodyIndex>(n);
  for (BodyIndex k = 0; k < n; ++k) edges.emplace_back(k % 3 ? k : ground, k % 3 ? ground : k);
  const Scene<double> scene = topology(n, edges, true);
  const Schedule s = build(scene);
  EXPECT_EQ(s.batch_count(), 1u);
  EXPECT_EQ(s.largest_batch(), n);
  EXPECT_EQ(s.conflicts(), 0u);
  EXPECT_TRUE(s.batch_is_contiguous(0));
  expect_level_schedule(scene, s);
}

TEST(Schedule, PairsSceneIsOneContiguousBatch) {
  const Scene<double> scene = pairs_scene<double>(10001);
  const Schedule s = build(scene);
  ASSERT_EQ(s.batch_count(), 1u);
  EXPECT_TRUE(s.batch_is_contiguous(0));
  EXPECT_EQ(s.largest_batch(), 10001u);
  EXPECT_EQ(s.conflicts(), 0u);
}

TEST(Schedule, EmptySceneHasNoBatches) {
  const Scene<double> scene = topology(3, {});
  const Schedule s = build(scene);
  EXPECT_EQ(s.batch_count(), 0u);
  EXPECT_EQ(s.contact_count(), 0u);
}

// Memory: 16 B per contact + 8 B per body + 8 B per batch + 256 B. The
// documented footprint is 5 B per contact and 1 B per body (8 and 4 from 254
// batches on), 5 B per batch, and up to 1 B per contact of per-chunk counts.
TEST(Schedule, MemoryIsBoundedPerContactAndBody) {
  std::vector<std::pair<BodyIndex, BodyIndex>> chain;
  for (BodyIndex k = 0; k < 3000; ++k) chain.emplace_back(k, k + 1);
  const std::vector<Scene<double>> scenes = {pairs_scene<double>(50000), shared_scene<double>(60000, 20000),
                                             shared_scene<double>(30000, 300), topology(3001, chain)};
  for (const Scene<double>& scene : scenes) {
    Scene<double> copy = scene;
    Schedule s;
    s.build(copy.contacts.view(), copy.bodies.view());
    const std::size_t bound = 16 * scene.contacts.size() + 8 * scene.bodies.size() + 8 * s.batch_count() + 256;
    EXPECT_LE(s.memory_bytes(), bound) << scene.contacts.size() << " contacts, " << s.batch_count() << " batches";
    // Rebuilding for the same scene allocates nothing new.
    const std::size_t first = s.memory_bytes();
    s.build(copy.contacts.view(), copy.bodies.view());
    EXPECT_EQ(s.memory_bytes(), first);
  }
}

/// The scalar path applying the contacts strictly one at a time, in input
/// order: each call sees a one-contact view.
template <class T>
ImpulseBuffer<T> one_by_one(BodyBuffer<T>& bodies, const ContactView<T>& all) {
  ImpulseBuffer<T> j(all.count);
  const ImpulseView<T> jv = j.view();
  const Solver solver(options_for(Path::scalar, 1));
  Schedule schedule;
  for (std::size_t k = 0; k < all.count; ++k) {
    ContactView<T> one = all;
    one.count = 1;
    one.a += k;
    one.b += k;
    one.c = {all.c.x + k, all.c.y + k, all.c.z + k};
    one.n = {all.n.x + k, all.n.y + k, all.n.z + k};
    if (one.e) one.e += k;
    if (one.mu) one.mu += k;
    schedule.build(one, bodies.view());
    solver.solve(bodies.view(), one, ImpulseView<T>{1, {jv.j.x + k, jv.j.y + k, jv.j.z + k}}, schedule);
  }
  return j;
}

template <class T>
void expect_input_order(bool friction, bool uniform_e) {
  SCOPED_TRACE(std::string(type_name<T>()) + (friction ? " friction" : " frictionless") +
               (uniform_e ? " uniform e" : " per-contact e"));
  SceneOptions o;
  o.seed = 11 + friction;
  o.friction = friction;
  const Scene<T> scene = shared_scene<T>(3000, 600, o);
  ContactView<T> view = scene.contacts.view();
  if (uniform_e) {
    view.e = nullptr;
    view.uniform_e = T(0.625);
  }
  BodyBuffer<T> fast = scene.bodies;
  const ImpulseBuffer<T> jf = kernel_solve(fast, view, options_for(Path::simd, 3, 8));
  BodyBuffer<T> slow = scene.bodies;
  const ImpulseBuffer<T> js = one_by_one(slow, view);
  EXPECT_TRUE(same_bodies(fast, slow));
  EXPECT_TRUE(same_impulses(jf, js));
}

TEST(ScheduleOrder, SolverEqualsScalarOneByOneInInputOrderBitwise) {
  for (const bool friction : {false, true}) {
    for (const bool uniform_e : {false, true}) {
      expect_input_order<float>(friction, uniform_e);
      expect_input_order<double>(friction, uniform_e);
    }
  }
}

// The kernel on a shared-body scene against the reference applied in input
// order: within the error bound for every contact (test_accuracy.cpp measures
// the same on larger scenes and reports the numbers).
TEST(ScheduleOrder, SharedSceneMatchesSequentialReference) {
  SceneOptions o;
  o.seed = 17;
  o.friction = true;
  const Scene<double> scene = shared_scene<double>(4000, 1000, o);
  BodyBuffer<double> kb = scene.bodies;
  const ImpulseBuffer<double> j = kernel_solve(kb, scene.contacts.view(), options_for(Path::simd, 2, 8));
  Scene<long double> ref = convert_scene<long double>(scene);
  std::vector<ReferenceContact<long double>> diag;
  const ImpulseBuffer<long double> jr = reference(ref.bodies, ref.contacts.view(), &diag);
  const auto a = j.view();
  const auto r = jr.view();
  const long double eps = std::numeric_limits<double>::epsilon();
  std::size_t active = 0;
  for (std::size_t k = 0; k < j.size(); ++k) {
    const long double dx = a.j.x[k] - r.j.x[k], dy = a.j.y[k] - r.j.y[k], dz = a.j.z[k] - r.j.z[k];
    const long double err = std::sqrt(dx * dx + dy * dy + dz * dz);
    // Contacts the reference finds separating still have a normal scale.
    const long double scale = diag[k].impulse_scale;
    active += diag[k].jn > 0;
    EXPECT_LE(err, kErrorBoundEps * eps * scale) << "contact " << k;
  }
  // The scene is not trivial: many contacts act, many after earlier ones.
  EXPECT_GT(active, 2000u);
}

}  // namespace
}  // namespace collide::test
