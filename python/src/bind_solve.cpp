// python/src/bind_solve.cpp - collide.Solver, collide.Schedule, the
// reference solve and the error measure, and the instruction-set queries.
//
// Design notes
// ------------
// * Everything is checked before anything is written: layouts (by the
//   Bodies/Contacts/PackedBodies constructors and impulse_array), values
//   (the library's validate(), or only the indices when check=False), the
//   model and the schedule's size. The library's std::invalid_argument
//   (Schedule::build, Solver::solve, parse_isa, parse_accuracy) arrives as
//   ValueError with the library's message (module.cpp).
// * check=False skips validate() and the model-fit check for frame loops
//   that validated their scene once; the indices are still checked, so no
//   index outside the arrays ever reaches the kernel: by Schedule::build when
//   the solve builds its schedule, by validate_indices() beside a schedule
//   the caller built earlier.
// * One generic solve for both kinds of bodies (Bodies, PackedBodies): the
//   steps that differ are overloads (scene.hpp, packed_bodies.hpp).
// * The GIL is released around every long C++ call (schedule, solve,
//   reference). The ndarrays stay referenced by the Bodies and Contacts
//   objects (and the call's arguments) meanwhile.
// * The statistics dict is collide::solve_record (collide/eval/check.hpp),
//   the record `collide solve --stats` prints (kernel_seconds is the wall
//   time of the solve call below less the solve's ISA measurement and its
//   allocate phase, which have keys of their own), the error per contact is
//   collide::impulse_errors_eps, what `--check` summarises, and the
//   conservation drifts are collide::conservation_drift, the report's.
// * Ctrl-C stops a solve of several passes after the pass in progress
//   (interrupt.hpp): each Solver has a stop flag (SolverOptions::stop) that
//   a SIGINT sets while the main thread solves; a solve that ran fewer
//   passes than asked raises KeyboardInterrupt, v, w and `out` as the passes
//   done left them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <oneapi/tbb/global_control.h>

#include "bindings.hpp"
#include "collide/eval/check.hpp"
#include "collide/eval/conservation.hpp"
#include "collide/eval/error_bound.hpp"
#include "collide/eval/reference.hpp"
#include "collide/io/scene.hpp"
#include "collide/isa.hpp"
#include "collide/validate.hpp"
#include "interrupt.hpp"
#include "packed_bodies.hpp"
#include "scene.hpp"

namespace collide::python {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

Path parse_path(const std::string& s) {
  if (s == "simd") return Path::simd;
  if (s == "scalar") return Path::scalar;
  throw py::value_error("path must be 'simd' or 'scalar', got '" + s + "'");
}

/// passes= of a solve or a reference solve: the range of `collide solve --passes`.
int passes_argument(const py::object& passes) {
  return static_cast<int>(integer_argument(passes, "passes", 1, kMaxPasses));
}

SolverOptions solver_options(const std::string& path, const py::object& threads, const py::object& isa,
                             const std::string& accuracy, const py::object& passes, const std::string& iteration,
                             bool warm_start) {
  SolverOptions o;
  o.passes = passes_argument(passes);
  o.iteration = parse_iteration(iteration);
  o.path = parse_path(path);
  o.threads = static_cast<int>(integer_argument(threads, "threads", 0, kMaxThreads));
  std::optional<std::string> isa_name;
  try {
    if (!isa.is_none()) isa_name = isa.cast<std::string>();
  } catch (const py::cast_error&) {
    throw py::type_error("isa must be a string or None");
  }
  if (isa_name) o.isa = parse_isa(*isa_name);
  o.accuracy = parse_accuracy(accuracy);
  if (o.iteration == Iteration::accumulate && o.accuracy == Accuracy::accurate) {
    throw py::value_error("iteration='accumulate' runs in the fast mode: it takes accuracy='fast'");
  }
  if (warm_start && o.iteration != Iteration::accumulate) {
    throw py::value_error(
        "a warm start needs iteration='accumulate' (the repeat mode's passes add impulses and cannot start from a "
        "J)");
  }
  o.warm_start = warm_start;
  return o;
}

/// The impulse output: `out` when given (checked like an input), else a new array.
py::array impulse_array(const py::object& out, Dtype dtype, std::size_t m) {
  if (out.is_none()) return new_array(dtype, {3, static_cast<py::ssize_t>(m)});
  py::array j = checked_array("solve", "out", out, numpy_dtype(dtype), dtype_name(dtype), 3, true);
  require_length("solve", "out", j, m, "contacts.a");
  return j;
}

/// A schedule built for one set of contacts and bodies; reusable while the
/// indices and inverse masses do not change (a frame loop over velocities).
struct PySchedule {
  Schedule schedule;
  std::size_t contacts = 0, bodies = 0;
  double build_seconds = 0;

