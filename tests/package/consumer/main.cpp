// A C++17 program that uses collide the way an embedding project does.
//
// Built four ways by tests/package/: in the collide build tree, against an
// installed package through find_package(collide COMPONENTS io eval), through
// add_subdirectory(collide), and with the flags of `pkg-config collide-eval`.
// It is compiled under -std=c++17 -Wall -Wextra -Wpedantic -Werror, so a
// C++20-only construct or a warning in a header fails the build, and it runs
// a scene whose answer is known exactly, so a library that links but
// misbehaves (a missing TBB, a wrong instantiation) fails the run.
//
// With COLLIDE_CONSUMER_CORE_ONLY it includes and links the core alone
// (collide::collide, `pkg-config collide`), the way a project that brings its
// own scenes embeds the solver: the core must build, install and link without
// the io and eval libraries.
#include <collide/accuracy.hpp>
#include <collide/bodies.hpp>
#include <collide/contacts.hpp>
#include <collide/isa.hpp>
#include <collide/model.hpp>
#include <collide/schedule.hpp>
#include <collide/solve.hpp>
#include <collide/validate.hpp>
#if !defined(COLLIDE_CONSUMER_CORE_ONLY)
#include <collide/eval/error_bound.hpp>
#include <collide/eval/reference.hpp>
#include <collide/io/generate.hpp>
#include <collide/io/scene.hpp>
#include <collide/io/scene_io.hpp>
#endif

#include <cmath>
#include <cstdio>
#include <vector>

static_assert(__cplusplus >= 201703L && __cplusplus < 202002L,
              "the consumer must be compiled as C++17: it proves the public headers are C++17");

namespace {

int failures = 0;

void expect(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FAILED: %s\n", what);
    ++failures;
  }
}

// Four bodies in the caller's own arrays (float): a head-on pair (0, 1), a
// ball (2) dropping on an immovable ground (3). Every contact point lies on
// the line of centres, so choose_model() must find the particle model.
void solve_caller_arrays() {
  std::vector<float> inv_mass{1, 1, 1, 0}, inv_inertia{2.5f, 2.5f, 2.5f, 0};
  std::vector<float> qw(4, 1), qx(4, 0), qy(4, 0), qz(4, 0);
  std::vector<float> px{0.5f, -0.5f, 5, 5}, py{0, 0, 0, 0}, pz{1, 1, 0.5f, -1};
  std::vector<float> vx{-1, 1, 0, 0}, vy(4, 0), vz{0, 0, -2, 0};
  std::vector<float> wx(4, 0), wy(4, 0), wz(4, 0);
  collide::BodyView<float> bodies;
  bodies.count = 4;
  bodies.inv_mass = inv_mass.data();
  bodies.inv_inertia = {inv_inertia.data(), inv_inertia.data(), inv_inertia.data()};
  bodies.q = {qw.data(), qx.data(), qy.data(), qz.data()};
  bodies.p = {px.data(), py.data(), pz.data()};
  bodies.v = {vx.data(), vy.data(), vz.data()};
  bodies.w = {wx.data(), wy.data(), wz.data()};

  const std::vector<collide::BodyIndex> a{0, 2}, b{1, 3};
  const std::vector<float> cx{0, 5}, cy{0, 0}, cz{1, 0};
  const std::vector<float> nx{1, 0}, ny{0, 0}, nz{0, 1};
  const std::vector<float> e{1.0f, 0.5f};
  collide::ContactView<float> contacts;
  contacts.count = 2;
  contacts.a = a.data();
  contacts.b = b.data();
  contacts.c = {cx.data(), cy.data(), cz.data()};
  contacts.n = {nx.data(), ny.data(), nz.data()};
  contacts.e = e.data();

  std::vector<float> jx(2), jy(2), jz(2);
  const collide::ImpulseView<float> impulses{2, {jx.data(), jy.data(), jz.data()}};

  expect(static_cast<bool>(collide::validate(bodies, contacts, impulses)), "validate accepts the scene");
  const collide::Model model = collide::choose_model(bodies, contacts);
  expect(model == collide::Model::particle, "choose_model finds the particle model");

  collide::Schedule schedule;
  schedule.build(contacts, bodies);
  collide::SolverOptions options;
  options.threads = 2;
  const collide::Solver solver(options);
  const collide::SolveStats stats = solver.solve(model, bodies, contacts, impulses, schedule);

  expect(stats.contacts == 2 && stats.batches == 1 && stats.model == collide::Model::particle, "stats");
  expect(schedule.conflicts() == 0, "no body is shared");
  // Equal masses, e = 1: the pair swaps velocities. The ball leaves the ground
  // at half its approach speed.
  expect(vx[0] == 1 && vx[1] == -1 && jx[0] == 2, "head-on pair swaps velocities");
  expect(vz[2] == 1 && jz[1] == 3, "ball bounces with e = 0.5");
  expect(vz[3] == 0, "the ground does not move");
  std::printf("caller arrays: model %s, %zu contacts, %zu batches, J0 = (%g, %g, %g), J1 = (%g, %g, %g)\n",
              collide::to_string(stats.model), stats.contacts, stats.batches, jx[0], jy[0], jz[0], jx[1], jy[1], jz[1]);
}

#if !defined(COLLIDE_CONSUMER_CORE_ONLY)
// Owned buffers in double, the one-shot solve(), and the reference: exercises
// the libraries' explicit instantiations and the TBB-backed scene generator.
void solve_owned_buffers() {
  collide::Scene<double> scene = collide::generate_pairs<double>(1000, {});
  collide::Scene<double> copy = collide::convert_scene<double>(scene);
  collide::ImpulseBuffer<double> impulses(scene.contacts.size());
  collide::ImpulseBuffer<double> reference(scene.contacts.size());
  const collide::SolveStats stats = collide::solve(scene.bodies.view(), scene.contacts.view(), impulses.view());
  collide::reference_solve(copy.bodies.view(), copy.contacts.view(), reference.view());
  double worst = 0;
  for (std::size_t k = 0; k < impulses.size(); ++k) {
    worst = std::fmax(worst, std::fabs(impulses.view().j.x[k] - reference.view().j.x[k]));
  }
  expect(stats.contacts == 1000, "one-shot solve resolves every contact");
  expect(worst < 1e-9, "kernel agrees with the reference");
  std::printf("owned buffers: %zu contacts on %zu lanes x %d threads, model %s, max |dJx| = %g\n", stats.contacts,
              stats.lanes, stats.threads, collide::to_string(stats.model), worst);
}
#endif

}  // namespace

// A library built with COLLIDE_KERNEL_ISAS=sse2 has no wider kernel to offer,
// whatever the CPU has, and still solves (above) on its baseline lanes.
void check_kernels_built() {
#if defined(COLLIDE_CONSUMER_BASELINE_ONLY)
  expect(collide::best_isa() == collide::Isa::sse2, "COLLIDE_KERNEL_ISAS=sse2: best_isa() is sse2");
  expect(!collide::isa_supported(collide::Isa::avx2), "COLLIDE_KERNEL_ISAS=sse2: no AVX2 kernel");
  std::puts("consumer: baseline kernel only, as configured");
#endif
}

int main() {
  solve_caller_arrays();
#if !defined(COLLIDE_CONSUMER_CORE_ONLY)
  solve_owned_buffers();
#else
  std::puts("consumer: the core alone");
#endif
  check_kernels_built();
  if (failures != 0) return 1;
  std::puts("consumer: ok");
  return 0;
}
