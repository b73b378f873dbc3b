// collide/eval/traffic.hpp - the bytes a collision must move: the size of the
// law's inputs and outputs for a body model, each counted once.
//
// This is the numerator of the bandwidth bound that the benchmarks and
// `collide report` state: a kernel that moved exactly these bytes at the
// machine's triad bandwidth would run at collisions/s = bandwidth / bytes.
// Per body (two per contact): the fields the model reads, plus v and w (or v
// alone) written back. Per contact: the two 4-byte indices, c (not for
// particles, which never form a lever arm), n, e (unless uniform), mu (only
// with friction), and J written. For the rigid model in float without
// friction that is 2 x (17 + 6) x 4 + 8 + 7 x 4 + 3 x 4 = 232 bytes.
#pragma once

#include <cstddef>

#include "collide/model.hpp"

namespace collide {

/// Values of one body the model reads and writes.
constexpr std::size_t body_values_read(Model model) {
  switch (model) {
    case Model::particle:
      return 1 + 3;  // 1/m, v
    case Model::sphere:
      return 1 + 1 + 3 + 3 + 3;  // 1/m, 1/I, p, v, w
    case Model::rigid:
      break;
  }
  return 1 + 3 + 4 + 3 + 3 + 3;  // 1/m, 1/I, q, p, v, w
}
constexpr std::size_t body_values_written(Model model) { return model == Model::particle ? 3 : 6; }

/// Bytes per collision for values of `value_bytes` (4 float, 8 double).
constexpr std::size_t bytes_per_collision(Model model, std::size_t value_bytes, bool friction,
                                          bool per_contact_e = true) {
  const std::size_t body = 2 * (body_values_read(model) + body_values_written(model));
  const std::size_t contact = (model == Model::particle ? 0 : 3) + 3 + (per_contact_e ? 1 : 0) + (friction ? 1 : 0);
  const std::size_t impulse = 3;
  return 2 * sizeof(unsigned) + (body + contact + impulse) * value_bytes;
}

// The sum in the header's note, and the 232 B of docs/report.md.
static_assert(bytes_per_collision(Model::rigid, 4, false) == 232, "rigid float without friction: 232 bytes");

}  // namespace collide
