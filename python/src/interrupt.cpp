// python/src/interrupt.cpp - the SIGINT handler of interrupt.hpp.
#include "interrupt.hpp"

#include <pybind11/pybind11.h>

#include <csignal>
#include <string>

// sigaction (POSIX; <csignal> declares it there).
#if defined(__unix__) || defined(__APPLE__)
#define COLLIDE_PYTHON_SIGACTION 1
#endif

namespace collide::python {
namespace py = pybind11;

namespace {

/// What the module needs of Python to decide whether to install the
/// handler, looked up once at import (the module's init holds the GIL) and
/// kept for the life of the process.
struct PythonSignals {
  py::object getsignal;              // signal.getsignal
  py::object default_int_handler;    // signal.default_int_handler
  unsigned long main_thread_id = 0;  // threading.main_thread().ident
};
PythonSignals* python_signals = nullptr;

#ifdef COLLIDE_PYTHON_SIGACTION
/// The flag the handler sets, and the handler it replaced (Python's).
std::atomic<std::atomic<bool>*> sigint_flag{nullptr};
struct sigaction replaced_sigint {};

void set_flag_on_sigint(int signal_number, siginfo_t* info, void* context) {
  if (std::atomic<bool>* flag = sigint_flag.load()) flag->store(true);
  // Python's own handler records the signal too: its KeyboardInterrupt
  // comes once the solve returns.
  if ((replaced_sigint.sa_flags & SA_SIGINFO) != 0) {
    if (replaced_sigint.sa_sigaction != nullptr) replaced_sigint.sa_sigaction(signal_number, info, context);
  } else if (replaced_sigint.sa_handler != SIG_DFL && replaced_sigint.sa_handler != SIG_IGN &&
             replaced_sigint.sa_handler != nullptr) {
    replaced_sigint.sa_handler(signal_number);
  }
}
#endif

/// The main thread, with SIGINT's Python handler Python's default one.
bool python_raises_on_sigint() {
  if (python_signals == nullptr || PyThread_get_thread_ident() != python_signals->main_thread_id) return false;
  return python_signals->getsignal(SIGINT).is(python_signals->default_int_handler);
}

}  // namespace

void prepare_interrupts() {
  if (python_signals != nullptr) return;
  auto* s = new PythonSignals;  // kept: read by every later solve, never freed
  const py::module_ signal = py::module_::import("signal");
  s->getsignal = signal.attr("getsignal");
  s->default_int_handler = signal.attr("default_int_handler");
  s->main_thread_id = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  python_signals = s;
}

InterruptOnSigint::InterruptOnSigint(std::atomic<bool>& flag) : flag_(flag) {
#ifdef COLLIDE_PYTHON_SIGACTION
  if (!python_raises_on_sigint()) return;
  // The handler in place first (Python's C handler), then ours: a signal
  // between the two calls reaches Python's alone, as it did before.
  struct sigaction current {};
  if (sigaction(SIGINT, nullptr, &current) != 0) return;
  if ((current.sa_flags & SA_SIGINFO) == 0 && (current.sa_handler == SIG_DFL || current.sa_handler == SIG_IGN)) {
    return;
  }
  replaced_sigint = current;
  flag_.store(false);
  sigint_flag.store(&flag_);
  struct sigaction ours {};
  ours.sa_sigaction = set_flag_on_sigint;
  ours.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&ours.sa_mask);
  if (sigaction(SIGINT, &ours, nullptr) != 0) {
    sigint_flag.store(nullptr);
    return;
  }
  armed_ = true;
#endif
}

InterruptOnSigint::~InterruptOnSigint() {
#ifdef COLLIDE_PYTHON_SIGACTION
  if (!armed_) return;
  sigaction(SIGINT, &replaced_sigint, nullptr);
  sigint_flag.store(nullptr);
  flag_.store(false);
#endif
}

void raise_interrupted(std::size_t done, std::size_t asked) {
  if (PyErr_CheckSignals() != 0) {
    if (!PyErr_ExceptionMatches(PyExc_KeyboardInterrupt)) throw py::error_already_set();
    PyErr_Clear();
  }
  const std::string message = "collide: Ctrl-C stopped the solve after " + std::to_string(done) + " of " +
                              std::to_string(asked) +
                              " passes; v, w (or the records) and out= are as those passes left them";
  PyErr_SetString(PyExc_KeyboardInterrupt, message.c_str());
  throw py::error_already_set();
}

}  // namespace collide::python
