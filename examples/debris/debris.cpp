// collide_debris - spheres and particles fall onto an immovable ground and onto
// each other; every contact is resolved by collide through its public API.
//
//   build/examples/debris/collide_debris --out debris.png
//
// Design notes
// ------------
// * This file is the simulation a user of the library writes; collide only
//   resolves contacts. Spheres have isotropic inertia, and a particle is a
//   small sphere with inverse inertia 0 (it never spins), so the sphere model
//   is the law for both and orientation is never stored.
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
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <collide/bodies.hpp>
#include <collide/contacts.hpp>
#include <collide/packed.hpp>
#include <collide/schedule.hpp>
#include <collide/solve.hpp>

namespace {

using Real = float;                        // what collide solves in: 8 lanes with AVX2, 16 with AVX-512
using Body = collide::PackedSphere<Real>;  // v, w, p, inverse mass, inverse inertia
constexpr double kGravity = 9.81;
constexpr double kPi = 3.14159265358979323846;
/// The deepest overlap --check accepts in the pile after the last step [m]:
/// five times the position correction's slop.
constexpr double kMaxRestingDepth = 0.010;

struct Options {
  int spheres = 2000;
  int particles = 2000;
  int steps = 600;
  double dt = 1.0 / 240.0;
  double restitution = 0.3;
  double friction = 0.5;
  int passes = 3;
  std::string order = "both";  // input, colour, or both one after the other
  int threads = 0;             // 0: every hardware thread
  int every = 1;               // print every n-th step
  std::uint64_t seed = 1;
  std::string out;  // PNG path; empty: no picture
  bool check = false;
};

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
      (o.order != "input" && o.order != "colour" && o.order != "both")) {
    std::fprintf(stderr, "bad option value\n");
    return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// The world: body 0 is the ground, the plane z = 0 (immovable: inverse mass 0).
// ---------------------------------------------------------------------------
struct World {
  collide::PackedBuffer<Body> bodies;  // the state collide reads, and v, w it writes
  std::vector<Real> radius;            // [m]
  std::vector<double> mass, inertia;   // [kg], [kg m^2], for the energy
  std::size_t spheres = 0;             // bodies 1..spheres are spheres, the rest particles

  [[nodiscard]] std::size_t size() const { return bodies.size(); }

  void add(double m, double moment, double r, double x, double y, double z) {
    Body body{};  // at rest
    body.p[0] = static_cast<Real>(x);
    body.p[1] = static_cast<Real>(y);
    body.p[2] = static_cast<Real>(z);
    body.inv_mass = std::isinf(m) ? Real(0) : static_cast<Real>(1 / m);
    body.inv_inertia = std::isinf(moment) ? Real(0) : static_cast<Real>(1 / moment);
    bodies.push_back(body);
    radius.push_back(static_cast<Real>(r));
    mass.push_back(m);
    inertia.push_back(moment);
  }

  /// The records as collide sees them; nothing is copied.
  collide::PackedView<Body> view() { return collide::packed_view(bodies); }
};

constexpr double kDensity = 1000;  // [kg/m^3]
constexpr double kSphereRadius[2] = {0.05, 0.10};
constexpr double kParticleRadius = 0.025;

/// Spheres and particles on a jittered lattice above the ground, shuffled so
/// that both kinds are everywhere in the cloud, with small random velocities.
World make_world(const Options& o) {
  const double inf = std::numeric_limits<double>::infinity();
  World world;
  world.add(inf, inf, 0, 0, 0, 0);  // the ground
  const int n = o.spheres + o.particles;
  std::vector<int> kind(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) kind[static_cast<std::size_t>(i)] = i < o.spheres ? 0 : 1;
  std::mt19937_64 rng(o.seed);
  std::shuffle(kind.begin(), kind.end(), rng);
  std::uniform_real_distribution<double> unit(0, 1);

  // A square block of lattice sites; a site holds the largest sphere.
  const double spacing = 2 * kSphereRadius[1] * 1.1;
  // About 1.6 n^(1/3) sites a side: a cloud a few times wider than tall, so
  // bodies land on the ground and on each other at a few m/s.
  const int side = std::max(1, static_cast<int>(1.6 * std::cbrt(n)));
  world.spheres = static_cast<std::size_t>(o.spheres);
  // Spheres first (ids 1..spheres), then particles: sites come from `kind`.
  std::vector<std::size_t> site_of_body;
  for (int pass = 0; pass < 2; ++pass) {
    for (int s = 0; s < n; ++s) {
      if (kind[static_cast<std::size_t>(s)] != pass) continue;
      const double x = (s % side - 0.5 * (side - 1)) * spacing + 0.1 * spacing * (unit(rng) - 0.5);
      const double y = ((s / side) % side - 0.5 * (side - 1)) * spacing + 0.1 * spacing * (unit(rng) - 0.5);
      const double z = kSphereRadius[1] * 1.5 + static_cast<double>(s / (side * side)) * spacing;  // layer
      const double r =
          pass == 0 ? kSphereRadius[0] + (kSphereRadius[1] - kSphereRadius[0]) * unit(rng) : kParticleRadius;
      const double m = kDensity * 4.0 / 3.0 * kPi * r * r * r;
      // A particle has no rotational state: infinite moment, inverse 0.
      const double moment = pass == 0 ? 0.4 * m * r * r : inf;
      world.add(m, moment, r, x, y, z);
      Body& body = world.bodies.bodies.back();
      body.v[0] = static_cast<Real>(0.5 * (unit(rng) - 0.5));
      body.v[1] = static_cast<Real>(0.5 * (unit(rng) - 0.5));
    }
  }
  return world;
}

// ---------------------------------------------------------------------------
// Contacts: the caller's arrays again, handed to collide as a ContactView.
// ---------------------------------------------------------------------------
struct Contacts {
  std::vector<collide::BodyIndex> a, b;
  std::vector<Real> cx, cy, cz, nx, ny, nz, mu;
  std::vector<Real> depth;  // overlap [m], for the position correction
  std::vector<Real> jx, jy, jz;
  std::size_t ground = 0;  // the first `ground` contacts are with the ground

  void clear() {
    for (auto* v : {&cx, &cy, &cz, &nx, &ny, &nz, &mu, &depth}) v->clear();
    a.clear();
    b.clear();
    ground = 0;
  }
  [[nodiscard]] std::size_t size() const { return a.size(); }

  /// Contact of body i (side a) with body j (side b), normal from j to i.
  void add(collide::BodyIndex i, collide::BodyIndex j, const double c[3], const double n[3], double overlap,
           double friction) {
    a.push_back(i);
    b.push_back(j);
    cx.push_back(static_cast<Real>(c[0]));
    cy.push_back(static_cast<Real>(c[1]));
    cz.push_back(static_cast<Real>(c[2]));
    nx.push_back(static_cast<Real>(n[0]));
    ny.push_back(static_cast<Real>(n[1]));
    nz.push_back(static_cast<Real>(n[2]));
    mu.push_back(static_cast<Real>(friction));
    depth.push_back(static_cast<Real>(overlap));
  }

  collide::ContactView<Real> view(double restitution) const {
    collide::ContactView<Real> v;
    v.count = size();
    v.a = a.data();
    v.b = b.data();
    v.c = {cx.data(), cy.data(), cz.data()};
    v.n = {nx.data(), ny.data(), nz.data()};
    v.uniform_e = static_cast<Real>(restitution);  // e == nullptr: one restitution for all
    v.mu = mu.data();
    return v;
  }
  collide::ImpulseView<Real> impulses() {
    jx.resize(size());
    jy.resize(size());
    jz.resize(size());
    return {size(), {jx.data(), jy.data(), jz.data()}};
  }
};

// ---------------------------------------------------------------------------
// Broadphase: a uniform grid over the bounding box of the bodies, cells at
// least one largest diameter wide, so overlapping bodies are in the same or
// neighbouring cells. Bodies are bucketed by a counting sort; each body then
// tests the bodies with larger ids in the 27 cells around it, so each pair is
// tested once.
// ---------------------------------------------------------------------------
class UniformGrid {
 public:
  void find_contacts(const World& w, double friction, Contacts& out) {
    out.clear();
    const std::size_t n = w.size();
    // Ground contacts: anything reaching below z = 0. The ground is side b,
    // its normal +z; the contact point is the middle of the overlap.
    for (std::size_t i = 1; i < n; ++i) {
      const Real* p = w.bodies[i].p;
      const double overlap = w.radius[i] - p[2];
      if (overlap > 0) {
        const double c[3] = {p[0], p[1], -0.5 * overlap};
        const double up[3] = {0, 0, 1};
        out.add(static_cast<collide::BodyIndex>(i), 0, c, up, overlap, friction);
      }
    }
    out.ground = out.size();

    bucket(w);
    pairs_.clear();
    for (std::size_t i = 1; i < n; ++i) {
      const Real* p = w.bodies[i].p;
      const int cx = cell_coord(p[0], 0), cy = cell_coord(p[1], 1), cz = cell_coord(p[2], 2);
      for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, dims_[2] - 1); ++z) {
        for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, dims_[1] - 1); ++y) {
          for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, dims_[0] - 1); ++x) {
            const std::size_t cell = index(x, y, z);
            for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
              const std::uint32_t j = sorted_[k];
              if (j > i) test_pair(w, static_cast<std::uint32_t>(i), j);
            }
          }
        }
      }
    }
    // Bottom of the pile first: support travels up in a single pass.
    std::sort(pairs_.begin(), pairs_.end(), [](const Pair& p, const Pair& q) { return p.z < q.z; });
    for (const Pair& pair : pairs_) {
      const Real* pi = w.bodies[pair.i].p;
      const Real* pj = w.bodies[pair.j].p;
      const double dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
      const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
      const double overlap = w.radius[pair.i] + w.radius[pair.j] - d;
      const double nrm[3] = {dx / d, dy / d, dz / d};  // from j towards i
      const double reach = w.radius[pair.j] - 0.5 * overlap;
      const double c[3] = {pj[0] + nrm[0] * reach, pj[1] + nrm[1] * reach, pj[2] + nrm[2] * reach};
      out.add(pair.i, pair.j, c, nrm, overlap, friction);
    }
  }

 private:
  struct Pair {
    std::uint32_t i, j;
    float z;  // height of the lower centre
  };

  void bucket(const World& w) {
    const std::size_t n = w.size();
    double max_radius = 0;
    for (int a = 0; a < 3; ++a) {
      lo_[a] = std::numeric_limits<double>::infinity();
      hi_[a] = -std::numeric_limits<double>::infinity();
    }
    for (std::size_t i = 1; i < n; ++i) {
      max_radius = std::max<double>(max_radius, w.radius[i]);
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min<double>(lo_[a], w.bodies[i].p[a]);
        hi_[a] = std::max<double>(hi_[a], w.bodies[i].p[a]);
      }
    }
    // A body thrown far away would make a dense grid huge: cells grow until
    // there are at most 8 per body (larger cells only mean more candidates).
    cell_ = 2 * max_radius;
    for (;;) {
      std::size_t cells = 1;
      for (int a = 0; a < 3; ++a) {
        dims_[a] = static_cast<int>((hi_[a] - lo_[a]) / cell_) + 1;
        cells *= static_cast<std::size_t>(dims_[a]);
      }
      if (cells <= 8 * n + 64) break;
      cell_ *= 2;
    }
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
    cell_of_.resize(n);
    start_.assign(cells + 1, 0);
    for (std::size_t i = 1; i < n; ++i) {
      const Real* p = w.bodies[i].p;
      cell_of_[i] = index(cell_coord(p[0], 0), cell_coord(p[1], 1), cell_coord(p[2], 2));
      ++start_[cell_of_[i] + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    sorted_.resize(n);
    fill_ = start_;
    for (std::size_t i = 1; i < n; ++i) sorted_[fill_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
  }

  void test_pair(const World& w, std::uint32_t i, std::uint32_t j) {
    const Real* pi = w.bodies[i].p;
    const Real* pj = w.bodies[j].p;
    const double dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
    const double r = w.radius[i] + w.radius[j];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < r * r && d2 > 0) pairs_.push_back({i, j, std::min(pi[2], pj[2])});
  }

  [[nodiscard]] int cell_coord(double x, int axis) const {
    return std::min(dims_[axis] - 1, static_cast<int>((x - lo_[axis]) / cell_));
  }
  [[nodiscard]] std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
  }

  double lo_[3] = {}, hi_[3] = {}, cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::size_t> cell_of_;
  std::vector<std::uint32_t> start_, fill_, sorted_;
  std::vector<Pair> pairs_;
};

