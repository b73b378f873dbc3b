// python/src/interrupt.hpp - Ctrl-C during a solve that runs without the GIL.
//
// Design notes
// ------------
// * A solve of many passes can run for minutes with the GIL released, and
//   Python handles a signal only when it runs bytecode again: Ctrl-C used to
//   wait for the whole solve. The library reads a stop flag between passes
//   (SolverOptions::stop), so the solve can end on a whole pass, its arrays
//   as the passes done left them.
// * The flag is set by a SIGINT handler of the module's own, installed only
//   for the time of the solve, only on Python's main thread (the only one
//   Python delivers KeyboardInterrupt to) and only while SIGINT's Python
//   handler is signal.default_int_handler (a program that handles Ctrl-C
//   itself keeps its own behaviour). It sets the flag and calls the C
//   handler it replaced (Python's), so Python records the signal as before;
//   after the solve, with the GIL held again, PyErr_CheckSignals runs
//   Python's handler, which raises KeyboardInterrupt. Nothing else reads
//   the flag: no GIL is taken while solving, and a solve that is not
//   stopped costs two sigaction calls and a relaxed load per pass.
// * A solve of one pass has no point to stop at, so nothing is installed
//   for it.
#pragma once

#include <atomic>
#include <cstddef>

namespace collide::python {

/// Looks up what InterruptOnSigint needs of Python (signal.getsignal, the
/// default handler, the main thread). Called once, with the GIL, by the
/// module's init.
void prepare_interrupts();

/// While alive, a SIGINT sets `flag` (which the solve reads between
/// passes) and still reaches Python's own handler. Construct it with the
/// GIL held; `armed()` says whether the handler was installed (the main
/// thread, Python's default handler for SIGINT, a POSIX system). The flag
/// is cleared when it is armed and when it is destroyed.
class InterruptOnSigint {
 public:
  explicit InterruptOnSigint(std::atomic<bool>& flag);
  ~InterruptOnSigint();
  InterruptOnSigint(const InterruptOnSigint&) = delete;
  InterruptOnSigint& operator=(const InterruptOnSigint&) = delete;

  [[nodiscard]] bool armed() const { return armed_; }

 private:
  std::atomic<bool>& flag_;
  bool armed_ = false;
};

/// A solve stopped after `done` of its `asked` passes: raises
/// KeyboardInterrupt("collide: Ctrl-C stopped the solve after 12 of 1000
/// passes; ..."), in place of Python's own (its handler runs first; an
/// exception of another type that it raises is raised as it is). Also when
/// Python's handler raises nothing: a solve on another thread that shares
/// the Solver of the main thread's stopped one. With the GIL held.
[[noreturn]] void raise_interrupted(std::size_t done, std::size_t asked);

}  // namespace collide::python
