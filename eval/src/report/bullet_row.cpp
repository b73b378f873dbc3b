// report/bullet_row.cpp - the peer row of `collide report`: Bullet's
// btSequentialImpulseConstraintSolver on the same pairs.
//
// Design notes
// ------------
// * Compiled only when CMake found Bullet with pkg-config (COLLIDE_WITH_BULLET);
//   without it the report says so and has no peer row (measure.cpp has the
//   stubs).
// * Bullet is configured to compute our law as closely as it can: one
//   iteration (the pairs share no body, so one sweep is exact), restitution
//   velocity threshold 0 (Bullet otherwise drops restitution below 0.2 m/s),
//   no warm starting (fresh points and a warm-starting factor 0; the mode
//   flag itself is on because Bullet writes the applied impulse back to the
//   manifold point only in that mode), no split
//   impulse and ERP 0 with zero penetration (no position correction folded
//   into the velocity), gyroscopic flags off (no spin integration inside the
//   solve), no gravity or forces. Each contact point is given as the same
//   world point c on both bodies, the restitution directly as the manifold
//   point's combined restitution, friction 0. docs/report.md lists where the
//   law still differs.
// * Bullet needs its own objects: a btRigidBody (744 bytes) per body and a
//   btPersistentManifold (880 bytes) per contact, 2.4 KB per pair, 9.6 GB for
//   four million pairs. So the pairs are fed in chunks of 2^18 pairs into
//   reused objects: loading a chunk (masses, inertia, transform, velocities,
//   the manifold point) is untimed, like the velocity restore of the kernel
//   rows, and only solveGroup is timed: Bullet's own setup (solver bodies,
//   constraint rows), its iteration and its write-back. A run's time is the
//   sum of its chunks' solveGroup times, and the runs follow the rule of
//   collide/eval/timing.hpp (measure_runs): one untimed warm-up run, then
//   `runs` timed runs, their median. A chunk's objects
//   (over 600 MB) are far larger than the last-level cache, so a chunk comes
//   from memory as the kernel's scene does.
// * Bullet here is the Debian build: btScalar is float (no
//   BT_USE_DOUBLE_PRECISION in bullet.pc), so the row's precision is float.
//   Masses are handed over as 1/(1/m) (Bullet stores 1/m itself; one
//   rounding), inverse moments exactly (setInvInertiaDiagLocal).
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "collide/eval/timing.hpp"
#include "collide/eval/traffic.hpp"
#include "measure.hpp"

namespace collide::report_detail {

namespace {

constexpr std::size_t kChunkPairs = std::size_t{1} << 18;

class BulletPeer {
 public:
  explicit BulletPeer(std::size_t pairs) {
    bodies_.reserve(2 * pairs);
    for (std::size_t i = 0; i < 2 * pairs; ++i) {
      btRigidBody::btRigidBodyConstructionInfo info(1, nullptr, &shape_, btVector3(1, 1, 1));
      bodies_.push_back(std::make_unique<btRigidBody>(info));
      bodies_.back()->setFlags(0);  // no gyroscopic term, no gravity flags
      body_ptrs_.push_back(bodies_.back().get());
    }
    for (std::size_t k = 0; k < pairs; ++k) {
      manifolds_.push_back(std::make_unique<btPersistentManifold>(bodies_[2 * k].get(), bodies_[2 * k + 1].get(), 0,
                                                                  BT_LARGE_FLOAT, BT_LARGE_FLOAT));
      manifold_ptrs_.push_back(manifolds_.back().get());
    }
    info_.m_numIterations = 1;
    info_.m_restitutionVelocityThreshold = 0;
    // Bullet writes the applied impulse back to the manifold point only in
    // warm-starting mode, so the mode is on with a factor of 0: every point is
    // fresh (applied impulse 0) and nothing is carried into the solve.
    info_.m_solverMode = SOLVER_SIMD | SOLVER_USE_WARMSTARTING;  // no random order
    info_.m_warmstartingFactor = 0;
    info_.m_splitImpulse = 0;
    info_.m_erp = 0;
    info_.m_erp2 = 0;
    info_.m_linearSlop = 0;
    info_.m_globalCfm = 0;
  }

  /// Loads contacts [first, first + count) and their bodies (untimed).
  void load(const Scene<float>& scene, std::size_t first, std::size_t count) {
    const BodyView<const float> b = scene.bodies.view();
    const ContactView<float> c = scene.contacts.view();
    count_ = count;
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t i = first + k;
      btRigidBody& a = *bodies_[2 * k];
      btRigidBody& bb = *bodies_[2 * k + 1];
      set_body(a, b, c.a[i]);
      set_body(bb, b, c.b[i]);
      btPersistentManifold& m = *manifolds_[k];
      m.setBodies(&a, &bb);
      m.clearManifold();
      btManifoldPoint point(btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(c.n.x[i], c.n.y[i], c.n.z[i]), 0);
      point.m_positionWorldOnA = btVector3(c.c.x[i], c.c.y[i], c.c.z[i]);
      point.m_positionWorldOnB = point.m_positionWorldOnA;
      point.m_localPointA = a.getCenterOfMassTransform().invXform(point.m_positionWorldOnA);
      point.m_localPointB = bb.getCenterOfMassTransform().invXform(point.m_positionWorldOnB);
      point.m_combinedRestitution = c.e ? c.e[i] : c.uniform_e;
      point.m_combinedFriction = 0;
      point.m_combinedRollingFriction = 0;
      point.m_combinedSpinningFriction = 0;
      m.addManifoldPoint(point);
    }
  }