  explicit PySchedule(Order order = Order::input) : schedule(order) {}

  /// Schedule::build checks every index (std::invalid_argument naming the
  /// first bad one: a ValueError).
  template <class T, class B>
  void build(const B& b, const Contacts& c) {
    const ContactView<T> cv = c.view<T>();
    const auto t0 = Clock::now();
    {
      py::gil_scoped_release release;
      build_schedule<T>(schedule, cv, b);
    }
    build_seconds = seconds_since(t0);
    contacts = c.count;
    bodies = b.count;
  }

  /// A schedule over validated input (it reads the indices).
  template <class B>
  static std::unique_ptr<PySchedule> make(const B& bodies, const Contacts& contacts, const std::string& order) {
    require_same_dtype(bodies, contacts);
    auto s = std::make_unique<PySchedule>(parse_order(order));
    with_dtype(bodies.dtype, [&](auto tag) {
      using T = decltype(tag);
      validate_or_throw<T>(bodies, contacts);
      s->build<T>(bodies, contacts);
    });
    return s;
  }
};

/// order= of a solve or a reference solve: None, "input" or "colour".
std::optional<Order> order_argument(const py::object& order) {
  if (order.is_none()) return std::nullopt;
  if (!py::isinstance<py::str>(order)) throw py::type_error("order must be 'input', 'colour' or None");
  return parse_order(order.cast<std::string>());
}

/// The schedule owns the order (collide/schedule.hpp): a call takes the
/// order of a schedule it is given, or order= for the one it builds, not
/// both. `own` is built (in `order`, else the input order) when no schedule
/// is given; the schedule to run is returned.
template <class T, class B>
PySchedule* schedule_to_run(const char* what, const B& bodies, const Contacts& contacts, const py::object& order,
                            PySchedule* given, PySchedule& own) {
  const std::optional<Order> asked = order_argument(order);
  if (given == nullptr) {
    own = PySchedule(asked.value_or(Order::input));
    own.build<T>(bodies, contacts);
    return &own;
  }
  if (asked) {
    throw py::value_error(std::string(what) +
                          ": give order= or schedule=, not both: a schedule runs in the order it "
                          "was built in (this one: '" +
                          to_string(given->schedule.order()) + "')");
  }
  if (given->contacts != contacts.count || given->bodies != bodies.count) {
    throw py::value_error(std::string(what) + ": schedule was built for " + std::to_string(given->contacts) +
                          " contacts and " + std::to_string(given->bodies) + " bodies, not " +
                          std::to_string(contacts.count) + " and " + std::to_string(bodies.count));
  }
  return given;
}

py::dict to_dict(const StatRecord& record) {
  py::dict d;
  for (const auto& entry : record) {
    // Not a structured binding: clang 14 cannot capture one in the lambda.
    const std::string& key = entry.first;
    std::visit([&](const auto& x) { d[py::str(key)] = py::cast(x); }, entry.second);
  }
  return d;
}

struct PySolver {
  /// The solver's SolverOptions::stop, set by Ctrl-C (interrupt.hpp).
  std::unique_ptr<std::atomic<bool>> stop = std::make_unique<std::atomic<bool>>(false);
  std::unique_ptr<Solver> solver;

  PySolver(const std::string& path, const py::object& threads, const py::object& isa, const std::string& accuracy,
           const py::object& passes, const std::string& iteration, bool warm_start)
      : solver(std::make_unique<Solver>(
            stoppable(solver_options(path, threads, isa, accuracy, passes, iteration, warm_start)))) {}

