// collide/io/drawn_scene.hpp - writing a scene that is drawn item by item
// (a generated scene, collide/io/generate.hpp) straight to its two scene
// files, without holding it as a Scene first.
//
// Design notes
// ------------
// * The scene is given as per-index draw functions, each item a pure
//   function of its index (generate.hpp's draw_pair, draw_debris_body,
//   draw_pile_contact... bound to their options): a DrawnScene draws its
//   bodies and its contacts separately (debris, pile), DrawnPairs draws
//   contact k together with its bodies 2k and 2k + 1 (pairs, whose contact
//   decides whether its bodies are drawn again, so neither can be drawn
//   alone without drawing the pair).
// * CSV is streamed: blocks of items are drawn and formatted in parallel and
//   written in order, a few blocks in memory at a time, so ten million pairs
//   need tens of megabytes, not the gigabytes of the scene. Values are
//   written as the CSV writers write them (append_body_row,
//   append_contact_row: the shortest text that reads back to the double
//   drawn, inf for an immovable body's mass and moments).
// * A binary (.npz) file holds a table column by column, so its columns are
//   drawn in parallel into memory (each value rounded once from the double
//   drawn to the precision, as the generators round it) and written by the
//   binary writers of collide/io/scene_npz.hpp in one pass.
// * Because every item depends on its index only and blocks are written in
//   order, the bytes depend neither on the threads (those of the caller's
//   TBB arena, as for every io writer) nor on the block size. The same scene
//   generated in memory (generate_pairs, generate_debris, generate_pile) and
//   the files written here hold the same values.
// * The files go through OutputFile like every writer: the caller commits
//   both once both are written, so a failure leaves no half-written scene.
//
// The header is C++17, like the rest of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string_view>

#include "collide/bodies.hpp"
#include "collide/contacts.hpp"
#include "collide/io/npz.hpp"
#include "collide/io/output_file.hpp"
#include "collide/io/scene_npz.hpp"

namespace collide {

/// A scene whose bodies and contacts are drawn separately, in physical units
/// and in double: draw_body(i, body) draws body i of [0, bodies),
/// draw_contact(k, contact) contact k of [0, contacts). Both are called from
/// several threads at once and must depend on the index only. Ids are
/// written as drawn, not checked against `bodies`.
struct DrawnScene {
  std::size_t bodies = 0;
  std::size_t contacts = 0;
  std::function<void(std::uint64_t i, BodyRecord<double>& body)> draw_body;
  std::function<void(std::uint64_t k, ContactRecord<double>& contact)> draw_contact;
};

/// A scene of independent pairs: draw_pair(k, a, b, contact) draws bodies 2k
/// and 2k + 1 and contact k of [0, pairs) in one call (generate.hpp's
/// draw_pair); 2 pairs bodies and `pairs` contacts. Called from several
/// threads at once; must depend on k only.
struct DrawnPairs {
  std::size_t pairs = 0;
  std::function<void(std::uint64_t k, BodyRecord<double>& a, BodyRecord<double>& b, ContactRecord<double>& contact)>
      draw_pair;
};

/// How a drawn scene is written.
struct DrawnSceneOptions {
  /// csv (the shortest text of each double drawn) or npz.
  SceneFormat format = SceneFormat::csv;
  /// The dtype of an npz scene's real columns: f8 (double) or f4 (float,
  /// each value rounded from the double drawn). CSV is written from the
  /// doubles and takes only f8.
  NpyType precision = NpyType::f8;
  /// Called, if set, after each block of CSV rows is written, on the writing
  /// thread: the part being written ("pairs" for DrawnPairs, else "bodies",
  /// then "contacts"), the items of that part written so far and their
  /// total. Not called for npz.
  std::function<void(std::string_view part, std::size_t done, std::size_t total)> progress;
};

/// Writes `scene` as a bodies file and a contacts file in options.format,
/// bodies and contacts in index order. Does not commit the files. Throws
/// std::invalid_argument for a precision other than f4 or f8, or f4 with
/// csv; SceneError when a file cannot be written; what a draw function
/// throws.
void write_drawn_scene(const DrawnScene& scene, const DrawnSceneOptions& options, OutputFile& bodies,
                       OutputFile& contacts);
/// The same for a scene of pairs: body 2k, body 2k + 1 and contact k are
/// pair k's, each pair drawn once.
void write_drawn_scene(const DrawnPairs& scene, const DrawnSceneOptions& options, OutputFile& bodies,
                       OutputFile& contacts);

}  // namespace collide
