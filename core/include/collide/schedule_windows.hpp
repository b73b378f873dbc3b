// collide/schedule_windows.hpp - the windows and limits of the schedule's
// two passes: the level pass of the input order (core/src/level_pass.hpp)
// and the colour pass of the colour order (core/src/colour_pass.hpp). The
// passes own them; collide/schedule.hpp, whose design notes say what they
// do, re-exports them as Schedule::kLevelWindow and the rest.
#pragma once

#include <cstddef>
#include <cstdint>

namespace collide::schedule_windows {

/// Contacts per level window of the input order.
inline constexpr std::size_t kLevelWindow = std::size_t{1} << 16;
/// A level window whose levels span fewer than this raises the floor of the next.
inline constexpr std::uint32_t kShallowWindowLevels = 16;
/// Contacts per window of the colour order.
inline constexpr std::size_t kColourWindow = std::size_t{1} << 16;
/// Colours a window of the colour order may use before its overflow.
inline constexpr std::uint32_t kMaxColours = 24;

}  // namespace collide::schedule_windows
