// report/report_json.cpp - the JSON document of `collide report --json`
// (format_report_json): the run, the machine, then one object per row, per
// hard row, per convergence row and per sweep point, keys in a fixed order.
//
// Design notes
// ------------
// * Written from the same Report as the table and the plot, rows already in
//   the canonical order (report_order.cpp), so the three agree.
// * JSON has no inf or NaN: those numbers, and cache sizes that could not be
//   read, are written as null.
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "collide/accuracy.hpp"
#include "collide/eval/check.hpp"
#include "report.hpp"
#include "report_format.hpp"

namespace collide {

namespace {

using report_detail::format;

/// A JSON number; JSON has no inf or NaN, so those become null.
std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  return format("%.6g", x);
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      // A control character as \u00XX (RFC 8259, section 7). Not format():
      // it passes a double, and %x wants an unsigned int.
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += escape;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string json_bytes(const std::optional<std::size_t>& bytes) { return bytes ? std::to_string(*bytes) : "null"; }

}  // namespace

std::string format_report_json(const Report& report) {
  const MachineInfo& m = report.machine;
  std::string s = "{\n";
  s += "  \"command\": \"collide report\",\n";
  s += "  \"n\": " + std::to_string(report.n) + ",\n";
  s += "  \"debris_n\": " + std::to_string(report.debris_n) + ",\n";
  s += "  \"pile_n\": " + std::to_string(report.pile_n) + ",\n";
  s += "  \"pile_side\": " + std::to_string(report.pile_side) + ",\n";
  s += "  \"error_sample\": " + std::to_string(report.error_sample) + ",\n";
  s += std::string("  \"quick\": ") + (report.quick ? "true" : "false") + ",\n";
  s += "  \"error_bound_eps\": " + json_number(kImpulseErrorBoundEps) + ",\n";
  s += "  \"wall_seconds\": " + json_number(report.wall_seconds) + ",\n";
  s += "  \"phase_seconds\": {";
  for (std::size_t i = 0; i < report.phase_seconds.size(); ++i) {
    s += (i ? ", " : "") + json_string(report.phase_seconds[i].first) + ": " +
         json_number(report.phase_seconds[i].second);
  }
  s += "},\n";
  s += "  \"peer\": " + json_string(report.peer_status) + ",\n";
  s += "  \"machine\": {\"cpu\": " + json_string(m.cpu) +
       ", \"hardware_threads\": " + std::to_string(m.hardware_threads) + ", \"l1d_bytes\": " + json_bytes(m.l1d_bytes) +
       ", \"l2_bytes\": " + json_bytes(m.l2_bytes) + ", \"l3_bytes\": " + json_bytes(m.l3_bytes) +
       ", \"simd\": " + json_string(m.simd_build) + ", \"load_average\": " + json_number(m.load_average) +
       ", \"triad_array_bytes\": " + std::to_string(m.triad_array_bytes) + ", \"triad_bytes_per_second\": {";
  for (std::size_t i = 0; i < m.triad_threads.size(); ++i) {
    s += (i ? ", " : "") + json_string(std::to_string(m.triad_threads[i])) + ": " +
         json_number(m.triad_bytes_per_second[i]);
  }
  s += "}, \"triad_median_bytes_per_second\": {";
  for (std::size_t i = 0; i < m.triad_threads.size(); ++i) {
    s += (i ? ", " : "") + json_string(std::to_string(m.triad_threads[i])) + ": " +
         json_number(m.triad_median_bytes_per_second[i]);
  }
  s += "}, \"isa_auto\": [";
  for (std::size_t i = 0; i < m.isa_auto.size(); ++i) {
    const IsaAutoPick& p = m.isa_auto[i];
    s += std::string(i ? ",\n" : "\n") + "    {\"precision\": " + json_string(p.precision) +
         ", \"model\": " + json_string(p.model) + ", \"accuracy\": " + json_string(p.accuracy) +
         ", \"scene\": " + json_string(p.scattered ? "scattered" : "streaming") + ", \"isa\": " + json_string(p.isa) +
         ", \"calibration_seconds\": " + json_number(p.calibration_seconds) + ", \"ns_per_contact\": {";
    for (std::size_t k = 0; k < p.ns_per_contact.size(); ++k) {
      s += (k ? ", " : "") + json_string(p.ns_per_contact[k].first) + ": " + json_number(p.ns_per_contact[k].second);
    }
    s += "}}";
  }
  s += "]},\n  \"rows\": [\n";
  for (std::size_t i = 0; i < report.rows.size(); ++i) {
    const ReportRow& r = report.rows[i];
    s += "    {\"scene\": " + json_string(r.scene) + ", \"variant\": " + json_string(r.variant) +
         ", \"model\": " + json_string(r.model) + ", \"precision\": " + json_string(r.precision) +
         ", \"simd\": " + (r.simd ? "true" : "false") + ", \"friction\": " + (r.friction ? "true" : "false") +
         ", \"threads\": " + std::to_string(r.threads) + ", \"n\": " + std::to_string(r.n) +
         ", \"lanes\": " + std::to_string(r.lanes) + ", \"isa\": " + json_string(r.isa) +
         ", \"layout\": " + json_string(r.layout) + ", \"order\": " + json_string(r.order) +
         ", \"runs\": " + std::to_string(r.runs) + ", \"seconds\": " + json_number(r.seconds) +
         ", \"collisions_per_second\": " + json_number(r.collisions_per_second) +
         ", \"bytes_per_collision\": " + json_number(r.bytes_per_collision) +
         ", \"bandwidth_fraction\": " + json_number(r.bandwidth_fraction) +
         ", \"error_sample\": " + std::to_string(r.error_sample) + ", \"eps\": " + json_number(r.eps) +
         ", \"max_err_eps\": " + json_number(r.max_err_eps) + ", \"p99_err_eps\": " + json_number(r.p99_err_eps) +
         ", \"max_rel_err\": " + json_number(r.max_rel_err) + ", \"momentum_drift\": " + json_number(r.momentum_drift) +
         ", \"angular_momentum_drift\": " + json_number(r.angular_momentum_drift) +
         ", \"energy_drift\": " + json_number(r.energy_drift) + ", \"note\": " + json_string(r.note) + "}" +
         (i + 1 < report.rows.size() ? ",\n" : "\n");
  }
  s += "  ],\n  \"hard_n\": " + std::to_string(report.hard_n) + ",\n";
  s += "  \"accurate_error_ulps\": " + json_number(kAccurateErrorUlps) + ",\n";
  s += "  \"impulse_error_target_eps\": " + json_number(kImpulseErrorTargetEps) + ",\n";
  s += "  \"hard\": [\n";
  for (std::size_t i = 0; i < report.hard.size(); ++i) {
    const HardRow& h = report.hard[i];
    s += "    {\"family\": " + json_string(h.family) + ", \"model\": " + json_string(h.model) +
         ", \"precision\": " + json_string(h.precision) + ", \"mode\": " + json_string(h.mode) +
         ", \"shared\": " + (h.shared ? "true" : "false") + ", \"n\": " + std::to_string(h.n) +
         ", \"acting\": " + std::to_string(h.acting) + ", \"threads\": " + std::to_string(h.threads) +
         ", \"isa\": " + json_string(h.isa) + ", \"runs\": " + std::to_string(h.runs) +
         ", \"seconds\": " + json_number(h.seconds) +
         ", \"collisions_per_second\": " + json_number(h.collisions_per_second) +
         ", \"max_err_eps\": " + json_number(h.max_err_eps) + ", \"p99_err_eps\": " + json_number(h.p99_err_eps) +
         ", \"max_err_ulps\": " + json_number(h.max_err_ulps) + ", \"judge\": " + json_string(h.judge) + "}" +
         (i + 1 < report.hard.size() ? ",\n" : "\n");
  }
  s += "  ],\n  \"convergence_pile_side\": " + std::to_string(report.convergence_pile_side) + ",\n";
  s += "  \"convergence\": [\n";
  for (std::size_t i = 0; i < report.convergence.size(); ++i) {
    const ConvergenceRow& c = report.convergence[i];
    s += "    {\"scene\": " + json_string(c.scene) + ", \"order\": " + json_string(c.order) +
         ", \"iteration\": " + json_string(c.iteration) + ", \"passes\": " + std::to_string(c.passes) +
         ", \"warm\": " + (c.warm ? "true" : "false") + ", \"n\": " + std::to_string(c.n) +
         ", \"threads\": " + std::to_string(c.threads) + ", \"isa\": " + json_string(c.isa) +
         ", \"runs\": " + std::to_string(c.runs) + ", \"seconds\": " + json_number(c.seconds) +
         ", \"collisions_per_second\": " + json_number(c.collisions_per_second) +
         ", \"residual\": " + json_number(c.residual) + ", \"start_residual\": " + json_number(c.start_residual) +
         ", \"next_pass\": " + json_number(c.next_pass) + "}" + (i + 1 < report.convergence.size() ? ",\n" : "\n");
  }
  s += "  ],\n  \"sweep\": [\n";
  for (std::size_t i = 0; i < report.sweep.size(); ++i) {
    const SweepPoint& p = report.sweep[i];
    s += "    {\"scene\": \"pairs\", \"variant\": \"simd\", \"precision\": \"float\", \"friction\": false, "
         "\"model\": " +
         json_string(p.model) + ", \"n\": " + std::to_string(p.n) + ", \"threads\": " + std::to_string(p.threads) +
         ", \"runs\": " + std::to_string(p.runs) +
         ", \"collisions_per_second\": " + json_number(p.collisions_per_second) +
         ", \"bandwidth_fraction\": " + json_number(p.bandwidth_fraction) + "}" +
         (i + 1 < report.sweep.size() ? ",\n" : "\n");
  }
  s += "  ]\n}\n";
  return s;
}

}  // namespace collide