  /// The timed part: one solveGroup over the loaded chunk. Returns seconds.
  double solve() {
    const auto t0 = std::chrono::steady_clock::now();
    solver_.solveGroup(body_ptrs_.data(), static_cast<int>(2 * count_), manifold_ptrs_.data(), static_cast<int>(count_),
                       nullptr, 0, info_, nullptr, nullptr);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  /// Reads the impulses and the velocities of the loaded chunk back into the
  /// scene's layout.
  void store(const Scene<float>& scene, std::size_t first, ImpulseView<float> j, BodyView<float> out) const {
    const ContactView<float> c = scene.contacts.view();
    for (std::size_t k = 0; k < count_; ++k) {
      const std::size_t i = first + k;
      const btManifoldPoint& p = manifolds_[k]->getContactPoint(0);
      // Frictionless: the lateral impulses are 0, J is the normal impulse on a.
      const btVector3 impulse = p.m_normalWorldOnB * p.m_appliedImpulse;
      j.j.x[i] = impulse.x();
      j.j.y[i] = impulse.y();
      j.j.z[i] = impulse.z();
      store_body(*bodies_[2 * k], out, c.a[i]);
      store_body(*bodies_[2 * k + 1], out, c.b[i]);
    }
  }

 private:
  static void set_body(btRigidBody& rb, const BodyView<const float>& b, std::size_t i) {
    const float inv_mass = b.inv_mass[i];
    rb.setMassProps(inv_mass > 0 ? 1.0f / inv_mass : 0.0f, btVector3(0, 0, 0));
    rb.setInvInertiaDiagLocal(btVector3(b.inv_inertia.x[i], b.inv_inertia.y[i], b.inv_inertia.z[i]));
    rb.setWorldTransform(
        btTransform(btQuaternion(b.q.x[i], b.q.y[i], b.q.z[i], b.q.w[i]), btVector3(b.p.x[i], b.p.y[i], b.p.z[i])));
    rb.updateInertiaTensor();
    rb.setLinearVelocity(btVector3(b.v.x[i], b.v.y[i], b.v.z[i]));
    rb.setAngularVelocity(btVector3(b.w.x[i], b.w.y[i], b.w.z[i]));
  }
  static void store_body(const btRigidBody& rb, BodyView<float>& out, std::size_t i) {
    const btVector3& v = rb.getLinearVelocity();
    const btVector3& w = rb.getAngularVelocity();
    out.v.x[i] = v.x();
    out.v.y[i] = v.y();
    out.v.z[i] = v.z();
    out.w.x[i] = w.x();
    out.w.y[i] = w.y();
    out.w.z[i] = w.z();
  }

  btEmptyShape shape_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btPersistentManifold>> manifolds_;
  std::vector<btCollisionObject*> body_ptrs_;
  std::vector<btPersistentManifold*> manifold_ptrs_;
  btSequentialImpulseConstraintSolver solver_;
  btContactSolverInfo info_;
  std::size_t count_ = 0;
};

}  // namespace

std::string bullet_version() {
  const int v = btGetVersion();
  return "bullet " + std::to_string(v / 100) + "." + std::to_string(v % 100);
}

ReportRow bullet_row(const Scene<float>& scene, std::size_t n, const Scene<float>& sample,
                     const ReferenceResult& reference, int runs, double triad_bytes_per_second) {
  n = std::min(n, scene.contacts.size());
  BulletPeer peer(std::min(kChunkPairs, std::max(n, sample.contacts.size())));

  ReportRow row;
  row.scene = "pairs";
  row.variant = "bullet";
  row.model = "rigid";
  row.precision = "float";
  row.threads = 1;
  row.n = n;
  row.note = bullet_version() + ", solveGroup per " + std::to_string(kChunkPairs) + " pairs";
  if (n != scene.contacts.size()) row.note = "first " + std::to_string(n) + " contacts; " + row.note;
  // One run: every chunk loaded (untimed) and solved (timed).
  const RunTimes times = measure_runs(RunPlan::fixed(runs), [&] {
    double total = 0;
    for (std::size_t first = 0; first < n; first += kChunkPairs) {
      peer.load(scene, first, std::min(kChunkPairs, n - first));
      total += peer.solve();
    }
    return total;
  });
  row.runs = times.runs();
  row.seconds = times.median;
  row.collisions_per_second = row.seconds > 0 ? static_cast<double>(n) / row.seconds : 0;
  row.bytes_per_collision = static_cast<double>(bytes_per_collision(Model::rigid, sizeof(float), false));
  row.bandwidth_fraction =
      bandwidth_fraction(row.collisions_per_second, Model::rigid, sizeof(float), false, triad_bytes_per_second);

  // The error sample, through the same chunks.
  BodyBuffer<float> after = sample.bodies;
  ImpulseBuffer<float> j(sample.contacts.size());
  for (std::size_t first = 0; first < sample.contacts.size(); first += kChunkPairs) {
    peer.load(sample, first, std::min(kChunkPairs, sample.contacts.size() - first));
    peer.solve();
    peer.store(sample, first, j.view(), after.view());
  }
  fill_error<float>(row, std::as_const(j).view(), std::as_const(after).view(), reference,
                    static_cast<double>(std::numeric_limits<float>::epsilon()));
  return row;
}

}  // namespace collide::report_detail
