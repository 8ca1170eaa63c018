#pragma once

#include <array>

namespace smx::view {

// Coverage as a scanner's user reads it: the share of twelve 30° sectors around the object
// (about the table's axis, or the first frame's vertical) seen within 30° of head-on.
class SidesSeen {
 public:
  // A view from this azimuth: the sectors whose middle is within 30° of it.
  void add(double azimuthDeg);
  [[nodiscard]] double percent() const;

 private:
  std::array<bool, 12> seen_{};
};

}  // namespace smx::view
