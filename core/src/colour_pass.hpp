// colour_pass.hpp - the colour order's schedule (schedule.hpp, Order::colour;
// docs/collision-law.md, "The colour order"): contacts coloured greedily over
// their movable bodies, window by window, and grouped colour by colour
// (private to the library).
//
// Design notes
// ------------
// * The input is cut into windows of kColourWindow contacts. In each
//   window, contact k takes the lowest colour of kColours that no earlier
//   contact of the window on one of its movable bodies holds; a contact that
//   finds none goes to the window's overflow. Immovable bodies join no
//   colour (the kernels never write them). The solve order is window by
//   window, colour by colour, then the overflow in input order, which runs
//   as the level schedule of its own contacts (a contact of overflow level L
//   after every earlier overflow contact of the window on its bodies).
// * Why windows, when Box2D colours a whole island: a window's contacts and
//   the bodies they reach stay in cache while its colours run one after
//   another, so a pile or a chain in a broadphase's cell order reads its
//   contacts and bodies from memory about once per pass, not once per colour
//   (the copy into the solve order, prepared_contacts.hpp, reads a window's
//   contacts colour after colour the same way); and the windows are coloured
//   independently, in parallel, with the same colours for any thread count.
// * The colouring reads two words of a per-thread body table per contact:
//   24 colour bits and a tag that says which window they belong to (so no
//   pass clears them between windows), or that the body is immovable. Like
//   the level pass, it is bound by those random reads on scattered scenes
//   and prefetches the words kPrefetchDistance contacts ahead. 24 colours,
//   as Box2D's graph has, more than the generated scenes' windows use
//   (docs/decisions/0031-the-colour-order.md).
// * Every index is screened (contact_indices.hpp) before the window's
//   colouring reads a table word through it; a window that fails records
//   itself, and the first bad contact of the first failing window is named,
//   as the level pass names it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "batch_sort.hpp"
#include "collide/schedule_windows.hpp"
#include "schedule_input.hpp"
#include "scratch_vector.hpp"

namespace collide::detail {

/// Colours a window may use; a contact that finds none of them free goes to
/// the window's overflow (Schedule::kMaxColours).
inline constexpr std::uint32_t kColours = schedule_windows::kMaxColours;

/// What the colour pass keeps between builds.
struct ColourScratch {
  std::vector<ScratchVector<std::uint32_t>> masks;   ///< per chunk: each body's colours in the window
  std::vector<ScratchVector<std::uint32_t>> levels;  ///< per chunk, when a window overflows: the overflow's level table
  ScratchVector<std::uint8_t> label;                 ///< per contact: its colour, or kColours for the overflow
  std::vector<std::vector<std::uint32_t>> batches;   ///< per window: the sizes of its batches, in solve order
};

/// What the colour pass found.
struct ColourSummary {
  std::uint32_t colours = 0;  ///< colours used by the most colourful window
  std::size_t overflow = 0;   ///< contacts in the windows' overflows
  std::size_t conflicts = 0;  ///< contacts' movable bodies with an earlier contact in the window
};

/// The colour schedule of the contacts into `order` and `out`, on at most
/// `workers` threads; the result does not depend on `workers`. Throws
/// std::invalid_argument naming the first contact with a bad index.
template <class T>
ColourSummary colour_contacts(const ContactIndices& contacts, const InverseMasses<T>& inv_mass, std::size_t workers,
                              ColourScratch& scratch, std::uint32_t* order, Batches& out);

}  // namespace collide::detail
