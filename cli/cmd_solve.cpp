// cli/cmd_solve.cpp - `collide solve`: read a scene, resolve it, write results.
//
// Design notes
// ------------
// * All input is read and validated before any output file is opened, and
//   regular outputs are written to temporaries that are renamed only when
//   both are complete: bad input, or any failure, writes nothing and leaves
//   pre-existing outputs untouched. An output that is stdout ("-"), a device
//   or a FIFO is written in place (collide/io/output_file.hpp), after the
//   temporaries and before their rename.
// * The library checks what keeps a solve inside the arrays (Schedule::build
//   every index, Solver::solve the counts) and throws std::invalid_argument
//   otherwise. The reader's rules are stricter, so that cannot happen on a
//   scene it accepted; if it did, the exception reaches main(), which prints
//   "collide: <message>" and exits 1, and since no output is opened before
//   the solve returns, nothing is written.
// * kernel_seconds times Solver::solve alone (steady_clock), one first solve
//   in a fresh process, with no warm-up (docs/report.md, "Timing"), less the
//   ISA measurement that the first solve of a process runs with --isa auto
//   (isa_calibration_seconds) and less the solver's allocate phase (allocate_seconds: the fresh Solver's
//   buffers grown and their pages touched before its kernels run), both
//   reported apart by solve_record; reading, scheduling and writing are timed
//   separately, and io_seconds (read + write) with io_fraction (its share of
//   read + schedule + solve + write, the solve's allocate phase included)
//   say how much of a run is file I/O: for large CSV scenes nearly all of it
//   (docs/decisions/0011-csv-scene-files.md).
// * --check runs reference_solve<long double> on an exact copy of the inputs
//   taken before the solve (convert_* copy without renormalising), in the
//   solve's sequence (its schedule's order, --passes times, from the same
//   --warm-start), and
//   measures each impulse error in units of eps(T) * impulse_scale, the
//   quantity kImpulseErrorBoundEps bounds (error_bound.hpp).
// * --threads N also caps the tbb threads of parsing and writing, so
//   "--threads 1" means one thread everywhere.
// * Each scene file is CSV or binary (.npz) by its name, or all of them as
//   --format says (collide/io/scene_npz.hpp). A binary input is mapped and its
//   columns used in place; without --precision a binary scene is solved in
//   its own precision (converting it would cost what mapping saves), a CSV
//   one in double, and binary bodies and contacts files of different
//   precisions are a usage error that asks for --precision (neither file's
//   precision is more the scene's than the other's).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "collide/eval/check.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/io/scene_io.hpp"
#include "collide/io/scene_npz.hpp"
#include "collide/model.hpp"
#include "collide/schedule.hpp"
#include "collide/solve.hpp"
#include "collide/validate.hpp"
#include "commands.hpp"

