// collide/solve.hpp - resolving a batch of contacts.
//
// Every contact is resolved by the law of docs/collision-law.md. The result
// does not depend on the path, the SIMD width or the thread count: all paths
// run the same kernel body (core/src/contact_kernel.hpp) with the same IEEE
// operations in the same order and no fused multiply-add, so they agree bit
// for bit. Contacts that share a movable body are applied in the schedule's
// order: input order, or the colour order collide chooses (schedule.hpp).
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/isa.hpp"
#include "collide/iteration.hpp"
#include "collide/model.hpp"
#include "collide/packed.hpp"
#include "collide/schedule.hpp"

namespace collide {

/// How a Solver runs. The kinds of its choices stand beside what they choose
/// between: Path and Isa in collide/isa.hpp, Accuracy in
/// collide/accuracy.hpp, BodyLayout in collide/packed.hpp and Iteration in
/// collide/iteration.hpp. The order contacts that share movable bodies are
/// applied in is not among them: the schedule owns it (Schedule(Order),
/// collide/schedule.hpp), and a solve runs in the order of the schedule it
/// is given.
struct SolverOptions {
  Path path = Path::simd;
  /// Worker threads; 0 means every hardware thread. Results do not depend on
  /// it. Must be 0 for a solver running in the caller's arena (collide/tbb.hpp).
  int threads = 0;
  /// Contacts per range a thread takes inside a batch (rounded up to the lane
  /// width), where the batch gives each thread at most four such ranges;
  /// larger batches give each thread four longer ones, so that every range
  /// streams. A batch of 128 contacts or more gives each thread at least one
  /// range; a smaller one runs on one thread. Results do not depend on it.
  std::size_t block = 1024;
  /// Instruction set of the SIMD path (collide/isa.hpp). A named one, or the
  /// one COLLIDE_ISA names when this is automatic, is resolved when the
  /// Solver is built (one the CPU lacks makes the constructor throw) and runs
  /// every solve. automatic with COLLIDE_ISA unset picks per solve the ISA
  /// that ran fastest on this CPU for the solve's model, precision, accuracy
  /// and scene kind (fastest_isa()). Results never depend on it.
  Isa isa = Isa::automatic;
  Accuracy accuracy = Accuracy::fast;
  /// For SoA input: automatic packs it when that is faster (Solver::solve),
  /// soa never packs, packed always packs. Ignored for packed input.
  BodyLayout layout = BodyLayout::automatic;
  /// Times the contacts are resolved in the schedule's order, each pass the
  /// law as the velocities stand (>= 1). J is the sum over the passes, the
  /// same bits as that many solves with their J added in turn (every NaN
  /// the canonical one). The schedule serves every pass.
  int passes = 1;
  /// What the passes after the first do (collide/iteration.hpp): repeat the
  /// law, J the sum of the passes (the default), or accumulate each
  /// contact's impulses, J their totals. One pass from zero is the same
  /// solve either way, bit for bit. Iteration::accumulate runs in the fast
  /// mode (the constructor refuses it with Accuracy::accurate).
  Iteration iteration = Iteration::repeat;
  /// The impulse arrays hold a warm start on entry: each contact's J from a
  /// solve before (the previous frame's, of the same contacts in the same
  /// places; which contact is which across frames is the caller's to keep,
  /// as in every engine). The accumulated passes start from it: the first
  /// pass applies it to the bodies, then moves it as a later pass moves its
  /// totals, so resting contacts start near their answer
  /// (docs/collision-law.md, "The warm start"). Only the normal part of J is
  /// kept for a contact with mu = 0, and none for one without a movable
  /// body. Needs Iteration::accumulate (the constructor refuses it
  /// otherwise). Each J must be finite with J . n >= 0 (n the contact's
  /// normal, to rounding): Solver::solve checks it in every build type
  /// before anything is written, and throws std::invalid_argument naming
  /// the contact.
  bool warm_start = false;
  /// A flag the solve's threads read between passes, never inside one: once
  /// it reads true, a solve ends with the pass in progress, v, w and J as
  /// the passes done left them (SolveStats::passes says how many). For a
  /// caller that stops a long solve from another thread or a signal handler
  /// (Ctrl-C: std::atomic<bool> is lock-free, so a handler may set it); it
  /// must outlive the solves, and it stops every solve running on the
  /// Solver. Null (the default): every pass runs. One relaxed load per pass
  /// and thread: no cost in the kernels.
  const std::atomic<bool>* stop = nullptr;
};

/// The most passes the `collide` tool (--passes) and the Python module
/// (passes=) take: a bound on a mistyped count, not a limit of the Solver.
inline constexpr int kMaxPasses = 1000000;
/// The most threads they take (--threads, threads=; 0 is every hardware thread).
inline constexpr int kMaxThreads = 4096;

/// What a solve did.
struct SolveStats {
  std::size_t contacts = 0;       ///< contacts resolved (including those with J = 0)
  std::size_t batches = 0;        ///< batches run one after another (Schedule::batch_count())
  std::size_t largest_batch = 0;  ///< contacts in the largest batch (Schedule::largest_batch())
  std::size_t conflicts = 0;      ///< dependencies the schedule respected (Schedule::conflicts())
  std::size_t lanes = 0;          ///< SIMD width used for this precision
  int threads = 0;                ///< threads available to the solve
  Model model = Model::rigid;
  Path path = Path::simd;
  bool friction = false;                     ///< the Coulomb step ran (ContactView::mu was set)
  Isa isa = Isa::sse2;                       ///< the instruction set that ran (never automatic)
  IsaChoice isa_choice = IsaChoice::forced;  ///< how `isa` was chosen (collide/isa.hpp)
  /// Time this solve spent measuring the ISAs for fastest_isa() [s]: the
  /// first solve of its kind in the process with isa_choice measured pays
  /// for the measurement, every later one 0. Part of the solve's wall time.
  double isa_calibration_seconds = 0;
  /// Time this solve spent in its allocate phase [s]: growing the solver's
  /// buffers (the records SoA input is packed into, the contacts a colour-
  /// order solve copies into its order) and writing a byte in every new page
  /// on the solve's threads, so that the passes that follow pay no first-
  /// touch page faults. The first solve of a size on a Solver (every one-shot
  /// collide::solve) pays it; a solve whose buffers are already large enough
  /// allocates nothing and reports 0. Part of the solve's wall time, before
  /// any kernel runs.
  double allocate_seconds = 0;
  BodyLayout layout = BodyLayout::soa;  ///< the layout the kernel ran on (never automatic)
  Accuracy accuracy = Accuracy::fast;
  Order order = Order::input;         ///< the schedule's order (Schedule::order())
  std::size_t colours = 0;            ///< the colour order: Schedule::colours()
  std::size_t overflow_contacts = 0;  ///< the colour order: Schedule::overflow_contacts()
  /// Passes run: SolverOptions::passes, or fewer when SolverOptions::stop
  /// ended the solve (at least 1).
  std::size_t passes = 1;
  Iteration iteration = Iteration::repeat;  ///< SolverOptions::iteration
  bool warm_start = false;                  ///< SolverOptions::warm_start: the passes started from the given J
  /// How far the passes are from converged: the largest change of a
  /// contact's J in the last pass, |J - J before the last pass|, over the
  /// largest |J| (docs/collision-law.md, "The residual"); 0 when every J is
  /// 0. A solve of one pass measures nothing and reports 1 (the pass is all
  /// of J); a solve that SolverOptions::stop ended before its last pass
  /// reports NaN.
  double residual = 1;
};

/// Number of lanes of the SIMD path for T under default_isa() (COLLIDE_ISA,
/// else the widest ISA). A solve whose ISA was measured (SolveStats::
/// isa_choice) may run fewer: SolveStats::lanes says what it ran.
template <class T>
std::size_t simd_width();

// fastest_isa() and isa_measurement(), the ISA a solve with Isa::automatic
// runs and the measurement behind it: collide/isa.hpp.

/// A caller's tbb::task_arena, defined in collide/external_arena.hpp so that
/// this header does not need TBB.
struct ExternalArena;

/// A reusable solver. It owns the worker threads (a tbb::task_arena), or runs
/// in the caller's arena (collide/tbb.hpp), and allocates nothing while
/// solving once its buffers are sized, so one Solver can run every frame.
/// A solve that has to grow them does so first, and touches their new pages
/// on its threads before its kernels run (SolveStats::allocate_seconds).
///
/// SoA input whose contacts reach bodies at random (contacts in
/// non-contiguous batches, or in consecutive batches whose bodies do not
/// follow one another, at least a quarter as many as there are bodies;
/// SolverOptions::layout can force either way) is packed
/// into the solver's own buffer, solved there, and v, w written back: the
/// same bits as solving in place, several times faster on scattered scenes
/// (docs/decisions/0005-packed-records-for-scattered-contacts.md). The buffer grows to the largest scene seen and is
/// kept; solves that pack on one Solver run one at a time. The only state
/// shared between solvers is the process's cache of fastest_isa() answers:
/// two solvers never share threads unless their caller shares an arena.
class Solver {
 public:
  explicit Solver(const SolverOptions& options = {});
  /// Runs every solve inside the caller's arena instead of owning one; the
  /// arena must outlive the solver, and options.threads must be 0 (the
  /// arena's concurrency is used). Prefer collide::make_solver(arena).
  Solver(const ExternalArena& arena, const SolverOptions& options);
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;
  Solver(Solver&&) noexcept;
  Solver& operator=(Solver&&) noexcept;

