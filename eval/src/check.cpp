// check.cpp - the impulse error against the reference and the statistics
// record of a solve (collide/eval/check.hpp).
#include "collide/eval/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_reduce.h>

#include "collide/eval/error_bound.hpp"

namespace collide {

namespace {

using L = long double;

template <class T>
L impulse_distance(const ImpulseView<const T>& j, const ImpulseView<const L>& ref, std::size_t k) {
  const L dx = L(j.j.x[k]) - ref.j.x[k];
  const L dy = L(j.j.y[k]) - ref.j.y[k];
  const L dz = L(j.j.z[k]) - ref.j.z[k];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

template <class T>
std::vector<double> impulse_errors_eps(const ImpulseView<const T>& j, const ImpulseView<const L>& ref,
                                       const std::vector<ReferenceContact<L>>& diag) {
  std::vector<double> errors(j.count);
  for (std::size_t k = 0; k < j.count; ++k) {
    errors[k] = static_cast<double>(normalised_impulse_error<T>(impulse_distance(j, ref, k), diag[k]));
  }
  return errors;
}

template <class T>
ImpulseCheck check_impulses(const ImpulseView<const T>& j, const ImpulseView<const L>& ref,
                            const std::vector<ReferenceContact<L>>& diag) {
  ImpulseCheck r;
  for (std::size_t k = 0; k < j.count; ++k) {
    const L dj = impulse_distance(j, ref, k);
    if (dj == L(0)) continue;
    const double err = static_cast<double>(normalised_impulse_error<T>(dj, diag[k]));
    // A NaN error is the worst and stays the worst (the CLI's loop before
    // this file let a later finite error replace it, so a NaN impulse could
    // pass --check).
    const bool worse = std::isnan(err) ? !std::isnan(r.max_error_eps) : err > r.max_error_eps;
    if (worse && !std::isnan(r.max_error_eps)) {
      r.max_error_eps = err;
      r.worst_contact = k;
    }
    const L jref = std::sqrt(ref.j.x[k] * ref.j.x[k] + ref.j.y[k] * ref.j.y[k] + ref.j.z[k] * ref.j.z[k]);
    if (jref > L(0)) r.max_relative_error = std::max(r.max_relative_error, static_cast<double>(dj / jref));
  }
  r.passed = r.max_error_eps <= kImpulseErrorBoundEps;
  return r;
}

template <class T>
std::size_t count_impacts(const ImpulseView<const T>& j) {
  // Bitwise or, not ||: no branch, so the loop vectorises. In parallel above a
  // few chunks: at a million contacts the pass is bound by one core's memory
  // bandwidth (a sum of counts: the same for any split).
  const auto count = [&](std::size_t k0, std::size_t k1) {
    std::size_t impacts = 0;
    for (std::size_t k = k0; k < k1; ++k) {
      impacts += static_cast<std::size_t>((j.j.x[k] != T(0)) | (j.j.y[k] != T(0)) | (j.j.z[k] != T(0)));
    }
    return impacts;
  };
  constexpr std::size_t kGrain = std::size_t{1} << 15;
  if (j.count < 2 * kGrain) return count(0, j.count);
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, j.count, kGrain), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t n) { return n + count(r.begin(), r.end()); },
      [](std::size_t x, std::size_t y) { return x + y; });
}

