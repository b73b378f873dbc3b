// options.hpp - the settings of a collide_debris run: what the command line
// (debris.cpp) sets, and what the world, the step and the output read.
//
// One plain struct, so that every part of the example takes the same values
// and only debris.cpp knows how they are spelled on the command line.
#pragma once

#include <cstdint>
#include <string>

namespace debris {

struct Options {
  int spheres = 2000;
  int particles = 2000;
  int steps = 600;
  double dt = 1.0 / 240.0;
  double restitution = 0.3;
  double friction = 0.5;
  int passes = 3;
  std::string iteration = "repeat";  // repeat or accumulate (collide::Iteration)
  bool warm_start = false;           // accumulate from the last step's J of the same pair of bodies
  std::string order = "both";        // input, colour, or both one after the other
  int threads = 0;                   // 0: every hardware thread
  int every = 1;                     // print every n-th step
  std::uint64_t seed = 1;
  std::string out;  // PNG path; empty: no picture
  bool check = false;
};

}  // namespace debris