namespace collide::cli {

const char* const kSolveUsage =
    "usage: collide solve --bodies B.csv --contacts C.csv --out-bodies OB.csv --out-impulses OJ.csv\n"
    "                     [--format csv|npz] [--precision float|double] [--threads N]\n"
    "                     [--path simd|scalar]\n"
    "                     [--isa auto|sse2|avx2|avx512] [--layout auto|soa|packed]\n"
    "                     [--accuracy fast|accurate] [--order input|colour] [--passes N]\n"
    "                     [--iteration repeat|accumulate] [--warm-start IMPULSES]\n"
    "                     [--model rigid|sphere|particle|auto] [--stats] [--check]\n"
    "\n"
    "Resolves every contact of the scene by the collision law and writes the bodies\n"
    "with their new v and w (all other columns unchanged) and the impulse J on body\n"
    "a of each contact (header jx,jy,jz), in input order.\n"
    "\n"
    "  --bodies FILE         bodies.csv: m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
    "  --contacts FILE       contacts.csv: a,b,cx,cy,cz,nx,ny,nz,e,mu\n"
    "  --out-bodies FILE     result bodies file: a regular file is replaced\n"
    "                        atomically (its directory created if missing); '-'\n"
    "                        (stdout), a device such as /dev/null or a FIFO is\n"
    "                        written in place\n"
    "  --out-impulses FILE   result impulses file, likewise (only one output may be '-')\n"
    "  --format F            csv or npz for all four files above, the inputs too\n"
    "                        (default: each file by its name: npz, the binary scene\n"
    "                        format, for a name ending in .npz, else csv; so CSV\n"
    "                        inputs and binary outputs need only the .npz names)\n"
    "  --precision P         float or double (default: a binary bodies file's own,\n"
    "                        else double; binary bodies and contacts files of\n"
    "                        different precisions need it)\n"
    "  --threads N           worker threads, 0 = all hardware threads (default 0);\n"
    "                        results do not depend on it\n"
    "  --path P              simd (default) or scalar; results do not depend on it\n"
    "  --layout L            body layout the kernel runs on: auto (default: packed when\n"
    "                        the contacts reach bodies at random), soa or packed;\n"
    "                        results do not depend on it\n"
    "  --isa I               instruction set of the simd path: auto (default: $COLLIDE_ISA,\n"
    "                        else the fastest on this CPU, measured at the first solve\n"
    "                        of each kind), sse2, avx2 or avx512; results do not\n"
    "                        depend on it; --stats says which ran and how it was chosen\n"
    "  --accuracy A          fast (default: plain arithmetic, within a few eps of the\n"
    "                        impulse scale) or accurate (J within a few ulps of the\n"
    "                        exact law, slower); both are deterministic\n"
    "  --order O             the order contacts that share a movable body are applied\n"
    "                        in: input (default: the law in input order) or colour\n"
    "                        (windows of contacts coloured over their bodies and solved\n"
    "                        colour by colour: several times faster on piles, stacks\n"
    "                        and chains; docs/collision-law.md, 'The solve order')\n"
    "  --passes N            resolve the contacts N times in that order (default 1)\n"
    "  --iteration I         what the passes after the first do: repeat (default: the\n"
    "                        law again, J the sum over the passes) or accumulate\n"
    "                        (each contact's total impulse moved towards rest and\n"
    "                        clamped, restitution once, J the totals: converges as\n"
    "                        physics engines' passes do; fast accuracy only)\n"
    "  --warm-start FILE     start the accumulated passes from the impulses in FILE\n"
    "                        (CSV or .npz by its name, as --out-impulses writes it:\n"
    "                        the previous frame's J of the same contacts, one row\n"
    "                        each); needs --iteration accumulate\n"
    "  --model M             body model of the kernel: auto (default) for the cheapest\n"
    "                        that fits the scene, or rigid, sphere or particle (an\n"
    "                        error when the scene does not fit); results are the law's\n"
    "  --stats               print one JSON object of statistics on stderr (kernel,\n"
    "                        allocate, schedule, read and write times; io_fraction\n"
    "                        is the share of file I/O, nearly all of a large\n"
    "                        scene's time; isa and isa_choice: forced, environment\n"
    "                        or measured)\n"
    "  --check               also run the long double reference and compare the\n"
    "                        impulses; exit 3 if an error exceeds the documented bound\n"
    "\n"
    "Bad input is reported as 'collide: FILE:LINE: row R, column 'C': what' with\n"
    "exit code 1, and no output is written.\n";

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct SolveRequest {
  std::string bodies_path, contacts_path, out_bodies_path, out_impulses_path;
  SceneFormat bodies_format = SceneFormat::csv, contacts_format = SceneFormat::csv;
  SceneFormat out_bodies_format = SceneFormat::csv, out_impulses_format = SceneFormat::csv;
  bool want_float = false;
  int threads = 0;
  Path path = Path::simd;
  Isa isa = Isa::automatic;  // checked in run_solve; automatic: COLLIDE_ISA, else measured by the Solver
  BodyLayout layout = BodyLayout::automatic;
  Accuracy accuracy = Accuracy::fast;
  Order order = Order::input;
  int passes = 1;
  Iteration iteration = Iteration::repeat;
  std::string warm_start_path;  // empty: no warm start
  bool auto_model = true;
  Model model = Model::rigid;
  bool stats = false;
  bool check = false;
};

template <class T>
int solve_scene(const SolveRequest& req) {
  const auto t_read = Clock::now();
  // The bodies' rules are checked in the pass that fills the solve's arrays
  // (one read of the file), before the contacts file is read.
  const LoadedBodies<T> table = load_bodies<T>(req.bodies_path, req.bodies_format, BodyRules::by_caller);
  SolveBodies<T> bodies(table);
  const LoadedContacts<T> contacts = load_contacts<T>(req.contacts_path, req.contacts_format, table.size());
  // The warm start is the solve's impulse arrays on entry.
  ImpulseBuffer<T> impulses(contacts.size());
  if (!req.warm_start_path.empty()) {
    impulses = load_impulses<T>(req.warm_start_path, scene_format_of(req.warm_start_path));
    if (impulses.size() != contacts.size()) {
      throw std::runtime_error(req.warm_start_path + ": --warm-start holds " + std::to_string(impulses.size()) +
                               " impulses but " + req.contacts_path + " holds " + std::to_string(contacts.size()) +
                               " contacts: a warm start gives one J per contact, in the same order");
    }
    // The solver refuses the same J; named here by the file's terms.
    const ImpulseView<const T> warm = std::as_const(impulses).view();
    if (const std::size_t k = first_refused_warm_start(contacts.view(), warm); k < contacts.size()) {
      std::ostringstream j;
      j << std::setprecision(std::numeric_limits<T>::max_digits10) << warm.j.x[k] << ", " << warm.j.y[k] << ", "
        << warm.j.z[k];
      throw std::runtime_error(req.warm_start_path + ": the J of contact " + std::to_string(k) + " (" + j.str() + ") " +
                               warm_start_refusal(contacts.view(), warm, k));
    }
  }
  const double read_seconds = seconds_since(t_read);

  // The reference must see the inputs the kernel sees: copy before solving.
  BodyBuffer<long double> ref_bodies;
  ContactBuffer<long double> ref_contacts;
  ImpulseBuffer<long double> ref_impulses;
  if (req.check) {
    ref_bodies = convert_bodies<long double>(std::as_const(bodies).view());
    ref_contacts = convert_contacts<long double>(contacts.view());
    ref_impulses.resize(contacts.size());
    if (!req.warm_start_path.empty()) {
      const ImpulseView<long double> to = ref_impulses.view();
      const ImpulseView<const T> from = std::as_const(impulses).view();
      for (std::size_t k = 0; k < contacts.size(); ++k) {
        to.j.x[k] = from.j.x[k];
        to.j.y[k] = from.j.y[k];
        to.j.z[k] = from.j.z[k];
      }
    }
  }

  // A smaller model computes the law only for scenes that fit it.
  Model model = req.model;
  if (req.auto_model) {
    model = choose_model(bodies.view(), contacts.view());
  } else if (const std::string misfit = model_misfit(model, bodies.view(), contacts.view()); !misfit.empty()) {
    throw std::runtime_error(std::string("--model ") + to_string(model) + " does not fit the scene: " + misfit);
  }

  const auto t_schedule = Clock::now();
  Schedule schedule(req.order);
  schedule.build(contacts.view(), bodies.view());
  const double schedule_seconds = seconds_since(t_schedule);

  SolverOptions options;
  options.path = req.path;
  options.threads = req.threads;
  options.isa = req.isa;
  options.layout = req.layout;
  options.accuracy = req.accuracy;
  options.passes = req.passes;
  options.iteration = req.iteration;
  options.warm_start = !req.warm_start_path.empty();
  const Solver solver(options);
  const auto t_kernel = Clock::now();
  const SolveStats stats = solver.solve(model, bodies.view(), contacts.view(), impulses.view(), schedule);
  const double kernel_seconds = seconds_since(t_kernel);

  ImpulseCheck check;
  double check_seconds = 0;
  if (req.check) {
    const auto t_check = Clock::now();
    std::vector<ReferenceContact<long double>> diag(contacts.size());
    // In the solve's own sequence: its schedule's order, pass after pass,
    // from the same warm start.
    reference_solve<long double>(
        ref_bodies.view(), ref_contacts.view(), ref_impulses.view(), diag.data(),
        SolveSequence{schedule.solve_order(), static_cast<std::size_t>(req.passes), req.iteration, options.warm_start});
    check = check_impulses<T>(std::as_const(impulses).view(), std::as_const(ref_impulses).view(), diag);
    check_seconds = seconds_since(t_check);
  }

  const auto t_write = Clock::now();
  {
    OutputFile out_bodies(req.out_bodies_path);
    OutputFile out_impulses(req.out_impulses_path);
    const auto write = [&](OutputFile& out) {
      if (&out == &out_bodies) {
        if (req.out_bodies_format == SceneFormat::npz) {
          write_bodies_npz(out_bodies, table.columns(), std::as_const(bodies).view());
        } else {
          write_bodies(out_bodies, table.columns(), std::as_const(bodies).view());
        }
      } else if (req.out_impulses_format == SceneFormat::npz) {
        write_impulses_npz(out_impulses, std::as_const(impulses).view());
      } else {
        write_impulses(out_impulses, std::as_const(impulses).view());
      }
    };
    // A direct output (stdout, device, FIFO) cannot be taken back: write it
    // after the temporaries, and flush it before they are renamed, so that a
    // failure anywhere still leaves every regular destination untouched.
    const bool bodies_first = !out_bodies.direct() || out_impulses.direct();
    OutputFile& first = bodies_first ? out_bodies : out_impulses;
    OutputFile& second = bodies_first ? out_impulses : out_bodies;
    write(first);
    write(second);
    second.commit();
    first.commit();
  }
  const double write_seconds = seconds_since(t_write);

  if (req.stats) {
    StatRecord record =
        solve_record<T>(stats, std::as_const(impulses).view(), table.size(), kernel_seconds, schedule_seconds);
    record.emplace_back("read_seconds", read_seconds);
    record.emplace_back("write_seconds", write_seconds);
    // File I/O against everything solve does: for large scenes the CSV text,
    // not the kernel, is where the time goes (docs/decisions/0011-csv-scene-files.md).
    const double io_seconds = read_seconds + write_seconds;
    record.emplace_back("io_seconds", io_seconds);
    // Against the solve's time without the ISA calibration, which is
    // reported apart (solve_record): the allocate phase is the solve's work.
    const double solve_seconds = schedule_seconds + std::max(0.0, kernel_seconds - stats.isa_calibration_seconds);
    record.emplace_back("io_fraction", io_seconds / (io_seconds + solve_seconds));
    if (req.check) add_check(record, check, check_seconds);
    std::fputs((to_json(record) + "\n").c_str(), stderr);
  }
  if (!check.passed) {
    std::fprintf(stderr,
                 "collide: check failed: impulse error %.6g eps * impulse_scale at contact %zu exceeds the "
                 "documented bound of %g\n",
                 check.max_error_eps, check.worst_contact, kImpulseErrorBoundEps);
    return kExitCheckFailed;
  }
  return kExitOk;
}

/// Whether `path` is a regular file whose first line is the header of a
/// bodies or contacts CSV file (what `--format npz` on CSV inputs reads).
/// Devices and FIFOs are not read: their bytes would be gone.
bool starts_with_a_csv_header(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream file(path, std::ios::binary);
  std::string first;
  if (!std::getline(file, first)) return false;
  if (!first.empty() && first.back() == '\r') first.pop_back();
  first += '\n';
  return first == bodies_header() || first == contacts_header();
}

}  // namespace

