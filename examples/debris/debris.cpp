// collide_debris - spheres and particles fall onto an immovable ground and onto
// each other; every contact is resolved by collide through its public API.
//
//   build/examples/debris/collide_debris --out debris.png
//
// Design notes
// ------------
// * These files are the simulation a user of the library writes; collide
//   only resolves contacts. Spheres have isotropic inertia, and a particle is
//   a small sphere with inverse inertia 0 (it never spins), so the sphere
//   model is the law for both and orientation is never stored.
// * One file a job, so that the calls into collide stand in one place
//   (frame.cpp), apart from the simulation around them: world.cpp the bodies
//   and their set-up, broadphase.cpp each step's contacts, frame.cpp one
//   step (contacts, solve, position correction, integration), output.cpp
//   what is printed, drawn and checked, and this file the command line and
//   the run.
// * The bodies live in collide's packed layout (collide/packed.hpp), one
//   64-byte collide::PackedSphere<float> record per body holding v, w, p,
//   inverse mass and inverse inertia, for the whole run. Why packed: the
//   contacts come from the broadphase, ordered by height, not by body, so
//   the solver reaches bodies at random; in separate arrays per component
//   that is a cache line per component per body, in a record it is one line
//   (collide/packed.hpp). Why for the whole run: the records are the
//   simulation's state, not a copy of it. Gravity, the broadphase, position
//   correction, integration, the energy and the picture read and write the
//   records, and the solver writes v and w into them in place, so nothing is
//   packed or unpacked per step (handing collide SoA views would have it pack
//   and unpack on every solve of a scattered scene).
// * Side arrays, indexed like the records, hold what collide does not read:
//   the radius (broadphase, picture), mass and moment of inertia (energy, in
//   double). One exception: Schedule::build reads inverse masses from a plain
//   array, so the example keeps a copy of them, written once with the records
//   (masses never change).
// * One step, symplectic Euler:
//     1. v += g dt                        (gravity)
//     2. contacts from penetration        (uniform grid over the bodies)
//     3. schedule.build, then solver.solve a few passes   (collide)
//     4. position correction of deep overlaps
//     5. p += v dt
//   The kernel applies an impulse only to approaching contacts (u.n < 0), so
//   resting and separating contacts are passed in unchanged and cost nothing
//   but a lane.
// * Contacts change every step, so the Schedule is rebuilt every step; it
//   keeps its buffers, so after the first steps it allocates nothing. One
//   Solver (one thread pool) serves the whole run, its passes
//   (SolverOptions::passes) sharing each step's schedule.
// * Several passes per step: one pass applies each contact once; in a pile a
//   body pushed by a later contact may approach an earlier one again.
//   Re-solving the same contacts (2 to 4 passes) resolves most of that,
//   which is the usual sequential-impulse iteration.
// * Both solve orders run by default, each from the same initial world: the
//   input order (the contacts as the broadphase lists them) and the colour
//   order collide chooses (collide/schedule.hpp), and the table at the end
//   sets their energy and the resting pile's overlaps side by side.
// * Position correction: impulses fix velocities, never positions, so a pile
//   under gravity slowly interpenetrates by the per-step velocity error. Each
//   step pushes overlapping bodies apart by a fraction of their overlap beyond
//   a small slop, in proportion to inverse mass. The potential energy that
//   adds is counted, and the energy check subtracts it.
// * Contact order: ground contacts first, then pairs from the bottom of the
//   pile upwards, so one pass in input order already carries support from the
//   ground up; the colour order gives that up for speed, and its passes carry
//   the support instead.
// * Energy is kinetic + rotational + potential (m g z) in double. With
//   restitution < 1 or friction it must not grow beyond what the position
//   correction adds; --check turns that and "contacts were resolved" into an
//   exit status (the ctest test runs it). With e = 1 and mu = 0 the check does
//   not hold and is not meant to: a body bouncing elastically on a resting
//   contact climbs out of its overlap a little every step (up to m g times
//   its depth), an artefact of penetration-based contacts, not of the kernel.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <collide/schedule.hpp>

#include "broadphase.hpp"
#include "frame.hpp"
#include "options.hpp"
#include "output.hpp"
#include "world.hpp"

