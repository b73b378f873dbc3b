// names.cpp - the names of the solver's options, as the command line, the
// statistics and the Python module spell them.
#include <stdexcept>
#include <string>
#include <string_view>

#include "collide/schedule.hpp"
#include "collide/solve.hpp"

namespace collide {

const char* to_string(Path path) { return path == Path::simd ? "simd" : "scalar"; }

const char* to_string(BodyLayout layout) {
  switch (layout) {
    case BodyLayout::soa:
      return "soa";
    case BodyLayout::packed:
      return "packed";
    case BodyLayout::automatic:
      break;
  }
  return "auto";
}

const char* to_string(Accuracy accuracy) { return accuracy == Accuracy::accurate ? "accurate" : "fast"; }

Accuracy parse_accuracy(std::string_view name) {
  if (name == "fast") return Accuracy::fast;
  if (name == "accurate") return Accuracy::accurate;
  throw std::invalid_argument("unknown accuracy '" + std::string(name) + "' (expected fast or accurate)");
}

const char* to_string(Iteration iteration) { return iteration == Iteration::accumulate ? "accumulate" : "repeat"; }

Iteration parse_iteration(std::string_view name) {
  if (name == "repeat") return Iteration::repeat;
  if (name == "accumulate") return Iteration::accumulate;
  throw std::invalid_argument("unknown iteration '" + std::string(name) + "' (expected repeat or accumulate)");
}

const char* to_string(Order order) { return order == Order::colour ? "colour" : "input"; }

Order parse_order(std::string_view name) {
  if (name == "input") return Order::input;
  if (name == "colour") return Order::colour;
  const std::string hint = name == "color" ? ": did you mean 'colour'?" : "";
  throw std::invalid_argument("unknown order '" + std::string(name) + "' (expected input or colour)" + hint);
}

}  // namespace collide
