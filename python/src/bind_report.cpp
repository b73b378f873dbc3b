// python/src/bind_report.cpp - collide.report and collide.report_hard: the
// rows of `collide report` (and of its hard section) as lists of dicts.
//
// Design notes
// ------------
// * The measurement is the library's (report.hpp: measure_report,
//   measure_hard_report), run without the GIL; its options out of range
//   (std::invalid_argument, named by the library) arrive as ValueError
//   (module.cpp).
// * The dict keys are those of the report's JSON rows (docs/report.md).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "report.hpp"

namespace collide::python {
namespace {

/// f() (a report measurement) without the GIL.
template <class F>
auto measure_without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

py::list report_py(std::size_t n, std::optional<std::size_t> debris_n, std::optional<std::size_t> pile_n,
                   std::vector<int> threads, std::size_t sample, int runs, std::uint64_t seed, bool quick) {
  ReportOptions o;
  o.n = n;
  o.debris_n = debris_n ? *debris_n : std::min<std::size_t>(n, o.debris_n);
  o.pile_n = pile_n ? *pile_n : std::min<std::size_t>(n, o.pile_n);
  o.threads = std::move(threads);
  o.sample = sample;
  o.runs = runs;
  o.seed = seed;
  o.quick = quick;
  // The rows are all it returns; report_convergence() measures that section.
  o.convergence = false;
  const Report r = measure_without_gil([&] { return measure_report(o); });
  py::list rows;
  for (const ReportRow& x : r.rows) {
    py::dict d;
    d["scene"] = x.scene;
    d["variant"] = x.variant;
    d["model"] = x.model;
    d["precision"] = x.precision;
    d["simd"] = x.simd;
    d["friction"] = x.friction;
    d["threads"] = x.threads;
    d["n"] = x.n;
    d["lanes"] = x.lanes;
    d["isa"] = x.isa;
    d["layout"] = x.layout;
    d["runs"] = x.runs;
    d["seconds"] = x.seconds;
    d["collisions_per_second"] = x.collisions_per_second;
    d["bytes_per_collision"] = x.bytes_per_collision;
    d["bandwidth_fraction"] = x.bandwidth_fraction;
    d["error_sample"] = x.error_sample;
    d["eps"] = x.eps;
    d["max_err_eps"] = x.max_err_eps;
    d["p99_err_eps"] = x.p99_err_eps;
    d["max_rel_err"] = x.max_rel_err;
    d["momentum_drift"] = x.momentum_drift;
    d["angular_momentum_drift"] = x.angular_momentum_drift;
    d["energy_drift"] = x.energy_drift;
    d["note"] = x.note;
    rows.append(d);
  }
  return rows;
}

/// The hard section alone (measure_hard_report), one dict per HardRow.
py::list report_hard_py(std::size_t n, int runs) {
  ReportOptions o;
  o.hard = true;
  o.hard_n = n;
  o.runs = runs;
  const std::vector<HardRow> hard = measure_without_gil([&] { return measure_hard_report(o); });
  py::list rows;
  for (const HardRow& x : hard) {
    py::dict d;
    d["family"] = x.family;
    d["model"] = x.model;
    d["precision"] = x.precision;
    d["mode"] = x.mode;
    d["shared"] = x.shared;
    d["n"] = x.n;
    d["acting"] = x.acting;
    d["threads"] = x.threads;
    d["isa"] = x.isa;
    d["runs"] = x.runs;
    d["seconds"] = x.seconds;
    d["collisions_per_second"] = x.collisions_per_second;
    d["max_err_eps"] = x.max_err_eps;
    d["p99_err_eps"] = x.p99_err_eps;
    // NaN where not measured (double without a __float128 reference): None, as the JSON's null.
    d["max_err_ulps"] = std::isnan(x.max_err_ulps) ? py::object(py::none()) : py::object(py::float_(x.max_err_ulps));
    d["judge"] = x.judge;
    rows.append(d);
  }
  return rows;
}

/// The convergence section alone (measure_convergence_report), one dict
/// per ConvergenceRow.
py::list report_convergence_py(std::size_t n, std::vector<int> threads, int runs, std::uint64_t seed) {
  ReportOptions o;
  o.convergence_n = n;
  o.threads = std::move(threads);
  o.runs = runs;
  o.seed = seed;
  const std::vector<ConvergenceRow> rows = measure_without_gil([&] { return measure_convergence_report(o); });
  py::list out;
  for (const ConvergenceRow& x : rows) {
    py::dict d;
    d["scene"] = x.scene;
    d["order"] = x.order;
    d["iteration"] = x.iteration;
    d["passes"] = x.passes;
    d["warm"] = x.warm;
    d["n"] = x.n;
    d["threads"] = x.threads;
    d["isa"] = x.isa;
    d["runs"] = x.runs;
    d["seconds"] = x.seconds;
    d["collisions_per_second"] = x.collisions_per_second;
    d["residual"] = x.residual;
    d["start_residual"] = x.start_residual;
    d["next_pass"] = x.next_pass;
    out.append(d);
  }
  return out;
}

}  // namespace

void register_report(py::module_& m) {
  m.def("report", &report_py, py::kw_only(), py::arg("n") = 1000000, py::arg("debris_n") = py::none(),
        py::arg("pile_n") = py::none(), py::arg("threads") = std::vector<int>{1, 2}, py::arg("sample") = 100000,
        py::arg("runs") = 3, py::arg("seed") = 1, py::arg("quick") = false);
  m.def("report_hard", &report_hard_py, py::kw_only(), py::arg("n") = 1000, py::arg("runs") = 5);
  m.def("report_convergence", &report_convergence_py, py::kw_only(), py::arg("n") = 188800,
        py::arg("threads") = std::vector<int>{1, 2}, py::arg("runs") = 3, py::arg("seed") = 1);
}

}  // namespace collide::python