  SolverOptions stoppable(SolverOptions o) const {
    o.stop = stop.get();
    return o;
  }

  template <class T, class B>
  py::tuple solve_t(const B& bodies, const Contacts& contacts, const std::string& model_name, const py::object& order,
                    PySchedule* schedule, const py::object& out, const py::object& warm, bool check, bool impacts) {
    const std::optional<Model> requested = parse_model(model_name);
    py::array j = impulse_array(out, bodies.dtype, contacts.count);
    const bool warm_start = solver->options().warm_start;
    if (warm.is_none() == warm_start) {
      throw py::value_error(warm_start ? "solve: this Solver was built with warm_start=True and takes warm=, the J to "
                                         "start from (zeros for a first frame)"
                                       : "solve: warm= needs a Solver built with warm_start=True (collide.solve "
                                         "builds one when it is given warm=)");
    }
    // The warm start is J on entry: `out` itself, or copied into it below.
    py::array w;
    if (warm_start) {
      w = checked_array("solve", "warm", warm, numpy_dtype(bodies.dtype), dtype_name(bodies.dtype), 3, false);
      require_length("solve", "warm", w, contacts.count, "contacts.a");
    }
    const bool warm_is_out = warm_start && w.ptr() == j.ptr();
    {
      // What the solve writes (v and w or the records, J) shares no memory
      // with what it reads or writes besides: checked with check=False too.
      std::vector<ArrayBytes> arrays;
      add_bytes(arrays, bodies);
      add_bytes(arrays, contacts);
      add_bytes(arrays, "solve", "out", j, true);
      if (warm_start && !warm_is_out) add_bytes(arrays, "solve", "warm", w, false);
      require_disjoint(arrays);
    }
    const ImpulseView<T> jv{contacts.count, vec3<T>(j)};  // rows one stride apart, as checked_array allows
    const ContactView<T> cv = contacts.view<T>();
    // Unchecked values are the caller's word; indices never are (memory
    // safety). A schedule built here checks every index in its own pass
    // (Schedule::build throws std::invalid_argument, a ValueError here); a
    // schedule built earlier vouches only for the indices it saw then, so
    // the indices are checked again beside it.
    if (check) {
      if (const Validation v = validate_values(bodies, cv, jv); !v) throw py::value_error(v.message);
    } else if (schedule != nullptr) {
      if (const Validation v = validate_indices(cv.a, cv.b, cv.count, bodies.count); !v) {
        throw py::value_error(v.message);
      }
    }
    // Before the model choice, which reads the bodies of every contact.
    PySchedule own;
    schedule = schedule_to_run<T>("solve", bodies, contacts, order, schedule, own);
    const Model model = solve_model<T>(bodies, cv, requested, check);
    if (warm_start) {
      if (!warm_is_out) j[py::ellipsis()] = w;
      if (check) {
        const ImpulseView<const T> wv{jv.count, {jv.j.x, jv.j.y, jv.j.z}};
        if (const std::size_t k = first_refused_warm_start(cv, wv); k < cv.count) {
          std::ostringstream value;
          value << std::setprecision(std::numeric_limits<T>::max_digits10) << "(" << wv.j.x[k] << ", " << wv.j.y[k]
                << ", " << wv.j.z[k] << ")";
          throw py::value_error("solve: warm[:, " + std::to_string(k) + "] = " + value.str() + " " +
                                warm_start_refusal(cv, wv, k));
        }
      }
    }
    SolveStats stats;
    double kernel_seconds = 0;
    {
      // One pass has nothing to stop between.
      std::optional<InterruptOnSigint> interruptible;
      if (solver->options().passes > 1) interruptible.emplace(*stop);
      {
        py::gil_scoped_release release;
        const auto t0 = Clock::now();
        stats = run_solve<T>(*solver, model, bodies, cv, jv, schedule->schedule);
        kernel_seconds = seconds_since(t0);
      }
    }
    const auto asked = static_cast<std::size_t>(solver->options().passes);
    if (stats.passes < asked) raise_interrupted(stats.passes, asked);
    // impacts=False: no pass over J (its cost beside a particle solve's:
    // docs/decisions/0013-python-call-overhead.md); the record is built over
    // no impulses and the key set to None.
    const ImpulseView<const T> jc{impacts ? jv.count : 0, {jv.j.x, jv.j.y, jv.j.z}};
    py::dict d =
        to_dict(solve_record<T>(stats, jc, bodies.count, kernel_seconds, schedule == &own ? own.build_seconds : 0.0));
    if (!impacts) d["impacts"] = py::none();
    return py::make_tuple(j, py::module_::import("collide").attr("Stats")(d));  // a dict, shown key by key
  }

