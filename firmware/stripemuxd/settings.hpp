#pragma once

#include <expected>
#include <filesystem>
#include <string>

#include "smx/config/board_json.hpp"
#include "smx/config/device_config.hpp"
#include "smx/device/device.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/protocol/messages.hpp"

// The owner's settings of a running board (docs/config.md): read from the state directory at
// start, changed by set-config, stored whole before the device restarts with them.
namespace smx::firmware {

// What the board's devices can change: settings for controls it lacks are refused, naming the key.
struct Hardware {
  hal::CameraControlSupport cameras;  // what every camera has
  bool dimmable = false;              // the projectors' power can be set
};

[[nodiscard]] Hardware hardwareOf(const hal::Hal& hal);

class Settings {
 public:
  // `stateDir` empty: no state directory, the board's settings and set-config refused. Reads
  // `<stateDir>/config.json` when there is one; a file that no longer fits the board is set
  // aside as config.json.rejected and said so in `report`, and the board's settings apply.
  static std::expected<Settings, std::string> load(const std::filesystem::path& stateDir,
                                                   config::Board board, Hardware hardware,
                                                   std::string& report);

  // The board and the device options as the device runs with the stored settings.
  [[nodiscard]] config::Board board() const { return config::appliedTo(stored_, board_); }
  [[nodiscard]] device::DeviceOptions deviceOptions(device::DeviceOptions base) const;

  // A host's set-config: checked against the board and the pipeline, stored, and then the
  // settings of board() and deviceOptions(). Returns the settings the device will run with.
  [[nodiscard]] std::expected<std::string, std::string> change(const protocol::SetConfig& request);
  // Goes back to the settings before the last change (the device could not start with them).
  [[nodiscard]] std::expected<void, std::string> revert();

  // "the board's" or "config.json: fps, rig" for the start-up line.
  [[nodiscard]] std::string describe() const;

 private:
  Settings(std::filesystem::path stateDir, config::Board board, Hardware hardware)
      : stateDir_(std::move(stateDir)), board_(std::move(board)), hardware_(hardware) {}
  [[nodiscard]] std::expected<void, std::string> store(const config::DeviceConfig& next);

  std::filesystem::path stateDir_;
  config::Board board_;  // as board.json says
  Hardware hardware_;
  config::DeviceConfig stored_;
  config::DeviceConfig previous_;
};

}  // namespace smx::firmware
