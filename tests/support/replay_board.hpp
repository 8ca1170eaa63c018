#pragma once

#include <filesystem>
#include <string>

#include "smx/config/board_json.hpp"

// Test support, host only: the simulated board replaying turntable frames rendered by its own
// rig, so the firmware's tests and benchmarks decode real depth without the renderer's cost.
namespace smx::test {

// The example rig of a 1- or 2-camera board (2 projectors).
[[nodiscard]] std::string replayRigFile(int cameras);

// `frames` turntable frames as that rig's cameras see them (<camera-id>_<n>.png), rendered once
// into a temporary folder and reused. Throws std::runtime_error with the reason.
[[nodiscard]] std::filesystem::path replayFrames(int cameras, int frames);

// boards/sim replaying those frames on a free loopback port, its cameras at 1000 fps (the loop,
// not the sensor, sets the pace); with 1 camera, the 1-camera rig. Throws on failure.
[[nodiscard]] config::Board replayBoard(int cameras, int frames);

}  // namespace smx::test
