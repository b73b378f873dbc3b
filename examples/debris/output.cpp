// output.cpp - the printing, the picture and the check of collide_debris
// (output.hpp): the format of every line the example prints, and the bounds
// --check holds a run to, in one place.
#include "output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace debris {
namespace {

/// The deepest overlap --check accepts in the pile after the last step [m]:
/// five times the position correction's slop.
constexpr double kMaxRestingDepth = 0.010;

/// Two panels: energy and contacts over time, and the final state seen from
/// above, coloured by height. The data go to gnuplot inline, so no temporary
/// files are left behind.
bool write_png(const std::string& path, const std::vector<StepRecord>& history, const World& w) {
  std::FILE* gp = popen("gnuplot", "w");
  if (!gp) return false;
  std::fprintf(gp, "set terminal pngcairo size 1600,700 font ',11'\nset output '%s'\n", path.c_str());
  std::fprintf(gp, "$energy << EOD\n");
  for (const StepRecord& r : history) {
    std::fprintf(gp, "%g %g %g %g %zu %zu\n", r.t, r.e.kinetic + r.e.rotational, r.e.potential, r.e.total(), r.contacts,
                 r.resolved);
  }
  std::fprintf(gp, "EOD\n$pile << EOD\n");
  for (std::size_t i = 1; i < w.size(); ++i) {
    const Real* p = w.bodies[i].p;
    std::fprintf(gp, "%g %g %g %g\n", p[0], p[1], w.radius[i], p[2]);
  }
  std::fprintf(gp, "EOD\n");
  std::fputs(
      "set multiplot layout 1,2 title 'collide debris: spheres and particles falling onto a ground'\n"
      "set title 'energy and contacts per step'\n"
      "set xlabel 'time [s]'\nset ylabel 'energy [J]'\nset y2label 'contacts per step'\n"
      "set ytics nomirror\nset y2tics\nset key center right opaque box\nset grid\n"
      "plot $energy using 1:4 with lines lw 2 title 'total', "
      "'' using 1:3 with lines title 'potential', "
      "'' using 1:2 with lines title 'kinetic + rotational', "
      "'' using 1:5 axes x1y2 with lines dt 2 lw 2 title 'contacts', "
      "'' using 1:6 axes x1y2 with lines dt 3 lw 2 title 'resolved (J != 0)'\n"
      "unset y2label\nunset y2tics\nset ytics mirror\nunset grid\n"
      "set title 'final state from above (colour: height)'\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n"
      "unset key\nset size ratio -1\nset cblabel 'z [m]'\nset palette rgb 33,13,10\n"
      "set style fill solid 0.8 noborder\n"
      "plot $pile using 1:2:3:4 with circles lc palette notitle\n"
      "unset multiplot\n",
      gp);
  return pclose(gp) == 0;
}

}  // namespace

namespace {
/// How the passes iterate, as the run header says it.
const char* iteration_name(const Options& o) {
  if (o.iteration != "accumulate") return "";
  return o.warm_start ? ", accumulated, warm-started" : ", accumulated";
}
}  // namespace

void print_run_header(const Options& o, collide::Order order) {
  std::printf("\n%s order: %d spheres + %d particles on a ground, dt = %g s, e = %g, mu = %g, %d passes%s\n",
              collide::to_string(order), o.spheres, o.particles, o.dt, o.restitution, o.friction, o.passes,
              iteration_name(o));
  std::printf("%5s %6s %10s %10s %10s %7s %7s %7s %8s %7s %9s %7s %7s\n", "step", "t[s]", "E_kin[J]", "E_pot[J]",
              "E_tot[J]", "contact", "ground", "pairs", "resolved", "batches", "conflicts", "pen[mm]", "ms");
}

