// report/convergence_rows.cpp - the convergence section of `collide report`:
// how far from converged (SolveStats::residual) a pile, a stack and debris
// are after 1 to 32 passes, in both orders and both iteration modes, cold
// and warm-started, against the time those passes take.
//
// Design notes
// ------------
// * The question a frame loop asks is "how many passes buy a residual I
//   accept, and what do they cost"; the speed rows of the report answer
//   "what does one pass cost". So a row is one solve of all its passes, its
//   time the kernel's, its residual the solve's own figure
//   (docs/collision-law.md, "The residual").
// * The scenes. The pile (generate_pile) and the stack are resting
//   problems, "the next frame": every body at rest, then one step of
//   gravity on the movable bodies (v_z = -g dt, z up), e = 0 (resting
//   contacts do not bounce, as an engine's restitution threshold decides).
//   The support must then travel from the ground up, which is what several
//   passes are for. The stack (columns of unit boxes, written here: no
//   generator has it) lists its contacts top first, the order in which the
//   support converges slowest in the input order; the pile's cell order is
//   bottom first, the easy one. The debris (generate_debris) is as
//   generated, every contact approaching: a scene of shared bodies with no
//   structure. All frictionless: Coulomb friction's passes are not a
//   contraction (docs/collision-law.md, "The error bound over passes"), so
//   the residual would measure the cone's clipping, not the iteration.
// * Warm rows: a frame loop starts each frame's passes from the last
//   frame's J. The stand-in for that J is the converged solve of the same
//   scene (kConvergedPasses accumulated passes, in the colour order); the warm
//   rows start from the same bodies with it (SolverOptions::warm_start), so
//   cold and warm rows solve the same problem and differ only in where the
//   passes start.
// * Timing: the rule of collide/eval/timing.hpp, as every row of the
//   report: one untimed warm-up, then timed solves, each after an untimed
//   restore of the bodies (and of the warm J, which the solve overwrites);
//   the median is reported. Float, the SIMD path on the default ISA, fast
//   mode (the accumulated passes run in it), the run's largest thread count.
// * The "next pass" column checks the residual from outside the solver:
//   one more plain pass on a copy of the solved bodies gives impulses as
//   large as what is still missing.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "collide/eval/timing.hpp"
#include "collide/io/generate.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/iteration.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "measure.hpp"

