// body_fill.hpp - BodyBuffer from checked columns (private to the library).
#pragma once

#include "collide/bodies.hpp"
#include "collide/scene_io.hpp"

namespace collide::detail {

/// The buffer the kernels take, from columns that obey the rules (a
/// reader's, already checked): q, p, v and w copied column by column, m and
/// I inverted as BodyBuffer::set inverts them. No rule is checked here:
/// to_body_buffer checks them first.
template <class T>
BodyBuffer<T> fill_body_buffer(const BodyColumns<T>& columns);

}  // namespace collide::detail
