// isa_calibration.hpp - which instruction set's kernel runs fastest on this
// CPU, measured (collide::fastest_isa in collide/isa.hpp).
//
// Design notes
// ------------
// Why measure: the widest ISA is not always the fastest. A CPU that splits
// 512-bit operations in two can run the streaming pairs scene slower with
// AVX-512 than with AVX2 and the scattered debris scene faster (the
// measurements: docs/decisions/0006-run-time-instruction-set-choice.md). Every
// ISA gives the same bits (kernel_table.hpp), so the choice can be made on
// speed alone, and the only way to know the speed on a given CPU is to run it.
//
// How: once per process, at the first use of each key (precision, model,
// accuracy, streaming or scattered; 24 keys), under std::call_once, so that
// concurrent first solves wait for one measurement and every later call
// reads the cached answer. The module builds its own small synthetic scene
// (1024 frictionless contacts, in L2): the core library does not depend on
// the scene generators of the tools.
//   * streaming: contact k joins bodies 2k and 2k+1, the SoA views, one
//     contiguous batch (the pairs scene's layout, which the kernel loads as
//     vectors);
//   * scattered: packed records (collide/packed.hpp) reached at random, a
//     quarter of the contacts against one immovable ground, the contacts
//     gathered through a shuffled order (how the debris scene runs).
// Each ISA's SIMD kernel is called directly through its KernelTable on the
// calling thread (no TBB, no Solver), the velocities restored before every
// pass (untimed). One warm-up pass per ISA over a quarter of the contacts
// also estimates the slowest ISA's cost per contact; the timed passes then
// run as many contacts (up to all 1024) as that ISA resolves in about 0.1
// ms, so that the slow kernels (double in the accurate mode) cost no more
// than the fast ones. The ISAs alternate within each of 5 timed rounds, the
// first rotating from round to round; each ISA keeps its best pass, and the
// lowest wins. What a key costs is paid by the first solve of its kind
// (SolveStats::isa_calibration_seconds; docs/decisions/0006-run-time-instruction-set-choice.md has the cost).
//
// In cache the kernel's own cost decides, which is where the ISAs differ;
// where memory bounds a large solve, every ISA waits on the same lines.
// Friction is not part of the key: it adds the same tangent step to every
// ISA's work.
#pragma once

#include "collide/accuracy.hpp"
#include "collide/isa.hpp"
#include "collide/model.hpp"

namespace collide::detail {

/// The measurement of one key, run on the first call in the process
/// (thread-safe) and cached. When `spent_seconds` is given it receives the
/// time this call spent measuring: the measurement's wall time if this call
/// ran it, else 0.
template <class T>
const IsaMeasurement& measured_isa(Model model, Accuracy accuracy, bool scattered, double* spent_seconds = nullptr);

}  // namespace collide::detail
