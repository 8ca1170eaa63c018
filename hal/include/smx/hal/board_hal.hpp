#pragma once

#include <expected>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "smx/algo/rig.hpp"
#include "smx/hal/board_config.hpp"
#include "smx/hal/camera.hpp"
#include "smx/hal/clock.hpp"
#include "smx/hal/link.hpp"
#include "smx/hal/trigger.hpp"
#include "smx/hal/turntable.hpp"

// What the firmware runs on: the board's devices as interfaces. Exactly one backend library
// (smx_hal_sim or smx_hal_linux) defines createBoardHal() and halBackend(); CMake picks it.
namespace smx::hal {

struct Hal {
  std::span<Camera* const> cameras;  // in the rig's camera order
  TriggerLines& trigger;
  Link& link;
  Clock& clock;
  Turntable* turntable = nullptr;  // nullptr: the board has none
};

class BoardHal {
 public:
  virtual ~BoardHal() = default;
  BoardHal(const BoardHal&) = delete;
  BoardHal& operator=(const BoardHal&) = delete;
  [[nodiscard]] virtual Hal hal() = 0;

 protected:
  BoardHal() = default;
};

// "sim" or "linux": the backend this build links.
[[nodiscard]] std::string_view halBackend();

// Opens the board's devices (init time: allocates, may fail with a message naming the device).
[[nodiscard]] std::expected<std::unique_ptr<BoardHal>, std::string> createBoardHal(
    const BoardConfig& board, const algo::Rig& rig);

}  // namespace smx::hal