void print_step_row(int step, const StepRecord& record, const StepFigures& figures, std::size_t conflicts, double ms) {
  std::printf("%5d %6.3f %10.3f %10.3f %10.3f %7zu %7zu %7zu %8zu %7zu %9zu %7.2f %7.2f\n", step, record.t,
              record.e.kinetic + record.e.rotational, record.e.potential, record.e.total(), record.contacts,
              record.ground, record.contacts - record.ground, record.resolved, figures.stats.batches, conflicts,
              1000 * figures.max_depth, ms);
}

void print_run_summary(const Options& o, const RunSummary& r) {
  std::printf(
      "done: %d steps in %.2f s; up to %zu contacts per step, up to %zu resolved (J != 0); "
      "collide: %.1f M contact-solves/s (model %s, %zu lanes, %d threads, %zu colours)\n",
      o.steps, r.wall, r.max_contacts, r.max_resolved, r.solved_contacts / std::max(r.solve_seconds, 1e-9) / 1e6,
      collide::to_string(r.stats.model), r.stats.lanes, r.stats.threads, r.stats.colours);
  std::printf("energy: start %.3f J, end %.3f J, highest %.3f J; position correction lifted %.3f J\n", r.e0, r.e_end,
              r.max_total, r.lifted);
}

void write_picture(const std::string& png, const std::vector<StepRecord>& history, const World& w) {
  if (!png.empty()) {
    if (!write_png(png, history, w)) {
      std::fprintf(stderr, "could not write %s with gnuplot (scripts/install-deps.sh installs gnuplot-nox)\n",
                   png.c_str());
      std::exit(1);
    }
    std::printf("wrote %s\n", png.c_str());
  }
}

void print_orders(const std::vector<RunSummary>& runs) {
  std::printf("\n%-7s %-16s %6s %14s %14s %13s %13s %12s %12s\n", "order", "iteration", "passes", "E_end[J]",
              "E_highest[J]", "pen_max[mm]", "pen_mean[mm]", "contacts", "M solves/s");
  for (const RunSummary& r : runs) {
    const char* iteration = r.iteration != "accumulate" ? "repeat" : r.warm_start ? "accumulate+warm" : "accumulate";
    std::printf("%-7s %-16s %6d %14.3f %14.3f %13.3f %13.3f %12zu %12.1f\n", collide::to_string(r.order), iteration,
                r.passes, r.e_end, r.max_total, 1000 * r.final_max_depth, 1000 * r.final_mean_depth, r.final_contacts,
                r.solved_contacts / std::max(r.solve_seconds, 1e-9) / 1e6);
  }
}

bool check(const std::vector<RunSummary>& runs) {
  // Contacts never add energy (e <= 1, friction dissipates); only the
  // position correction does, and that is accounted for. What is left is
  // rounding and the time discretisation: 0.1% of the start energy.
  // Non-finite energy fails too. Every order is held to the same bounds,
  // the resting pile's deepest overlap among them.
  bool ok = true;
  for (const RunSummary& r : runs) {
    const char* name = collide::to_string(r.order);
    const bool bounded = std::isfinite(r.max_total) && r.max_excess <= 1e-3 * std::fabs(r.e0);
    const bool resolved_some = r.max_resolved > 0 && r.final_contacts > 0;
    const bool resting = r.final_max_depth < kMaxRestingDepth;
    if (!bounded) {
      std::fprintf(stderr,
                   "check failed (%s order): energy grew by %g J beyond the %g J the position correction "
                   "added\n",
                   name, r.max_excess, r.lifted);
    }
    if (!resolved_some) std::fprintf(stderr, "check failed (%s order): no contact was resolved\n", name);
    if (!resting) {
      std::fprintf(stderr, "check failed (%s order): the resting pile overlaps by up to %g mm (bound %g mm)\n", name,
                   1000 * r.final_max_depth, 1000 * kMaxRestingDepth);
    }
    ok = ok && bounded && resolved_some && resting;
  }
  if (ok) std::puts("check: ok");
  return ok;
}

}  // namespace debris