  template <class B>
  py::tuple solve(const B& bodies, const Contacts& contacts, const std::string& model, const py::object& order,
                  PySchedule* schedule, const py::object& out, const py::object& warm, bool check, bool impacts) {
    require_same_dtype(bodies, contacts);
    return with_dtype(bodies.dtype, [&](auto tag) {
      return solve_t<decltype(tag)>(bodies, contacts, model, order, schedule, out, warm, check, impacts);
    });
  }
};

// ---------------------------------------------------------------------------
// The reference and the error measure.
// ---------------------------------------------------------------------------

/// reference_solve<long double> on an exact copy of the inputs: the caller's
/// bodies are not modified.
struct Reference {
  ImpulseBuffer<long double> impulses;
  std::vector<ReferenceContact<long double>> diagnostics;
  BodyBuffer<long double> after;
  /// The momenta and energy before the reference solve and after it
  /// (collide/eval/conservation.hpp), what conservation_drift compares with.
  MomentumTotals before_totals, after_totals;
  Dtype dtype = Dtype::f64;

  py::array j_array() const {
    const ImpulseView<const long double> j = impulses.view();
    return rows_as_double(j.j.x, j.j.y, j.j.z, j.count);
  }
  py::array vec_array(bool angular) const {
    const BodyView<const long double> b = after.view();
    const Vec3Array<const long double> x = angular ? b.w : b.v;
    return rows_as_double(x.x, x.y, x.z, b.count);
  }
  py::array impulse_scale() const {
    py::array_t<double> out(static_cast<py::ssize_t>(diagnostics.size()));
    double* o = out.mutable_data();
    for (std::size_t k = 0; k < diagnostics.size(); ++k) o[k] = static_cast<double>(diagnostics[k].impulse_scale);
    return out;
  }
  static py::array rows_as_double(const long double* x, const long double* y, const long double* z, std::size_t n) {
    py::array_t<double> out({py::ssize_t{3}, static_cast<py::ssize_t>(n)});
    double* o = out.mutable_data();
    for (std::size_t k = 0; k < n; ++k) {
      o[k] = static_cast<double>(x[k]);
      o[n + k] = static_cast<double>(y[k]);
      o[2 * n + k] = static_cast<double>(z[k]);
    }
    return out;
  }
};

std::shared_ptr<Reference> reference_solve_py(const Bodies& bodies, const Contacts& contacts, const py::object& order,
                                              const py::object& passes_in, const std::string& iteration_name,
                                              PySchedule* given, const py::object& warm) {
  require_same_dtype(bodies, contacts);
  const int passes = passes_argument(passes_in);
  const Iteration iteration = parse_iteration(iteration_name);
  return with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    validate_or_throw<T>(bodies, contacts);
    // The solve's sequence: the given schedule's order, or the one a solve
    // in `order` builds (a schedule depends on the input alone).
    PySchedule own;
    const PySchedule* schedule = schedule_to_run<T>("reference_solve", bodies, contacts, order, given, own);
    const bool warm_start = !warm.is_none();
    if (warm_start && iteration != Iteration::accumulate) {
      throw py::value_error(
          "reference_solve: a warm start needs iteration='accumulate' (the repeat mode's passes add impulses and "
          "cannot start from a J)");
    }
    py::array w;
    if (warm_start) {
      w = checked_array("reference_solve", "warm", warm, numpy_dtype(bodies.dtype), dtype_name(bodies.dtype), 3, false);
      require_length("reference_solve", "warm", w, contacts.count, "contacts.a");
    }
    const Vec3Array<T> wrows = warm_start ? vec3<T>(w) : Vec3Array<T>{};
    const SolveSequence sequence{schedule->schedule.solve_order(), static_cast<std::size_t>(passes), iteration,
                                 warm_start};
    auto r = std::make_shared<Reference>();
    r->dtype = bodies.dtype;
    const BodyView<T> bv = bodies.view<T>();
    const ContactView<T> cv = contacts.view<T>();
    py::gil_scoped_release release;
    r->after = convert_bodies<long double>(const_view(bv));
    const ContactBuffer<long double> lc = convert_contacts<long double>(cv);
    r->impulses.resize(contacts.count);
    if (warm_start) {
      const ImpulseView<long double> to = r->impulses.view();
      for (std::size_t k = 0; k < contacts.count; ++k) {
        to.j.x[k] = wrows.x[k];
        to.j.y[k] = wrows.y[k];
        to.j.z[k] = wrows.z[k];
      }
    }
    r->diagnostics.resize(contacts.count);
    r->before_totals = momentum_totals<long double>(std::as_const(r->after).view());
    reference_solve<long double>(r->after.view(), lc.view(), r->impulses.view(), r->diagnostics.data(), sequence);
    r->after_totals = momentum_totals<long double>(std::as_const(r->after).view());
    return r;
  });
}

