// The simulated board's replay cameras (`stripemuxd --replay DIR`) read camera images from
// files: a file is checked against its camera before its pixels are allocated.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "alloc_counter.hpp"
#include "png_claim.hpp"
#include "smx/config/board_json.hpp"
#include "smx/hal/board_hal.hpp"
#include "source_dir.hpp"

namespace smx {
namespace {

namespace fs = std::filesystem;

// Given boards/sim replaying a folder whose cam0_0.png is 65 bytes claiming 20000x20000 pixels
// (1.2 GB as RGB), when the board's HAL is created, then it fails naming the file, its claim and
// the camera's 640x480, having allocated nothing near the claim.
TEST(SimReplay, FrameClaimingAHugeSizeIsRefusedNamingTheFileAndBothSizes) {
  auto board = config::loadBoard(test::sourceDir() / "boards/sim");
  ASSERT_TRUE(board.has_value()) << board.error().message();
  const fs::path dir = fs::temp_directory_path() / "smx_replay_png_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto bomb = test::pngClaiming(20000, 20000);
  std::ofstream(dir / "cam0_0.png", std::ios::binary)
      .write(reinterpret_cast<const char*>(bomb.data()), static_cast<std::streamsize>(bomb.size()));
  board->config.sim.scene.clear();
  board->config.sim.replayDir = dir;

  const test::AllocationCounter counter;
  const auto hal = hal::createBoardHal(board->config, board->rig);
  EXPECT_LT(counter.bytes(), 16U << 20U);
  ASSERT_FALSE(hal.has_value());
  EXPECT_NE(hal.error().find("cam0_0.png: image is 20000x20000, camera cam0 is 640x480"),
            std::string::npos)
      << hal.error();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smx
