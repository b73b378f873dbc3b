// buffers.cpp - the owning SoA buffers of bodies.hpp and contacts.hpp, in the
// precisions the core solves and checks in (the definitions and the design
// notes are in buffers_impl.hpp; collide::eval instantiates the __float128
// buffers of its reference, eval/src/quad_buffers.cpp).
#include "buffers_impl.hpp"

namespace collide {

template class BodyBuffer<float>;
template class BodyBuffer<double>;
template class BodyBuffer<long double>;
template class ContactBuffer<float>;
template class ContactBuffer<double>;
template class ContactBuffer<long double>;

}  // namespace collide