py::array impulse_error_py(const py::object& j_in, const Reference& ref) {
  const Dtype dtype = scene_dtype("impulse_error.J", j_in);
  const py::array j = checked_array("impulse_error", "J", j_in, numpy_dtype(dtype), "float32 or float64", 3, false);
  require_length("impulse_error", "J", j, ref.impulses.size(), "the reference");
  return with_dtype(dtype, [&](auto tag) {
    using T = decltype(tag);
    const std::size_t m = length(j);
    const Vec3Array<T> rows = vec3<T>(j);
    const ImpulseView<const T> jv{m, {rows.x, rows.y, rows.z}};
    const std::vector<double> errors = impulse_errors_eps<T>(jv, ref.impulses.view(), ref.diagnostics);
    py::array_t<double> out(static_cast<py::ssize_t>(m));
    std::copy(errors.begin(), errors.end(), out.mutable_data());
    return out;
  });
}

/// The conservation drifts of bodies solved from the state the reference
/// started from (collide/eval/conservation.hpp; the report's columns).
py::dict conservation_drift_py(const Bodies& bodies, const Reference& ref) {
  if (bodies.count != ref.after.size()) {
    throw py::value_error("conservation_drift: the bodies are " + std::to_string(bodies.count) + ", the reference's " +
                          std::to_string(ref.after.size()));
  }
  const ConservationDrift drift = with_dtype(bodies.dtype, [&](auto tag) {
    using T = decltype(tag);
    const BodyView<T> bv = bodies.view<T>();
    py::gil_scoped_release release;
    return conservation_drift(ref.before_totals, ref.after_totals, momentum_totals<T>(const_view(bv)));
  });
  py::dict d;
  d["momentum_drift"] = drift.momentum;
  d["angular_momentum_drift"] = drift.angular_momentum;
  d["energy_drift"] = drift.energy;
  return d;
}

}  // namespace

/// At most `threads` threads in every parallel loop of the process while
/// held (a `with` block): generate, load, islands and the solvers alike
/// (tbb::global_control). For a process that is given a share of a
/// machine, such as a Dask worker of one thread, which would otherwise
/// compete with its neighbours for every core.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads) : threads_(threads) {
    if (threads < 1) throw py::value_error("ThreadLimit: threads must be >= 1, got " + std::to_string(threads));
  }
  void enter() { control_.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads_)); }
  void exit() { control_.reset(); }
  [[nodiscard]] int threads() const { return threads_; }

 private:
  int threads_;
  std::optional<tbb::global_control> control_;
};

