// itt_tsan_bridge.cpp - hands oneTBB's synchronisation to ThreadSanitizer.
//
// Why this exists
// ---------------
// libtbb.so from Debian is not built with -fsanitize=thread, so TSan cannot
// see the happens-before edges TBB creates when a task is spawned on one
// thread and stolen by another, or when parallel_for returns after the last
// worker finishes. Without them every hand-over of data between the calling
// thread and the workers (the scene written before Solver::solve, a batch's
// output read by the next batch on another worker, the impulses read after
// the solve) is reported as a race, and a real race (two lanes of one batch
// writing the same body) cannot be told apart from them.
//
// TBB publishes exactly those edges through the ITT notification API it
// implements for Intel's threading tools: sync_releasing(p) before a
// hand-over and sync_acquired(p) after it, in libtbb (task pools, mailboxes,
// waiters) and in the TBB headers when they are compiled with
// TBB_USE_PROFILING_TOOLS=2 (spawn, fold_tree, wait_context). libtbb loads
// the ITT collector named by INTEL_LIBITTNOTIFY64 and, because this one
// exports __itt_api_version, fills the function pointers of the groups named
// by INTEL_ITTNOTIFY_GROUPS (the run sets "sync"). This library is that
// collector: releasing -> __tsan_release, acquired -> __tsan_acquire, on the
// same address. It suppresses nothing: an access that no TBB edge orders is
// still reported (tests/tsan/race_canary.cpp checks that).
//
// Built only in TSan builds (cmake/sanitizers.cmake: libcollide_itt_tsan.so);
// scripts/ci-sanitizers.sh sets the two variables.
#include <sanitizer/tsan_interface.h>

extern "C" {

// The ITT API fixes these reserved names: the loader finds them by name.
// NOLINTBEGIN(bugprone-reserved-identifier)

// Presence marks an ITT "version 1" collector, whose functions the loader
// looks up by name.
__attribute__((visibility("default"))) int __itt_api_version = 1;

__attribute__((visibility("default"))) void __itt_sync_releasing(void* addr) { __tsan_release(addr); }
__attribute__((visibility("default"))) void __itt_sync_acquired(void* addr) { __tsan_acquire(addr); }

// NOLINTEND(bugprone-reserved-identifier)

}  // extern "C"
