// report/report_machine.cpp - the machine block of the report
// (measure_machine): the CPU, its caches and load, the ISA the SIMD rows
// run and the ones this CPU has, what Isa::automatic picks for every model,
// accuracy and scene kind, and the triad bandwidth at every thread count of
// the rows.
//
// Design notes
// ------------
// * Apart from the Runner (run_report.cpp): the machine block says where the
//   rows ran and depends on no scene. It is measured once, first in the run,
//   and the Runner keeps only the triad bandwidth by thread count, the
//   divisor of the rows' bandwidth fraction (the bandwidth bound in the
//   design notes of run_report.cpp).
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "collide/eval/bandwidth.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"
#include "collide/rules.hpp"
#include "collide/solve.hpp"
#include "report.hpp"
#include "report_run.hpp"

namespace collide::report_detail {

namespace {

/// What Isa::automatic picks for every model, accuracy and scene kind in
/// T (fastest_isa; the first call of each kind in this process measures).
template <class T>
void measure_isa_auto(std::vector<IsaAutoPick>& picks) {
  for (const Accuracy accuracy : {Accuracy::fast, Accuracy::accurate}) {
    for (const Model model : {Model::particle, Model::sphere, Model::rigid}) {
      for (const bool scattered : {false, true}) {
        const IsaMeasurement measured = isa_measurement<T>(model, accuracy, scattered);
        IsaAutoPick pick;
        pick.precision = precision_name<T>();
        pick.model = to_string(model);
        pick.accuracy = to_string(accuracy);
        pick.scattered = scattered;
        pick.isa = to_string(measured.fastest);
        pick.calibration_seconds = measured.calibration_seconds;
        for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
          const double seconds = measured.seconds[static_cast<int>(isa) - static_cast<int>(Isa::sse2)];
          if (seconds > 0 && measured.contacts > 0) {
            pick.ns_per_contact.emplace_back(to_string(isa), 1e9 * seconds / static_cast<double>(measured.contacts));
          }
        }
        picks.push_back(std::move(pick));
      }
    }
  }
}

}  // namespace

std::map<int, double> measure_machine(const ReportOptions& config, MachineInfo& m,
                                      const std::function<void(const std::string&)>& progress) {
  std::map<int, double> triad;
  {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line)) {
      if (line.rfind("model name", 0) == 0) {
        const std::size_t colon = line.find(':');
        if (colon != std::string::npos) m.cpu = line.substr(colon + 2);
        break;
      }
    }
    std::ifstream loadavg("/proc/loadavg");
    loadavg >> m.load_average;
  }
  m.hardware_threads = static_cast<unsigned>(sysconf(_SC_NPROCESSORS_ONLN));
  m.l1d_bytes = cache_bytes(1);
  m.l2_bytes = cache_bytes(2);
  m.l3_bytes = cache_bytes(3);
  {
    std::string supported;
    for (const Isa isa : {Isa::sse2, Isa::avx2, Isa::avx512}) {
      if (isa_supported(isa)) supported += std::string(supported.empty() ? "" : ", ") + to_string(isa);
    }
    m.simd_build = std::string("simd rows: ") + to_string(default_isa()) + " (this CPU has " + supported +
                   "): " + std::to_string(simd_width<float>()) + " float / " + std::to_string(simd_width<double>()) +
                   " double lanes";
  }
  progress("isa auto: measuring the ISAs");
  measure_isa_auto<float>(m.isa_auto);
  measure_isa_auto<double>(m.isa_auto);
  for (const int t : config.threads) {
    if (std::find(m.triad_threads.begin(), m.triad_threads.end(), t) != m.triad_threads.end()) continue;
    progress("triad bandwidth, " + std::to_string(t) + " thread(s)");
    const TriadResult r = measure_triad(t, 0, config.quick ? 3 : 10);
    m.triad_threads.push_back(t);
    m.triad_bytes_per_second.push_back(r.bytes_per_second);
    m.triad_median_bytes_per_second.push_back(r.median_bytes_per_second);
    m.triad_array_bytes = r.array_bytes;
    triad[t] = r.bytes_per_second;
  }
  return triad;
}

}  // namespace collide::report_detail