void register_solve(py::module_& m) {
  prepare_interrupts();
  py::class_<PySchedule>(m, "Schedule")
      .def(py::init(&PySchedule::make<Bodies>), py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("order") = "input")
      .def(py::init(&PySchedule::make<PackedBodies>), py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("order") = "input")
      .def_property_readonly("order", [](const PySchedule& s) { return to_string(s.schedule.order()); })
      .def_property_readonly("batches", [](const PySchedule& s) { return s.schedule.batch_count(); })
      .def_property_readonly("largest_batch", [](const PySchedule& s) { return s.schedule.largest_batch(); })
      .def_property_readonly("colours", [](const PySchedule& s) { return s.schedule.colours(); })
      .def_property_readonly("overflow_contacts", [](const PySchedule& s) { return s.schedule.overflow_contacts(); })
      .def(
          "solve_order",
          [](const PySchedule& s) {
            py::array_t<std::uint32_t> out(static_cast<py::ssize_t>(s.schedule.contact_count()));
            std::copy(s.schedule.solve_order(), s.schedule.solve_order() + s.schedule.contact_count(),
                      out.mutable_data());
            return out;
          },
          "The contact indices in the order a solve applies them (uint32, (M,)).")
      .def_readonly("build_seconds", &PySchedule::build_seconds)
      .def("__repr__", [](const PySchedule& s) {
        const Schedule& k = s.schedule;
        std::string text = "collide.Schedule(" + counted(s.contacts, "contact", "contacts") + ", " +
                           counted(s.bodies, "body", "bodies") + ", order '" + to_string(k.order()) +
                           "': " + counted(k.batch_count(), "batch", "batches") + ", the largest " +
                           counted(k.largest_batch(), "contact", "contacts");
        if (k.order() == Order::colour) {
          text += ", " + counted(k.colours(), "colour", "colours") + ", " +
                  counted(k.overflow_contacts(), "overflow contact", "overflow contacts");
        }
        return text + ")";
      });

  py::class_<PySolver>(m, "Solver")
      .def(py::init<const std::string&, const py::object&, const py::object&, const std::string&, const py::object&,
                    const std::string&, bool>(),
           py::kw_only(), py::arg("path") = "simd", py::arg("threads") = 0, py::arg("isa") = py::none(),
           py::arg("accuracy") = "fast", py::arg("passes") = 1, py::arg("iteration") = "repeat",
           py::arg("warm_start") = false)
      .def_property_readonly("path", [](const PySolver& s) { return to_string(s.solver->options().path); })
      .def_property_readonly("threads", [](const PySolver& s) { return s.solver->options().threads; })
      .def_property_readonly("isa", [](const PySolver& s) { return to_string(s.solver->isa()); })
      .def_property_readonly("accuracy", [](const PySolver& s) { return to_string(s.solver->options().accuracy); })
      .def_property_readonly("passes", [](const PySolver& s) { return s.solver->options().passes; })
      .def_property_readonly("iteration", [](const PySolver& s) { return to_string(s.solver->options().iteration); })
      .def_property_readonly("warm_start", [](const PySolver& s) { return s.solver->options().warm_start; })
      .def("__repr__",
           [](const PySolver& s) {
             const SolverOptions& o = s.solver->options();
             return std::string("collide.Solver(path='") + to_string(o.path) +
                    "', threads=" + std::to_string(o.threads) + ", isa='" + to_string(s.solver->isa()) +
                    "', accuracy='" + to_string(o.accuracy) + "', passes=" + std::to_string(o.passes) +
                    ", iteration='" + to_string(o.iteration) + "'" + (o.warm_start ? ", warm_start=True" : "") + ")";
           })
      .def("solve", &PySolver::solve<Bodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("model") = "auto", py::arg("order") = py::none(), py::arg("schedule") = nullptr,
           py::arg("out") = py::none(), py::arg("warm") = py::none(), py::arg("check") = true,
           py::arg("impacts") = true)
      .def("solve", &PySolver::solve<PackedBodies>, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
           py::arg("model") = "auto", py::arg("order") = py::none(), py::arg("schedule") = nullptr,
           py::arg("out") = py::none(), py::arg("warm") = py::none(), py::arg("check") = true,
           py::arg("impacts") = true);

  py::class_<ThreadLimit>(m, "ThreadLimit")
      .def(py::init<int>(), py::arg("threads"))
      .def(
          "__enter__",
          [](ThreadLimit& t) -> ThreadLimit& {
            t.enter();
            return t;
          },
          py::return_value_policy::reference)
      .def("__exit__", [](ThreadLimit& t, const py::args&) { t.exit(); })
      .def("__repr__", [](const ThreadLimit& t) { return "collide.ThreadLimit(" + std::to_string(t.threads()) + ")"; });

  py::class_<Reference, std::shared_ptr<Reference>>(m, "Reference")
      .def_property_readonly("J", &Reference::j_array)
      .def_property_readonly("v", [](const Reference& r) { return r.vec_array(false); })
      .def_property_readonly("w", [](const Reference& r) { return r.vec_array(true); })
      .def_property_readonly("impulse_scale", &Reference::impulse_scale)
      .def_property_readonly("dtype", [](const Reference& r) { return numpy_dtype(r.dtype); })
      .def("__len__", [](const Reference& r) { return r.impulses.size(); })
      .def("__repr__", [](const Reference& r) {
        return "collide.Reference(" + counted(r.impulses.size(), "contact", "contacts") + ", " +
               counted(r.after.size(), "body", "bodies") + ", of a " + dtype_name(r.dtype) +
               " scene: J, v, w and impulse_scale in float64)";
      });

  // The options of collide.solve checked and normalised as it checks them,
  // without a Solver (no threads, no CPU check of the ISA): what
  // collide.dask checks on the client before its tasks run collide.solve.
  m.def(
      "solve_options",
      [](const std::string& path, const py::object& threads, const py::object& isa, const std::string& accuracy,
         const std::string& order, const py::object& passes, const std::string& iteration, bool warm_start) {
        const SolverOptions o = solver_options(path, threads, isa, accuracy, passes, iteration, warm_start);
        py::dict d;
        d["path"] = to_string(o.path);
        d["threads"] = o.threads;
        d["isa"] = o.isa == Isa::automatic ? py::object(py::none()) : py::object(py::str(to_string(o.isa)));
        d["accuracy"] = to_string(o.accuracy);
        d["order"] = to_string(parse_order(order));  // the schedule's, which collide.solve builds
        d["passes"] = o.passes;
        d["iteration"] = to_string(o.iteration);
        d["warm_start"] = o.warm_start;
        return d;
      },
      py::kw_only(), py::arg("path") = "simd", py::arg("threads") = 0, py::arg("isa") = py::none(),
      py::arg("accuracy") = "fast", py::arg("order") = "input", py::arg("passes") = 1, py::arg("iteration") = "repeat",
      py::arg("warm_start") = false);
  m.def("reference_solve", &reference_solve_py, py::arg("bodies"), py::arg("contacts"), py::kw_only(),
        py::arg("order") = py::none(), py::arg("passes") = 1, py::arg("iteration") = "repeat",
        py::arg("schedule") = nullptr, py::arg("warm") = py::none());
  m.def("impulse_error", &impulse_error_py, py::arg("J"), py::arg("reference"));
  m.def("conservation_drift", &conservation_drift_py, py::arg("bodies"), py::arg("reference"));
  m.attr("accurate_error_ulps") = kAccurateErrorUlps;
  m.attr("error_target_eps") = kImpulseErrorTargetEps;
  m.attr("error_bound_eps") = kImpulseErrorBoundEps;
  m.attr("warm_start_least_cosine") = kWarmStartLeastCosine;

  m.def(
      "simd_width",
      [](const std::string& isa, const py::object& dtype) {
        const Dtype d = parse_dtype(dtype);
        const Isa i = resolve_isa(parse_isa(isa));
        return d == Dtype::f32 ? simd_width<float>(i) : simd_width<double>(i);
      },
      py::arg("isa") = "auto", py::arg("dtype"));
  m.def(
      "isa_supported", [](const std::string& isa) { return isa_supported(parse_isa(isa)); }, py::arg("isa"));
  m.def("best_isa", [] { return std::string(to_string(best_isa())); });
}

}  // namespace collide::python