namespace collide::report_detail {

namespace {

/// One step of gravity at 60 Hz [m/s].
constexpr float kFall = 9.81F / 60;
/// Boxes per column of the stack: tall enough that the support needs many
/// plain passes to reach the top.
constexpr std::size_t kStackHeight = 16;
/// The passes of the cold rows, and of the warm rows.
constexpr int kPasses[] = {1, 2, 4, 8, 16, 32};
constexpr int kWarmPasses[] = {1, 2};
/// Accumulated passes of the solve whose J the warm rows start from: enough
/// for every scene's residual to be far below the rows' own.
constexpr int kConvergedPasses = 256;

/// Every body at rest, then one step of gravity on the movable ones; no
/// bounce.
void next_frame(Scene<float>& scene) {
  const BodyView<float> b = scene.bodies.view();
  for (std::size_t i = 0; i < b.count; ++i) {
    b.v.x[i] = b.v.y[i] = b.w.x[i] = b.w.y[i] = b.w.z[i] = 0;
    b.v.z[i] = b.inv_mass[i] > 0 ? -kFall : 0.0F;
  }
  for (std::size_t k = 0; k < scene.contacts.size(); ++k) {
    ContactRecord<float> c = scene.contacts.record(k);
    c.e = 0;
    scene.contacts.set(k, c);
  }
}

/// `columns` columns of kStackHeight unit boxes (1 kg, moments 1/6 kg m^2)
/// on a square grid of pitch 2 m, standing on the ground (the last body),
/// every box falling at g dt. Box k of a column (from the bottom) touches
/// the box or the ground below at the middle of their shared face, n = +z;
/// the contacts are listed top first, layer by layer. The boxes are
/// numbered layer by layer too, as a broadphase that sorts by height would
/// hand them: a layer's contacts then read neighbouring bodies, as the
/// pile's do, and the rows measure the iteration, not cache misses.
Scene<float> make_stack(std::size_t columns) {
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(columns))));
  const auto box = [columns](std::size_t column, std::size_t level) {
    return static_cast<BodyIndex>(level * columns + column);
  };
  const auto ground = static_cast<BodyIndex>(columns * kStackHeight);
  Scene<float> s;
  s.bodies.reserve(columns * kStackHeight + 1);
  for (std::size_t level = 0; level < kStackHeight; ++level) {
    for (std::size_t c = 0; c < columns; ++c) {
      BodyRecord<float> b;
      b.m = 1;
      b.I[0] = b.I[1] = b.I[2] = 1.0F / 6;
      const std::size_t grid_row = c / side;
      b.p[0] = 2.0F * static_cast<float>(c % side);
      b.p[1] = 2.0F * static_cast<float>(grid_row);
      b.p[2] = 0.5F + static_cast<float>(level);
      b.v[2] = -kFall;
      s.bodies.push_back(b);
    }
  }
  BodyRecord<float> g;
  g.m = g.I[0] = g.I[1] = g.I[2] = std::numeric_limits<float>::infinity();
  g.p[2] = -0.5F;
  s.bodies.push_back(g);
  s.contacts.reserve(columns * kStackHeight);
  for (std::size_t level = kStackHeight; level-- > 0;) {
    for (std::size_t c = 0; c < columns; ++c) {
      ContactRecord<float> k;
      k.a = box(c, level);
      k.b = level > 0 ? box(c, level - 1) : ground;
      const std::size_t grid_row = c / side;
      k.c[0] = 2.0F * static_cast<float>(c % side);
      k.c[1] = 2.0F * static_cast<float>(grid_row);
      k.c[2] = static_cast<float>(level);
      k.e = 0;
      s.contacts.push_back(k);
    }
  }
  return s;
}

/// The largest |J| of the solve.
float largest_impulse(const ImpulseBuffer<float>& impulses) {
  const ImpulseView<const float> j = impulses.view();
  float largest = 0;
  for (std::size_t k = 0; k < j.count; ++k) {
    largest = std::max(largest, std::sqrt(j.j.x[k] * j.j.x[k] + j.j.y[k] * j.j.y[k] + j.j.z[k] * j.j.z[k]));
  }
  return largest;
}

SolverOptions convergence_options(int threads, Iteration iteration, int passes, bool warm) {
  SolverOptions o;
  o.path = Path::simd;
  o.isa = default_isa();
  o.threads = threads;
  o.iteration = iteration;
  o.passes = passes;
  o.warm_start = warm;
  return o;
}

/// The rows of one scene: both orders, both modes, every pass count, then
/// the warm rows.
class SceneRows {
 public:
  SceneRows(std::string name, const Scene<float>& scene, int threads, int runs, std::vector<ConvergenceRow>& rows)
      : name_(std::move(name)), scene_(scene), threads_(threads), runs_(runs), rows_(rows) {}

  void run(const std::function<void(const std::string&)>& progress) {
    progress("convergence: " + name_ + ": the converged J");
    converged();
    for (const Order order : {Order::input, Order::colour}) {
      Schedule schedule(order);
      schedule.build(scene_.contacts.view(), scene_.bodies.size(), scene_.bodies.view().inv_mass);
      for (const Iteration iteration : {Iteration::repeat, Iteration::accumulate}) {
        for (const int passes : kPasses) {
          progress(what(order, iteration, passes, false));
          measure(schedule, convergence_options(threads_, iteration, passes, false), warm_);
        }
      }
      for (const int passes : kWarmPasses) {
        progress(what(order, Iteration::accumulate, passes, true));
        measure(schedule, convergence_options(threads_, Iteration::accumulate, passes, true), warm_);
      }
    }
  }

 private:
  [[nodiscard]] std::string what(Order order, Iteration iteration, int passes, bool warm) const {
    return "convergence: " + name_ + " " + to_string(order) + " " + to_string(iteration) + (warm ? " warm" : "") +
           ", " + std::to_string(passes) + " pass(es)";
  }