// ---------------------------------------------------------------------------
// Energy, position correction, the picture.
// ---------------------------------------------------------------------------
struct Energy {
  double kinetic = 0, rotational = 0, potential = 0;
  [[nodiscard]] double total() const { return kinetic + rotational + potential; }
};

Energy energy(const World& w) {
  Energy e;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const Body& b = w.bodies[i];
    const double v2 = double(b.v[0]) * b.v[0] + double(b.v[1]) * b.v[1] + double(b.v[2]) * b.v[2];
    const double w2 = double(b.w[0]) * b.w[0] + double(b.w[1]) * b.w[1] + double(b.w[2]) * b.w[2];
    e.kinetic += 0.5 * w.mass[i] * v2;
    if (b.inv_inertia > 0) e.rotational += 0.5 * w.inertia[i] * w2;
    e.potential += w.mass[i] * kGravity * b.p[2];
  }
  return e;
}

/// Pushes overlapping bodies apart by part of their overlap beyond a slop,
/// in proportion to inverse mass (the ground does not move). Returns the
/// potential energy this added by lifting bodies [J], so that the energy
/// check can tell it from energy the contacts would have created.
double correct_positions(World& w, const Contacts& c) {
  constexpr double kSlop = 0.002;    // [m] overlap left alone, so resting contacts persist
  constexpr double kFraction = 0.4;  // of the excess removed per step
  double lifted = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double excess = c.depth[k] - kSlop;
    if (excess <= 0) continue;
    Body& a = w.bodies[c.a[k]];
    Body& b = w.bodies[c.b[k]];
    const double wa = a.inv_mass, wb = b.inv_mass;
    const double s = kFraction * excess / (wa + wb);
    a.p[0] += static_cast<Real>(s * wa * c.nx[k]);
    a.p[1] += static_cast<Real>(s * wa * c.ny[k]);
    a.p[2] += static_cast<Real>(s * wa * c.nz[k]);
    b.p[0] -= static_cast<Real>(s * wb * c.nx[k]);
    b.p[1] -= static_cast<Real>(s * wb * c.ny[k]);
    b.p[2] -= static_cast<Real>(s * wb * c.nz[k]);
    // m g dz for both sides; m * (s * w) = s for a movable body.
    lifted += kGravity * s * c.nz[k] * ((wa > 0 ? 1 : 0) - (wb > 0 ? 1 : 0));
  }
  return lifted;
}

