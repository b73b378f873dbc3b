// bench/check.cpp - collide_bench's start-up check (check.hpp).
#include "check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "scenes.hpp"
#include "textbook.hpp"

namespace collide_bench {
namespace {

using collide::Path;

template <class T>
bool check_scene(Kind kind, std::ostream& out) {
  const std::size_t n = is_pile(kind) ? pile_size(5000) : 5000;
  const collide::Scene<T> original = generate<T>(kind, n);
  auto run = [&](auto&& solve) {
    collide::Scene<T> scene = original;
    collide::ImpulseBuffer<T> impulses(n);
    solve(scene, impulses);
    return std::make_pair(std::move(scene), std::move(impulses));
  };
  auto with_solver = [&](Path path, int threads) {
    return [=](collide::Scene<T>& scene, collide::ImpulseBuffer<T>& impulses) {
      collide::SolverOptions options;
      options.path = path;
      options.threads = threads;
      // The rigid model explicitly: collide::solve() would pick the cheapest
      // model that fits, and the rows time the rigid one.
      collide::Schedule schedule;
      schedule.build(scene.contacts.view(), scene.bodies.view());
      const collide::Solver solver(options);
      solver.solve(scene.bodies.view(), scene.contacts.view(), impulses.view(), schedule);
    };
  };
  const auto scalar = run(with_solver(Path::scalar, 1));
  const auto simd = run(with_solver(Path::simd, 2));
  const auto textbook = run([](collide::Scene<T>& scene, collide::ImpulseBuffer<T>& impulses) {
    textbook_solve(scene.bodies.view(), scene.contacts.view(), impulses.view());
  });

  // Flattens v, w and J of one result.
  auto values = [](const auto& result) {
    std::vector<T> out;
    const collide::BodyView<const T> b = result.first.bodies.view();
    for (const T* a : {b.v.x, b.v.y, b.v.z, b.w.x, b.w.y, b.w.z}) {
      out.insert(out.end(), a, a + b.count);
    }
    const collide::ImpulseView<const T> j = result.second.view();
    for (const T* a : {j.j.x, j.j.y, j.j.z}) {
      out.insert(out.end(), a, a + j.count);
    }
    return out;
  };
  const std::vector<T> vs = values(scalar), vv = values(simd), vt = values(textbook);
  const bool bitwise = std::memcmp(vs.data(), vv.data(), vs.size() * sizeof(T)) == 0;
  double max_diff = 0, max_value = 0;
  for (std::size_t i = 0; i < vv.size(); ++i) {
    max_diff = std::max(max_diff, std::abs(static_cast<double>(vv[i]) - static_cast<double>(vt[i])));
    max_value = std::max(max_value, std::abs(static_cast<double>(vt[i])));
  }
  const double relative = max_value > 0 ? max_diff / max_value : max_diff;
  // Rounding differences grow along the chains of shared bodies in debris,
  // so the tolerance is loose; it catches a wrong law, not a wrong last bit.
  const double tolerance = sizeof(T) == 4 ? 1e-2 : 1e-8;
  const bool ok = bitwise && relative <= tolerance;
  char line[256];
  std::snprintf(line, sizeof line,
                "check %-12s %s n=%zu: scalar/t:1 vs simd/t:2 %s; simd vs textbook max|diff|/max|x| = %.2e%s\n",
                kind_name(kind), precision_tag<T>(), n, bitwise ? "bitwise equal" : "DIFFER (kernel bug?)", relative,
                relative <= tolerance ? "" : " (TOO LARGE: kernel or textbook bug?)");
  out << line;
  return ok;
}

}  // namespace

bool check_kernels(std::ostream& out) {
  bool ok = true;
  // The chain: one batch per contact, the path a scene of sequential
  // contacts takes through the kernels.
  for (Kind kind : {Kind::pairs, Kind::debris, Kind::pairs_mu, Kind::pile_shuffled, Kind::chain}) {
    ok &= check_scene<float>(kind, out);
    ok &= check_scene<double>(kind, out);
  }
  return ok;
}

}  // namespace collide_bench