int run_solve(int argc, char** argv) {
  const Options opt = parse_options(argc, argv, 2,
                                    {{"bodies", true},
                                     {"contacts", true},
                                     {"out-bodies", true},
                                     {"out-impulses", true},
                                     {"precision", true},
                                     {"threads", true},
                                     {"path", true},
                                     {"isa", true},
                                     {"layout", true},
                                     {"accuracy", true},
                                     {"order", true},
                                     {"passes", true},
                                     {"iteration", true},
                                     {"warm-start", true},
                                     {"model", true},
                                     {"stats", false},
                                     {"check", false},
                                     {"format", true}});
  if (opt.count("help") != 0) {
    std::fputs(kSolveUsage, stdout);
    return kExitOk;
  }
  SolveRequest req;
  req.bodies_path = required(opt, "bodies");
  req.contacts_path = required(opt, "contacts");
  req.out_bodies_path = required(opt, "out-bodies");
  req.out_impulses_path = required(opt, "out-impulses");
  {
    // Compared as resolved paths, so "./x.csv" and "x.csv" count as the same.
    std::error_code ec1, ec2;
    const auto a = std::filesystem::weakly_canonical(req.out_bodies_path, ec1);
    const auto b = std::filesystem::weakly_canonical(req.out_impulses_path, ec2);
    if (req.out_bodies_path == kStdoutPath && req.out_impulses_path == kStdoutPath) {
      throw UsageError("only one of --out-bodies and --out-impulses can be '-' (stdout)");
    }
    // One character device (/dev/null) may take both: nothing is replaced.
    const bool same = req.out_bodies_path == req.out_impulses_path || (!ec1 && !ec2 && a == b);
    if (same && !std::filesystem::is_character_file(req.out_bodies_path, ec1)) {
      throw UsageError("--out-bodies and --out-impulses must be different files");
    }
  }
  if (const auto it = opt.find("format"); it != opt.end()) {
    try {
      const SceneFormat f = parse_scene_format(it->second);
      req.bodies_format = req.contacts_format = req.out_bodies_format = req.out_impulses_format = f;
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--format: ") + e.what());
    }
    for (const std::string* input : {&req.bodies_path, &req.contacts_path}) {
      if (req.bodies_format == SceneFormat::npz && starts_with_a_csv_header(*input)) {
        throw UsageError("--format npz applies to the inputs too, and " + *input +
                         " is CSV: drop --format and name the outputs .npz (each file's format then comes from its "
                         "name)");
      }
    }
  } else {
    req.bodies_format = scene_format_of(req.bodies_path);
    req.contacts_format = scene_format_of(req.contacts_path);
    req.out_bodies_format = scene_format_of(req.out_bodies_path);
    req.out_impulses_format = scene_format_of(req.out_impulses_path);
  }
  if (const std::optional<Precision> precision = parse_precision(opt)) {
    req.want_float = *precision == Precision::single;
  } else if (req.bodies_format == SceneFormat::npz) {
    // A binary scene runs in its own precision; a bad file is reported (exit
    // 1) when it is read. Binary bodies and contacts of different precisions
    // leave the choice to the caller: neither silently wins.
    std::optional<NpyType> bodies, contacts;
    try {
      bodies = npz_scene_precision(NpzArchive::map(req.bodies_path));
      if (req.contacts_format == SceneFormat::npz) contacts = npz_scene_precision(NpzArchive::map(req.contacts_path));
    } catch (const SceneError&) {
    }
    if (bodies && contacts && *bodies != *contacts) {
      const auto name = [](NpyType t) { return t == NpyType::f4 ? "float32 (float)" : "float64 (double)"; };
      throw UsageError(req.bodies_path + " holds " + name(*bodies) + " values but " + req.contacts_path + " " +
                       name(*contacts) +
                       ": say which precision to solve the scene in with --precision float or "
                       "--precision double");
    }
    req.want_float = bodies == NpyType::f4;
  }
  req.threads = parse_threads(opt);
  if (const auto it = opt.find("path"); it != opt.end()) {
    if (it->second != "simd" && it->second != "scalar") {
      throw UsageError("--path must be simd or scalar, got '" + it->second + "'");
    }
    req.path = it->second == "simd" ? Path::simd : Path::scalar;
  }
  {
    // Checked before anything is read: an unknown name, or an ISA this CPU
    // lacks (named by --isa or by COLLIDE_ISA), is a usage error. automatic
    // stays automatic: the Solver reads COLLIDE_ISA, or measures.
    const auto it = opt.find("isa");
    try {
      req.isa = it == opt.end() ? Isa::automatic : parse_isa(it->second);
      (void)resolve_isa(req.isa);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string(it == opt.end() ? "" : "--isa: ") + e.what());
    }
  }
  if (const auto it = opt.find("accuracy"); it != opt.end()) {
    try {
      req.accuracy = parse_accuracy(it->second);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--accuracy: ") + e.what());
    }
  }
  if (const auto it = opt.find("order"); it != opt.end()) {
    try {
      req.order = parse_order(it->second);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--order: ") + e.what());
    }
  }
  if (const auto it = opt.find("passes"); it != opt.end()) {
    req.passes = static_cast<int>(parse_integer("passes", it->second, 1, kMaxPasses));
  }
  if (const auto it = opt.find("iteration"); it != opt.end()) {
    try {
      req.iteration = parse_iteration(it->second);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--iteration: ") + e.what());
    }
    if (req.iteration == Iteration::accumulate && req.accuracy == Accuracy::accurate) {
      throw UsageError("--iteration accumulate runs in the fast mode: it takes --accuracy fast");
    }
  }
  if (const auto it = opt.find("warm-start"); it != opt.end()) {
    if (req.iteration != Iteration::accumulate) {
      throw UsageError(
          "--warm-start needs --iteration accumulate (the repeat mode's passes add impulses and "
          "cannot start from a J)");
    }
    req.warm_start_path = it->second;
  }
  if (const auto it = opt.find("layout"); it != opt.end()) {
    if (it->second == "auto") {
      req.layout = BodyLayout::automatic;
    } else if (it->second == "soa") {
      req.layout = BodyLayout::soa;
    } else if (it->second == "packed") {
      req.layout = BodyLayout::packed;
    } else {
      throw UsageError("--layout must be auto, soa or packed, got '" + it->second + "'");
    }
  }
  if (const auto it = opt.find("model"); it != opt.end()) {
    const std::string& m = it->second;
    if (m == "auto") {
      req.auto_model = true;
    } else if (m == "rigid" || m == "sphere" || m == "particle") {
      req.auto_model = false;
      req.model = m == "rigid" ? Model::rigid : m == "sphere" ? Model::sphere : Model::particle;
    } else {
      throw UsageError("--model must be rigid, sphere, particle or auto, got '" + m + "'");
    }
  }
  req.stats = opt.count("stats") != 0;
  req.check = opt.count("check") != 0;

  const ThreadLimit limit(req.threads);
  return req.want_float ? solve_scene<float>(req) : solve_scene<double>(req);
}

}  // namespace collide::cli