struct StepRecord {
  double t;
  Energy e;
  std::size_t contacts, ground, resolved;
};

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

/// What a run leaves for the comparison of the orders and for --check.
struct RunSummary {
  collide::Order order = collide::Order::input;
  double e0 = 0, e_end = 0, max_total = 0, lifted = 0, max_excess = 0;
  std::size_t max_contacts = 0, max_resolved = 0, final_contacts = 0;
  double final_max_depth = 0, final_mean_depth = 0;  // [m] the resting pile's overlaps after the last step
  double solve_seconds = 0, wall = 0;
  std::size_t solved_contacts = 0;
  collide::SolveStats stats;
};

/// The whole simulation in one solve order, from the same initial world.
RunSummary simulate(const Options& o, collide::Order order, const std::string& png) {
  World world = make_world(o);
  Contacts contacts;
  UniformGrid grid;
  collide::Schedule schedule(order);  // rebuilt every step; keeps its buffers
  collide::SolverOptions solver_options;
  solver_options.threads = o.threads;
  solver_options.order = order;
  solver_options.passes = o.passes;              // the passes of a step share its schedule
  const collide::Solver solver(solver_options);  // one thread pool for the whole run

  RunSummary r;
  r.order = order;
  const Energy e0 = energy(world);
  r.e0 = e0.total();
  r.max_total = r.e0;
  std::printf("\n%s order: %d spheres + %d particles on a ground, dt = %g s, e = %g, mu = %g, %d passes\n",
              collide::to_string(order), o.spheres, o.particles, o.dt, o.restitution, o.friction, o.passes);
  std::printf("%5s %6s %10s %10s %10s %7s %7s %7s %8s %7s %9s %7s %7s\n", "step", "t[s]", "E_kin[J]", "E_pot[J]",
              "E_tot[J]", "contact", "ground", "pairs", "resolved", "batches", "conflicts", "pen[mm]", "ms");

  std::vector<StepRecord> history;
  const auto t_start = std::chrono::steady_clock::now();
  for (int step = 1; step <= o.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    const Real dv = static_cast<Real>(kGravity * o.dt);
    for (std::size_t i = 1; i < world.size(); ++i) world.bodies[i].v[2] -= dv;

    grid.find_contacts(world, o.friction, contacts);
    const collide::ContactView<Real> view = contacts.view(o.restitution);
    const collide::ImpulseView<Real> impulses = contacts.impulses();
    const collide::PackedView<Body> bodies = world.view();

    // collide: one schedule for this step's contacts, several passes over
    // it in one solve, each writing v and w into the records in place.
    const auto s0 = std::chrono::steady_clock::now();
    schedule.build(view, bodies);  // inverse masses read from the records
    r.stats = solver.solve(bodies, view, impulses, schedule);
    r.solve_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    r.solved_contacts += contacts.size() * static_cast<std::size_t>(o.passes);
    // J sums the passes: the contacts that got an impulse in some pass.
    std::size_t resolved = 0;
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      resolved += contacts.jx[k] != 0 || contacts.jy[k] != 0 || contacts.jz[k] != 0 ? 1 : 0;
    }

    double max_depth = 0, sum_depth = 0;
    for (const Real d : contacts.depth) {
      max_depth = std::max<double>(max_depth, d);
      sum_depth += d;
    }
    r.final_max_depth = max_depth;
    r.final_mean_depth = contacts.size() > 0 ? sum_depth / static_cast<double>(contacts.size()) : 0;
    r.lifted += correct_positions(world, contacts);
    const Real dt = static_cast<Real>(o.dt);
    for (std::size_t i = 1; i < world.size(); ++i) {
      Body& b = world.bodies[i];
      b.p[0] += b.v[0] * dt;
      b.p[1] += b.v[1] * dt;
      b.p[2] += b.v[2] * dt;
    }

    const Energy e = energy(world);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    history.push_back({step * o.dt, e, contacts.size(), contacts.ground, resolved});
    r.max_total = std::max(r.max_total, e.total());
    r.max_excess = std::max(r.max_excess, e.total() - r.lifted - r.e0);
    r.max_contacts = std::max(r.max_contacts, contacts.size());
    r.max_resolved = std::max(r.max_resolved, resolved);
    r.final_contacts = contacts.size();
    if (step % o.every == 0 || step == o.steps) {
      std::printf("%5d %6.3f %10.3f %10.3f %10.3f %7zu %7zu %7zu %8zu %7zu %9zu %7.2f %7.2f\n", step, step * o.dt,
                  e.kinetic + e.rotational, e.potential, e.total(), contacts.size(), contacts.ground,
                  contacts.size() - contacts.ground, resolved, r.stats.batches, schedule.conflicts(), 1000 * max_depth,
                  ms);
    }
  }
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  r.e_end = energy(world).total();
  std::printf(
      "done: %d steps in %.2f s; up to %zu contacts per step, up to %zu resolved (J != 0); "
      "collide: %.1f M contact-solves/s (model %s, %zu lanes, %d threads, %zu colours)\n",
      o.steps, r.wall, r.max_contacts, r.max_resolved, r.solved_contacts / std::max(r.solve_seconds, 1e-9) / 1e6,
      collide::to_string(r.stats.model), r.stats.lanes, r.stats.threads, r.stats.colours);
  std::printf("energy: start %.3f J, end %.3f J, highest %.3f J; position correction lifted %.3f J\n", r.e0, r.e_end,
              r.max_total, r.lifted);
  if (!png.empty()) {
    if (!write_png(png, history, world)) {
      std::fprintf(stderr, "could not write %s with gnuplot (scripts/install-deps.sh installs gnuplot-nox)\n",
                   png.c_str());
      std::exit(1);
    }
    std::printf("wrote %s\n", png.c_str());
  }
  return r;
}

