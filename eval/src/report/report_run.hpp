// report/report_run.hpp - what the run of the report (the Runner,
// run_report.cpp) takes from its neighbours: the scenes (report_scenes.cpp)
// and the machine description (report_machine.cpp); private to the report
// engine.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "collide/io/scene.hpp"
#include "collide/model.hpp"
#include "report.hpp"

namespace collide::report_detail {

// ---------------------------------------------------------------------------
// Scenes (report_scenes.cpp).
// ---------------------------------------------------------------------------

/// Contacts of the error sample: --sample, and with --quick at most the
/// smallest scene.
std::size_t report_sample_size(const ReportOptions& config);

enum class SceneKind { pairs, debris, pile, file };
const char* scene_name(SceneKind kind);

/// The caller's scene (ReportOptions::scene_bodies, scene_contacts) in T,
/// every rule checked as `collide solve` checks it.
template <class T>
Scene<T> read_scene_files(const std::string& bodies_path, const std::string& contacts_path);

/// The first `k` contacts of a scene with only the bodies they touch,
/// renumbered in order of first use. The law applies contacts in input
/// order, so each of them gets the impulse it gets in the whole scene; the
/// reference of a sample then needs the sample's bodies, not all of them.
template <class T>
Scene<T> contact_prefix(const Scene<T>& scene, std::size_t k);

/// A generated scene of `n` collisions; the pile of at most `n`, the largest
/// cubic one (in broadphase cell order, as a user's broadphase hands it).
template <class T>
Scene<T> make_scene(SceneKind kind, std::size_t n, bool friction, std::uint64_t seed);

/// Turns a rigid scene into one that `model` fits (see the design notes of
/// run_report.cpp).
template <class T>
void derive_model(Scene<T>& scene, Model model);

// ---------------------------------------------------------------------------
// The machine (report_machine.cpp).
// ---------------------------------------------------------------------------

/// Fills `machine`: the CPU, its caches and load, the SIMD build, what
/// Isa::automatic picks, and the triad bandwidth at every thread count of
/// config.threads. Returns that bandwidth by thread count, which the rows'
/// bandwidth fraction divides by; `progress` is told what runs.
std::map<int, double> measure_machine(const ReportOptions& config, MachineInfo& machine,
                                      const std::function<void(const std::string&)>& progress);

}  // namespace collide::report_detail