  /// The J the warm rows start from (warm_, and its residual): one
  /// converged solve per scene, in the colour order, whose threads make it
  /// the quicker; a converged J is the same problem's answer in either order.
  void converged() {
    Schedule schedule(Order::colour);
    schedule.build(scene_.contacts.view(), scene_.bodies.size(), scene_.bodies.view().inv_mass);
    const Solver solver(convergence_options(threads_, Iteration::accumulate, kConvergedPasses, false));
    BodyBuffer<float> bodies = scene_.bodies;
    warm_.resize(scene_.contacts.size());
    warm_residual_ = solver.solve(Model::rigid, bodies.view(), scene_.contacts.view(), warm_.view(), schedule).residual;
  }

  /// One row: the solve timed by the rule, then its next pass. `warm` is
  /// the J a warm-started solve starts from (unused when cold).
  void measure(const Schedule& schedule, const SolverOptions& options, const ImpulseBuffer<float>& warm) {
    const Solver solver(options);
    const ContactView<float> contacts = scene_.contacts.view();
    BodyBuffer<float> bodies = scene_.bodies;
    ImpulseBuffer<float> j(contacts.count);
    SolveStats stats;
    const RunTimes times = time_solve(
        RunPlan::fixed(runs_),
        [&] {
          bodies = scene_.bodies;
          if (options.warm_start) j = warm;
        },
        [&] { stats = solver.solve(Model::rigid, bodies.view(), contacts, j.view(), schedule); });

    ConvergenceRow row;
    row.scene = name_;
    row.order = to_string(schedule.order());
    row.iteration = to_string(options.iteration);
    row.passes = options.passes;
    row.warm = options.warm_start;
    row.n = contacts.count;
    row.threads = threads_;
    row.isa = to_string(stats.isa);
    row.runs = times.runs();
    row.seconds = times.median;
    row.collisions_per_second =
        row.seconds > 0 ? static_cast<double>(row.n) * static_cast<double>(row.passes) / row.seconds : 0;
    row.residual = stats.residual;
    row.start_residual = options.warm_start ? warm_residual_ : 1;

    const float largest = largest_impulse(j);
    const Solver next(convergence_options(threads_, Iteration::repeat, 1, false));
    ImpulseBuffer<float> more(contacts.count);
    next.solve(Model::rigid, bodies.view(), contacts, more.view(), schedule);
    row.next_pass = largest > 0 ? static_cast<double>(largest_impulse(more)) / largest : 0;
    rows_.push_back(std::move(row));
  }

  std::string name_;
  const Scene<float>& scene_;
  int threads_;
  int runs_;
  std::vector<ConvergenceRow>& rows_;
  ImpulseBuffer<float> warm_;
  double warm_residual_ = 1;
};

}  // namespace

std::size_t convergence_pile_side(const ReportOptions& options) {
  return std::max<std::size_t>(pile_side_for_contacts(options.convergence_n), 2);
}

std::vector<ConvergenceRow> measure_convergence_rows(const ReportOptions& options,
                                                     const std::function<void(const std::string&)>& progress) {
  const int threads = *std::max_element(options.threads.begin(), options.threads.end());
  const std::size_t side = convergence_pile_side(options);
  const std::size_t n = pile_contact_count(side);
  std::vector<ConvergenceRow> rows;
  GenerateOptions generate;
  generate.seed = options.seed;
  {
    progress("convergence: generating the pile");
    Scene<float> pile = generate_pile<float>(side, generate);
    next_frame(pile);
    SceneRows("pile", pile, threads, options.runs, rows).run(progress);
  }
  {
    progress("convergence: generating the stack");
    const Scene<float> stack = make_stack((n + kStackHeight - 1) / kStackHeight);
    SceneRows("stack", stack, threads, options.runs, rows).run(progress);
  }
  {
    progress("convergence: generating the debris");
    const Scene<float> debris = generate_debris<float>(n, generate);
    SceneRows("debris", debris, threads, options.runs, rows).run(progress);
  }
  return rows;
}

}  // namespace collide::report_detail
