// isa_env.hpp - sets or clears COLLIDE_ISA for one scope, restoring it after.
#pragma once

#include <cstdlib>
#include <string>

namespace collide::test {

class IsaEnv {
 public:
  /// nullptr clears the variable.
  explicit IsaEnv(const char* value) {
    if (const char* old = std::getenv("COLLIDE_ISA")) saved_ = old, had_ = true;
    if (value) {
      setenv("COLLIDE_ISA", value, 1);
    } else {
      unsetenv("COLLIDE_ISA");
    }
  }
  ~IsaEnv() {
    if (had_) {
      setenv("COLLIDE_ISA", saved_.c_str(), 1);
    } else {
      unsetenv("COLLIDE_ISA");
    }
  }
  IsaEnv(const IsaEnv&) = delete;
  IsaEnv& operator=(const IsaEnv&) = delete;

 private:
  std::string saved_;
  bool had_ = false;
};

}  // namespace collide::test
