// isa_test.hpp - for the lane-layer tests compiled once per kernel ISA
// (collide_add_isa_test in tests/CMakeLists.txt): which ISA this binary was
// compiled for, and a global environment that skips every test, with the
// reason, on a CPU that cannot run it (executing them would be SIGILL, not a
// failure of the code under test).
#pragma once

#include <gtest/gtest.h>

#include <string_view>

#include "collide/isa.hpp"

#ifndef COLLIDE_TEST_ISA
#error "isa_test.hpp is for tests built by collide_add_isa_test (COLLIDE_TEST_ISA)"
#endif

namespace collide::test {

#define COLLIDE_TEST_STR2(x) #x
#define COLLIDE_TEST_STR(x) COLLIDE_TEST_STR2(x)

/// The ISA this test binary's lanes are compiled for ("native" builds, off
/// x86-64, answer to every name and count as sse2 here).
inline Isa test_isa() {
  const std::string_view name = COLLIDE_TEST_STR(COLLIDE_TEST_ISA);
  return name == "native" ? Isa::sse2 : parse_isa(name);
}

class IsaEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    if (!isa_supported(test_isa())) {
      GTEST_SKIP() << "this CPU cannot run " << to_string(test_isa()) << " (it has up to " << to_string(best_isa())
                   << "); these lane tests run on a CPU that has it";
    }
  }
};

inline ::testing::Environment* const kIsaEnvironment = ::testing::AddGlobalTestEnvironment(new IsaEnvironment);

}  // namespace collide::test