/// FILE.png -> FILE-colour.png.
std::string colour_png(const std::string& path) {
  const std::size_t dot = path.rfind('.');
  return dot == std::string::npos ? path + "-colour" : path.substr(0, dot) + "-colour" + path.substr(dot);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    usage(argv[0]);
    return 2;
  }
  std::vector<RunSummary> runs;
  if (o.order != "colour") runs.push_back(simulate(o, collide::Order::input, o.out));
  if (o.order != "input") {
    runs.push_back(
        simulate(o, collide::Order::colour, o.order == "both" && !o.out.empty() ? colour_png(o.out) : o.out));
  }

  std::printf("\n%-7s %14s %14s %13s %13s %12s %12s\n", "order", "E_end[J]", "E_highest[J]", "pen_max[mm]",
              "pen_mean[mm]", "contacts", "M solves/s");
  for (const RunSummary& r : runs) {
    std::printf("%-7s %14.3f %14.3f %13.3f %13.3f %12zu %12.1f\n", collide::to_string(r.order), r.e_end, r.max_total,
                1000 * r.final_max_depth, 1000 * r.final_mean_depth, r.final_contacts,
                r.solved_contacts / std::max(r.solve_seconds, 1e-9) / 1e6);
  }

  if (o.check) {
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
    if (!ok) return 1;
    std::puts("check: ok");
  }
  return 0;
}
