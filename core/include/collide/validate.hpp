// collide/validate.hpp - checking views before they reach a kernel.
//
// The kernels trust the values of their input; what keeps them inside the
// arrays is checked in every build type: Schedule::build checks every index
// (< bodies.count, a != b), and Solver::solve the counts (the schedule's
// against the views', impulses against contacts) and that no array it reads
// is null. The values (finite, unit normals, e in [0, 1], ...) are the
// caller's: a caller that hands over its own arrays calls validate() at the
// boundary, once per scene or whenever the data may be bad, and the one-shot
// collide::solve() calls it itself. The views hold inverse units; the rules
// for physical units (what a scene file or a BodyRecord holds: m > 0, 1/m
// finite, ...) are collide/rules.hpp's, which the file reader and the
// buffers apply. The normal tolerance and the quaternion rule are the same.
#pragma once

#include <cstddef>
#include <string>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/packed.hpp"

namespace collide {

/// The first problem found, or ok.
struct Validation {
  bool ok = true;
  std::string message;  ///< names the view, the field and the element, e.g. "contacts.b[17] = 40: out of range"
  explicit operator bool() const { return ok; }
};

/// Checks what the kernels assume:
///  * every non-null view has its arrays (no null pointer with count > 0);
///  * impulses.count == contacts.count;
///  * no array the solve writes (v and w, the impulses; packed: the
///    records) shares memory with another array it writes or reads, each
///    array taken as the bytes of its `count` elements (validate_disjoint:
///    "bodies.v.x and bodies.w.x share memory: the solve writes both");
///  * contact indices < bodies.count and a != b;
///  * inverse mass and inverse moments finite and >= 0;
///  * q, p, v, w, c, n finite; |n| equal to 1 within kNormalTolerance
///    (1e-3) and |q|^2 a normal, finite number in T: the scene files' rules
///    (collide/rules.hpp). The law normalises both, and so do the kernels,
///    so they take n and q as given within those rules;
///  * e in [0, 1] (per contact, or uniform_e), mu finite and >= 0.
template <class T>
Validation validate(const BodyView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses);
/// The same for the sphere model's view (no orientation to check).
template <class T>
Validation validate(const SphereView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses);
/// The same for the particle model's view; the contact point may be absent
/// (contacts.c null), since particles never read it.
template <class T>
Validation validate(const ParticleView<T>& bodies, const ContactView<T>& contacts, const ImpulseView<T>& impulses);

/// The same for packed records (collide/packed.hpp), with the rules of the
/// record's model; messages name the field as the SoA views do
/// ("bodies.v.x[17]"). The padding of a record is not read.
template <class T>
Validation validate(const PackedView<PackedRigid<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses);
template <class T>
Validation validate(const PackedView<PackedSphere<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses);
template <class T>
Validation validate(const PackedView<PackedParticle<T>>& bodies, const ContactView<T>& contacts,
                    const ImpulseView<T>& impulses);

/// One array a solve touches, as the bytes it touches: [data, data + bytes).
struct ArrayBytes {
  const char* owner = "";  ///< what holds it: "bodies", "contacts", "impulses"
  const char* name = "";   ///< its name there: "v.x" (a message says "bodies.v.x")
  const void* data = nullptr;
  std::size_t bytes = 0;
  bool written = false;  ///< the solve writes it (and may read it)
};

/// The first two of `arrays` (in their order) whose bytes overlap where the
/// solve writes at least one of them: "A and B share memory: the solve
/// writes both" or "...: the solve writes B while it reads A". Arrays that
/// are only read may share memory; null or empty arrays share nothing.
/// validate() checks every view this way; the Python module names its
/// arrays (one row of a 2-D array at a time) and calls it at its boundary.
Validation validate_disjoint(const ArrayBytes* arrays, std::size_t count);

/// Only what keeps a solve inside the arrays: every index of `a` and `b`
/// below `body_count`, and a != b. O(count), for callers that vouch for the
/// values (a frame loop re-solving a scene it validated once: the Python
/// module's check=False); the message names the element like validate()'s.
/// A quick sufficient test of the contact rules (collide/rules.hpp) over
/// every contact, column by column on the lane layer and in parallel, as
/// validate() screens them: true means every contact obeys them; false
/// means one may not (a value near a bound is left to contact_ok, which
/// decides exactly). Null e and mu count as valid, as in validate().
template <class T>
bool contacts_pass_screen(const ContactView<T>& contacts, std::size_t body_count);

Validation validate_indices(const BodyIndex* a, const BodyIndex* b, std::size_t count, std::size_t body_count);

/// The least cosine of the angle between a warm start's J and its contact's
/// normal that a solve takes: J within 120 degrees of n. A J from the frame
/// before lies in the Coulomb cone of that frame's normal, and the normal
/// turns between frames, so J . n may come out a little below 0 and the
/// solve takes its normal part as 0; a J that points against n, as the
/// impulse on body b instead of a, or another contact's, is refused.
inline constexpr double kWarmStartLeastCosine = -0.5;

/// A warm start's J (SolverOptions::warm_start) a solve takes: finite, and
/// J . n >= kWarmStartLeastCosine |J| |n|. Solver::solve checks every
/// contact's this way before writing anything.
template <class T>
bool warm_start_accepted(const T (&j)[3], const T (&n)[3]);

/// The first contact (by index) whose J in `warm` warm_start_accepted
/// refuses, or contacts.count when there is none. O(count), one thread:
/// for callers that name the contact in their own terms before solving.
template <class T>
std::size_t first_refused_warm_start(const ContactView<T>& contacts, const ImpulseView<const T>& warm);

/// Why contact k's J in `warm` is refused, as a phrase that follows the
/// value: "is not finite", or "has J . n = -0.5 < 0: a normal impulse never
/// pulls the bodies together".
template <class T>
std::string warm_start_refusal(const ContactView<T>& contacts, const ImpulseView<const T>& warm, std::size_t k);

}  // namespace collide