namespace debris {
namespace {

void usage(const char* argv0) {
  std::printf(
      "usage: %s [options]\n"
      "  --spheres N      spheres (default 2000)\n"
      "  --particles N    particles (default 2000)\n"
      "  --steps N        time steps (default 600: 2.5 s at dt = 1/240 s)\n"
      "  --dt S           time step [s]\n"
      "  --e E            restitution in [0, 1] (default 0.3)\n"
      "  --mu MU          friction coefficient (default 0.5)\n"
      "  --passes N       solver passes per step (default 3)\n"
      "  --iteration I    what the passes after the first do: repeat (default: the law again)\n"
      "                   or accumulate (each contact's total impulse moved and clamped)\n"
      "  --warm-start     start each step's accumulated passes from the last step's impulse\n"
      "                   of the same two bodies (needs --iteration accumulate)\n"
      "  --order O        input, colour or both (default: both, the same world once in each\n"
      "                   solve order, the figures of each side by side)\n"
      "  --threads N      worker threads, 0 = all (default 0)\n"
      "  --every N        print every N-th step (default 1)\n"
      "  --seed N         random seed (default 1)\n"
      "  --out FILE.png   picture of energy over time and of the final pile (gnuplot), of\n"
      "                   each order run: FILE.png for the first, FILE-colour.png for colour\n"
      "                   when both run\n"
      "  --check          exit 1 unless, in every order run, energy stayed bounded (needs\n"
      "                   e < 1 or mu > 0), contacts were resolved and the resting pile's\n"
      "                   deepest overlap is below 10 mm\n",
      argv0);
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--check") {
      o.check = true;
      continue;
    }
    if (arg == "--warm-start") {
      o.warm_start = true;
      continue;
    }
    if (arg == "--help" || arg == "-h") return false;
    if (i + 1 >= argc) {
      std::fprintf(stderr, "%s needs a value\n", arg.c_str());
      return false;
    }
    const char* value = argv[++i];
    if (arg == "--spheres") {
      o.spheres = std::atoi(value);
    } else if (arg == "--particles") {
      o.particles = std::atoi(value);
    } else if (arg == "--steps") {
      o.steps = std::atoi(value);
    } else if (arg == "--dt") {
      o.dt = std::atof(value);
    } else if (arg == "--e") {
      o.restitution = std::atof(value);
    } else if (arg == "--mu") {
      o.friction = std::atof(value);
    } else if (arg == "--passes") {
      o.passes = std::atoi(value);
    } else if (arg == "--iteration") {
      o.iteration = value;
    } else if (arg == "--order") {
      o.order = value;
    } else if (arg == "--threads") {
      o.threads = std::atoi(value);
    } else if (arg == "--every") {
      o.every = std::max(1, std::atoi(value));
    } else if (arg == "--seed") {
      o.seed = std::strtoull(value, nullptr, 10);
    } else if (arg == "--out") {
      o.out = value;
    } else {
      std::fprintf(stderr, "unknown option %s\n", arg.c_str());
      return false;
    }
  }
  if (o.spheres < 0 || o.particles < 0 || o.spheres + o.particles == 0 || o.steps < 1 || !(o.dt > 0) || o.passes < 1 ||
      !(o.restitution >= 0 && o.restitution <= 1) || !(o.friction >= 0) || o.threads < 0 ||
      (o.order != "input" && o.order != "colour" && o.order != "both") ||
      (o.iteration != "repeat" && o.iteration != "accumulate") || (o.warm_start && o.iteration != "accumulate")) {
    std::fprintf(stderr, "bad option value\n");
    return false;
  }
  return true;
}

/// The whole simulation in one solve order, from the same initial world.
RunSummary simulate(const Options& o, collide::Order order, const std::string& png) {
  World world = make_world(o);
  Frame frame(o, order);

  RunSummary r;
  r.order = order;
  r.iteration = o.iteration;
  r.warm_start = o.warm_start;
  r.passes = o.passes;
  const Energy e0 = energy(world);
  r.e0 = e0.total();
  r.max_total = r.e0;
  print_run_header(o, order);

  std::vector<StepRecord> history;
  const auto t_start = std::chrono::steady_clock::now();
  for (int step = 1; step <= o.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    const StepFigures f = frame.step(world);
    const Contacts& contacts = frame.contacts();
    r.stats = f.stats;
    r.solve_seconds += f.solve_seconds;
    r.solved_contacts += contacts.size() * static_cast<std::size_t>(o.passes);
    r.final_max_depth = f.max_depth;
    r.final_mean_depth = f.mean_depth;
    r.lifted += f.lifted;

    const Energy e = energy(world);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    history.push_back({step * o.dt, e, contacts.size(), contacts.ground, f.resolved});
    r.max_total = std::max(r.max_total, e.total());
    r.max_excess = std::max(r.max_excess, e.total() - r.lifted - r.e0);
    r.max_contacts = std::max(r.max_contacts, contacts.size());
    r.max_resolved = std::max(r.max_resolved, f.resolved);
    r.final_contacts = contacts.size();
    if (step % o.every == 0 || step == o.steps) print_step_row(step, history.back(), f, frame.conflicts(), ms);
  }
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  r.e_end = energy(world).total();
  print_run_summary(o, r);
  write_picture(png, history, world);
  return r;
}

/// FILE.png -> FILE-colour.png.
std::string colour_png(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  return dot == std::string::npos ? path + "-colour" : path.substr(0, dot) + "-colour" + path.substr(dot);
}

}  // namespace
}  // namespace debris

int main(int argc, char** argv) {
  debris::Options o;
  if (!debris::parse(argc, argv, o)) {
    debris::usage(argv[0]);
    return 2;
  }
  std::vector<debris::RunSummary> runs;
  if (o.order != "colour") runs.push_back(debris::simulate(o, collide::Order::input, o.out));
  if (o.order != "input") {
    runs.push_back(debris::simulate(o, collide::Order::colour,
                                    o.order == "both" && !o.out.empty() ? debris::colour_png(o.out) : o.out));
  }

  debris::print_orders(runs);

  if (o.check && !debris::check(runs)) return 1;
  return 0;
}