  [[nodiscard]] const SolverOptions& options() const;
  /// The instruction set this solver's SIMD path runs when it is fixed:
  /// options().isa, or the one COLLIDE_ISA named when that was automatic.
  /// Isa::automatic when the choice is made per solve (isa_choice() is
  /// measured): each solve's SolveStats::isa says which ISA ran.
  [[nodiscard]] Isa isa() const;
  /// How the ISA of this solver's SIMD solves is chosen: forced,
  /// environment or measured (SolveStats::isa_choice, which is baseline on
  /// the scalar path: it always runs the baseline).
  [[nodiscard]] IsaChoice isa_choice() const;

  /// Resolves every contact: updates v and w of movable bodies and writes J.
  /// Checked in every build type before anything is read or written
  /// (std::invalid_argument naming the counts or the array): the schedule
  /// was built for as many contacts and bodies as the views hold
  /// (schedule.contact_count() == contacts.count, schedule.body_count() ==
  /// bodies.count), impulses.count == contacts.count, and no array the
  /// model reads is null while its count is > 0 (contacts.c may be null for
  /// the particle model; e and mu are optional). Schedule::build checked
  /// every index against the body count; the schedule must have been built
  /// from these contacts' indices, unchanged since (a schedule is reused
  /// while they do not change). Precondition, not checked here: the values
  /// obey validate()'s rules (finite, unit normals and quaternions, e in
  /// [0, 1], ...); values that do not may give NaN or inf but stay inside
  /// the arrays.
  template <class T>
  SolveStats solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                   const Schedule& schedule) const;
  /// The sphere model (see model.hpp for when it is the law).
  template <class T>
  SolveStats solve(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                   const Schedule& schedule) const;
  /// The particle model (see model.hpp for when it is the law).
  template <class T>
  SolveStats solve(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                   const Schedule& schedule) const;
  /// The same on packed bodies (collide/packed.hpp): the caller's records are
  /// read and their v, w written in place; nothing is packed or unpacked.
  template <class T>
  SolveStats solve(const PackedView<PackedRigid<T>>& bodies, const ContactView<T>& contacts,
                   const ImpulseView<T>& impulses, const Schedule& schedule) const;
  template <class T>
  SolveStats solve(const PackedView<PackedSphere<T>>& bodies, const ContactView<T>& contacts,
                   const ImpulseView<T>& impulses, const Schedule& schedule) const;
  template <class T>
  SolveStats solve(const PackedView<PackedParticle<T>>& bodies, const ContactView<T>& contacts,
                   const ImpulseView<T>& impulses, const Schedule& schedule) const;
  /// Rigid bodies solved with `model`, which must fit them (model_misfit()
  /// is empty; asserted in debug builds): the views of the smaller models
  /// point into the same arrays, so nothing is copied.
  template <class T>
  SolveStats solve(Model model, const BodyView<T>& bodies, const ContactView<T>& contacts,
                   const ImpulseView<T>& impulses, const Schedule& schedule) const;

 private:
  template <class Record, class View, class T>
  SolveStats solve_soa(Model model, const View& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                       const Schedule& schedule) const;
  template <class Record, class T>
  SolveStats solve_packed(Model model, const PackedView<Record>& bodies, const ContactView<T>& contacts,
                          const ImpulseView<T>& impulses, const Schedule& schedule) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot convenience: checks the input with validate() first, then builds
/// a schedule in `order` and a solver and solves with the cheapest model
/// that fits (choose_model()). Input that validate() rejects throws
/// std::invalid_argument carrying validate()'s message ("collide::solve:
/// contacts.b[17] = 40: out of range (8 bodies)") and nothing is written;
/// options the Solver refuses throw as its constructor does.
template <class T>
SolveStats solve(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses,
                 const SolverOptions& options = {}, Order order = Order::input);

}  // namespace collide
