// minimal.cpp - the smallest complete program that embeds collide; quoted in
// docs/embedding.md and run by ctest, so the sample there always compiles.
//
// Two particles collide head-on and a third lands on the immovable ground.
// The bodies stay in the caller's own arrays: collide reads them through a
// view and writes the new velocities back in place.
#include <collide/schedule.hpp>
#include <collide/solve.hpp>

#include <cstdio>

int main() {
  // Bodies: inverse mass and velocity (the particle model). Body 3 is the
  // ground: inverse mass 0 makes it immovable.
  float inv_mass[] = {1, 1, 1, 0};
  float vx[] = {-1, 1, 0, 0}, vy[] = {0, 0, 0, 0}, vz[] = {0, 0, -2, 0};
  const collide::ParticleView<float> bodies{4, inv_mass, {vx, vy, vz}};

  // Contacts: bodies a and b, the contact point c and the unit normal n from
  // b towards a (the impulse on a is along +n).
  const collide::BodyIndex a[] = {0, 2}, b[] = {1, 3};
  const float cx[] = {0, 5}, cy[] = {0, 0}, cz[] = {0, 0};
  const float nx[] = {1, 0}, ny[] = {0, 0}, nz[] = {0, 1};
  collide::ContactView<float> contacts;
  contacts.count = 2;
  contacts.a = a;
  contacts.b = b;
  contacts.c = {cx, cy, cz};
  contacts.n = {nx, ny, nz};
  contacts.uniform_e = 0.5f;  // restitution; set contacts.mu for friction

  // Output: the impulse J on body a of every contact.
  float jx[2], jy[2], jz[2];
  const collide::ImpulseView<float> impulses{2, {jx, jy, jz}};

  collide::Schedule schedule;  // rebuild when the contacts change; keeps its buffers
  schedule.build(contacts, bodies.count, bodies.inv_mass);
  collide::SolverOptions options;
  options.threads = 2;                    // 0 (the default): every hardware thread
  const collide::Solver solver(options);  // owns its threads: make one, reuse it
  const collide::SolveStats stats = solver.solve(bodies, contacts, impulses, schedule);

  std::printf("model %s, %zu contacts in %zu batches, %zu conflicts\n", collide::to_string(stats.model), stats.contacts,
              stats.batches, schedule.conflicts());
  for (int k = 0; k < 2; ++k) std::printf("J[%d] = (%g, %g, %g)\n", k, jx[k], jy[k], jz[k]);
  for (int i = 0; i < 3; ++i) std::printf("v[%d] = (%g, %g, %g)\n", i, vx[i], vy[i], vz[i]);
}
