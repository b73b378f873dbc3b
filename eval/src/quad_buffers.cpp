// quad_buffers.cpp - the body and contact buffers of the __float128 reference
// (collide/eval/reference.hpp), where GCC has __float128
// (COLLIDE_HAS_FLOAT128, collide/bodies.hpp). They are the evaluation's, not
// the core's: the core instantiates its buffers for float, double and long
// double only (core/src/buffers.cpp) and needs no quad-precision runtime.
#include "buffers_impl.hpp"

#include "collide/eval/reference.hpp"

namespace collide {

#if COLLIDE_HAS_FLOAT128
template class BodyBuffer<__float128>;
template class ContactBuffer<__float128>;
#endif

}  // namespace collide
