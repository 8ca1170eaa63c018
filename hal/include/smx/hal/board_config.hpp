#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "smx/hal/camera.hpp"

// A board as its board.json describes it (docs/boards.md): which backend it needs, its rig,
// cameras, projector trigger lines by role, network and depth unit. Plain data; the firmware's
// board loader fills and validates it, a backend's createBoardHal() consumes it.
namespace smx::hal {

struct CameraConfig {
  std::string id;      // the rig's camera id
  std::string device;  // "/dev/video0", "libcamera:<name>", or "sim" on the simulated board
  CameraFormat format;
  int buffers = 4;            // streaming buffers, 2..32
  CameraControls controls{};  // the owner's exposure and gain (docs/config.md)
};

struct TriggerLineConfig {
  std::string role;  // the rig's projector id
  std::string chip;  // "gpiochip0" (linux); ignored by the simulated board
  unsigned offset = 0;
  bool activeLow = false;
};

struct TriggerConfig {
  std::vector<TriggerLineConfig> lines;  // in the rig's projector order
  std::int64_t leadNs = 0;               // lines active this long before the exposure starts
  std::uint32_t rangeMask = 0;  // the projectors a range capture lights and decodes; 0: all
  int powerPercent = 100;       // every projector's light, percent of full
};

// A stepper turntable driven through a STEP/DIR driver (docs/boards.md, "turntable"). The
// simulated board ignores the chip and lines.
struct TurntableConfig {
  std::string chip;  // "gpiochip0" (linux)
  unsigned stepLine = 0;
  unsigned dirLine = 0;
  std::optional<unsigned> enableLine{};  // none: the driver is always enabled
  bool enableActiveLow = true;           // most stepper drivers enable on a low EN
  std::int32_t stepsPerTurn = 0;
  double speedDegS = 30.0;
  int settleMs = 500;
};

struct NetworkConfig {
  std::string bindAddress = "0.0.0.0";
  std::uint16_t port = 5555;  // 0: any free port (tests)
  // The kernel's send buffer for the host connection (0: the system's default). Small keeps
  // frames in the firmware's queue, where a slow host makes the oldest drop, rather than in the
  // kernel, where they would only grow old.
  int sendBufferBytes = 0;
};

// Only the simulated board: what its cameras see.
struct SimBoardConfig {
  std::string scene;                // a named scene or a scene.json path; rendered live
  std::filesystem::path replayDir;  // or: replay <dir>/<camera-id>_<n>.png in a loop
  std::uint64_t seed = 1;
};

struct BoardConfig {
  std::string name;
  std::string backend;  // "sim" or "linux": which HAL the firmware must be built with
  std::filesystem::path directory;
  std::filesystem::path rigPath;
  std::vector<CameraConfig> cameras;  // in the rig's camera order
  TriggerConfig trigger;
  std::optional<TurntableConfig> turntable{};  // none: the board has no turntable
  NetworkConfig network;
  double depthUnitM = 1e-4;
  int threads = 0;         // decoding threads (0: one per camera)
  bool pipelined = false;  // capture the next frame while the last decodes
  SimBoardConfig sim;
};

}  // namespace smx::hal
