// race_canary.cpp - proves that the TSan run can see a race in the kernel.
//
// The TSan run of the parallel kernel tests passes only if TSan reports
// nothing, and it reports nothing only because the ITT bridge hands it TBB's
// synchronisation and tbb.supp hides TBB's own task bookkeeping. This
// program checks that neither hides a real race on the kernel's data: it
// builds the schedule of a scene of independent pairs (one batch, no two
// contacts on a body) and then, against that schedule, solves contacts that
// all join bodies 0 and 1 - a violated precondition (the schedule was not
// built for these contacts) under which blocks of the one batch run on
// several threads and write the same two bodies. scripts/ci-sanitizers.sh
// runs it under TSan and requires a data race report in solve.cpp; a TSan
// setup that stays silent here fails the CI.
//
// It is not a ctest test: in a correct build its only outcome is TSan's
// report (exit code 66).
#include <cstdio>

#include <oneapi/tbb/global_control.h>

#include "collide/io/scene.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"

int main() {
  using namespace collide;
  constexpr std::size_t kPairs = 4096;
  tbb::global_control workers(tbb::global_control::max_allowed_parallelism, 4);

  Scene<double> pairs, clash;
  for (std::size_t k = 0; k < 2 * kPairs; ++k) {
    BodyRecord<double> b;
    b.p[2] = k % 2 == 0 ? 1 : -1;
    b.v[2] = k % 2 == 0 ? -1 : 1;
    pairs.bodies.push_back(b);
  }
  for (std::size_t k = 0; k < kPairs; ++k) {
    ContactRecord<double> c;
    c.a = static_cast<BodyIndex>(2 * k);
    c.b = static_cast<BodyIndex>(2 * k + 1);
    pairs.contacts.push_back(c);
    c.a = 0;  // every contact on bodies 0 and 1
    c.b = 1;
    clash.contacts.push_back(c);
  }
  Schedule schedule;
  schedule.build(pairs.contacts.view(), pairs.bodies.view());
  std::printf("race_canary: %zu contacts in %zu batch(es), all on bodies 0 and 1\n", kPairs, schedule.batch_count());

  SolverOptions options;
  options.threads = 4;
  options.block = 8;
  const Solver solver(options);
  ImpulseBuffer<double> j(kPairs);
  for (int round = 0; round < 20; ++round) {
    solver.solve(pairs.bodies.view(), clash.contacts.view(), j.view(), schedule);
  }
  return 0;
}