template <class T>
StatRecord solve_record(const SolveStats& stats, const ImpulseView<const T>& impulses, std::size_t bodies,
                        double kernel_seconds, double schedule_seconds) {
  using U = std::uint64_t;
  StatRecord r;
  // The first solve of its kind in a process may have measured the ISAs, and
  // the first solve of a size on a Solver grew its buffers and touched their
  // pages: both are reported apart (isa_calibration_seconds,
  // allocate_seconds), not as kernel time.
  kernel_seconds = std::max(0.0, kernel_seconds - stats.isa_calibration_seconds - stats.allocate_seconds);
  r.emplace_back("collisions", U(stats.contacts));
  r.emplace_back("impacts", U(count_impacts(impulses)));
  r.emplace_back("bodies", U(bodies));
  r.emplace_back("kernel_seconds", kernel_seconds);
  r.emplace_back("collisions_per_second", kernel_seconds > 0 ? static_cast<double>(stats.contacts) / kernel_seconds
                                                             : std::numeric_limits<double>::infinity());
  r.emplace_back("precision", std::string(sizeof(T) == sizeof(float) ? "float" : "double"));
  r.emplace_back("threads", U(stats.threads));
  r.emplace_back("model", std::string(to_string(stats.model)));
  r.emplace_back("path", std::string(to_string(stats.path)));
  r.emplace_back("isa", std::string(to_string(stats.isa)));
  r.emplace_back("isa_choice", std::string(to_string(stats.isa_choice)));
  r.emplace_back("layout", std::string(to_string(stats.layout)));
  r.emplace_back("accuracy", std::string(to_string(stats.accuracy)));
  r.emplace_back("lanes", U(stats.lanes));
  r.emplace_back("order", std::string(to_string(stats.order)));
  r.emplace_back("passes", U(stats.passes));
  r.emplace_back("iteration", std::string(to_string(stats.iteration)));
  r.emplace_back("warm_start", stats.warm_start);
  r.emplace_back("residual", stats.residual);
  r.emplace_back("batches", U(stats.batches));
  r.emplace_back("largest_batch", U(stats.largest_batch));
  r.emplace_back("colours", U(stats.colours));
  r.emplace_back("overflow_contacts", U(stats.overflow_contacts));
  r.emplace_back("schedule_seconds", schedule_seconds);
  r.emplace_back("isa_calibration_seconds", stats.isa_calibration_seconds);
  r.emplace_back("allocate_seconds", stats.allocate_seconds);
  return r;
}

void add_check(StatRecord& r, const ImpulseCheck& check, double check_seconds) {
  r.emplace_back("check", true);
  r.emplace_back("max_impulse_error_eps", check.max_error_eps);
  r.emplace_back("max_relative_error", check.max_relative_error);
  r.emplace_back("worst_contact", std::uint64_t(check.worst_contact));
  r.emplace_back("error_bound_eps", kImpulseErrorBoundEps);
  r.emplace_back("check_passed", check.passed);
  r.emplace_back("check_seconds", check_seconds);
}

std::string to_json(const StatRecord& record) {
  std::string s = "{";
  for (const auto& [key, value] : record) {
    if (s.size() > 1) s += ", ";
    s += json_string(key) + ": ";
    if (const auto* u = std::get_if<std::uint64_t>(&value)) {
      s += std::to_string(*u);
    } else if (const auto* d = std::get_if<double>(&value)) {
      s += json_number(*d);
    } else if (const auto* t = std::get_if<std::string>(&value)) {
      s += json_string(*t);
    } else {
      s += std::get<bool>(value) ? "true" : "false";
    }
  }
  return s + "}";
}

template std::vector<double> impulse_errors_eps<float>(const ImpulseView<const float>&, const ImpulseView<const L>&,
                                                       const std::vector<ReferenceContact<L>>&);
template std::vector<double> impulse_errors_eps<double>(const ImpulseView<const double>&, const ImpulseView<const L>&,
                                                        const std::vector<ReferenceContact<L>>&);
template ImpulseCheck check_impulses<float>(const ImpulseView<const float>&, const ImpulseView<const L>&,
                                            const std::vector<ReferenceContact<L>>&);
template ImpulseCheck check_impulses<double>(const ImpulseView<const double>&, const ImpulseView<const L>&,
                                             const std::vector<ReferenceContact<L>>&);
template std::size_t count_impacts<float>(const ImpulseView<const float>&);
template std::size_t count_impacts<double>(const ImpulseView<const double>&);
template StatRecord solve_record<float>(const SolveStats&, const ImpulseView<const float>&, std::size_t, double,
                                        double);
template StatRecord solve_record<double>(const SolveStats&, const ImpulseView<const double>&, std::size_t, double,
                                         double);

}  // namespace collide
