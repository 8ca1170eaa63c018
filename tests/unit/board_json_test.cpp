#include "smx/config/board_json.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "source_dir.hpp"

namespace smx::config {
namespace {

const std::filesystem::path kBoards = smx::test::sourceDir() / "boards";

// The sim board's text with one substitution, parsed against the sim board folder.
std::expected<Board, BoardError> simBoardWith(const std::string& from, const std::string& to) {
  std::ifstream in(kBoards / "sim" / "board.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) {
    text.replace(at, from.size(), to);
  }
  return parseBoard(text, kBoards / "sim");
}

void expectError(const std::expected<Board, BoardError>& board, const std::string& field,
                 const std::string& problemPart) {
  ASSERT_FALSE(board.has_value());
  EXPECT_EQ(board.error().field, field) << board.error().message();
  EXPECT_NE(board.error().problem.find(problemPart), std::string::npos) << board.error().message();
}

TEST(BoardJson, TheShippedBoardsLoad) {
  const auto sim = loadBoard(kBoards / "sim");
  ASSERT_TRUE(sim.has_value()) << sim.error().message();
  EXPECT_EQ(sim->config.backend, "sim");
  ASSERT_EQ(sim->config.cameras.size(), 2U);
  EXPECT_EQ(sim->config.cameras[1].id, "cam1");
  EXPECT_EQ(sim->config.cameras[0].format.width, 640);
  ASSERT_EQ(sim->config.trigger.lines.size(), 2U);
  EXPECT_EQ(sim->config.trigger.leadNs, 200'000);
  EXPECT_EQ(sim->config.sim.scene, "turntable");
  EXPECT_EQ(sim->rig.projectors.size(), 2U);

  const auto rpi = loadBoard(kBoards / "rpi4" / "board.json");
  ASSERT_TRUE(rpi.has_value()) << rpi.error().message();
  EXPECT_EQ(rpi->config.backend, "linux");
  EXPECT_EQ(rpi->config.cameras[0].device, "/dev/video0");
  EXPECT_EQ(rpi->config.cameras[0].format.pixelFormat, hal::PixelFormat::kYuyv);
  EXPECT_EQ(rpi->config.trigger.lines[1].offset, 27U);
  EXPECT_EQ(rpi->config.network.bindAddress, "0.0.0.0");
  // The Pi's four cores decode, and capture overlaps decoding.
  EXPECT_EQ(rpi->config.threads, 4);
  EXPECT_TRUE(rpi->config.pipelined);
  // Unsaid: one thread per camera, capture then decode.
  EXPECT_EQ(sim->config.threads, 0);
  EXPECT_FALSE(sim->config.pipelined);

  // The hand-held board: 15 fps, one camera, two projectors, the hand-held head scene.
  const auto handheld = loadBoard(kBoards / "sim-handheld");
  ASSERT_TRUE(handheld.has_value()) << handheld.error().message();
  ASSERT_EQ(handheld->config.cameras.size(), 1U);
  EXPECT_EQ(handheld->config.cameras[0].format.fps, 15);
  EXPECT_EQ(handheld->config.sim.scene, "head_handheld");
  EXPECT_EQ(handheld->rig.projectors.size(), 2U);

  // The kernel tests' board shares the simulator's rig through a relative path.
  const auto qemu = loadBoard(kBoards / "qemu");
  ASSERT_TRUE(qemu.has_value()) << qemu.error().message();
  EXPECT_EQ(qemu->config.cameras[0].format.pixelFormat, hal::PixelFormat::kRgb24);
  EXPECT_EQ(qemu->rig.cameras[0].id, "cam0");
  EXPECT_EQ(qemu->rig.projectors.size(), 2U);
}

TEST(BoardJson, ErrorsNameTheField) {
  expectError(simBoardWith(R"("id": "cam1")", R"("id": "camX")"), "cameras[1].id",
              "is not the rig's camera 1");
  expectError(simBoardWith(R"("pixel_format": "RGB24", "fps": 30, "buffers": 4},)",
                           R"("pixel_format": "NV12", "fps": 30, "buffers": 4},)"),
              "cameras[0].pixel_format", "is not one of: RGB24, BGR24, YUYV");
  expectError(simBoardWith(R"("fps": 30, "buffers": 4}
  ])",
                           R"("fps": 30, "buffers": 64}
  ])"),
              "cameras[1].buffers", "from 2 to 32");
  expectError(simBoardWith(R"({"role": "proj1", "chip": "sim", "line": 1})",
                           R"({"role": "proj1", "chip": "sim", "line": 0})"),
              "triggers.lines[1].line", "already the line of \"proj0\"");
  expectError(simBoardWith(R"(,
      {"role": "proj1", "chip": "sim", "line": 1})",
                           ""),
              "triggers.lines", "has 1 entries but the rig has 2 projectors");
  expectError(simBoardWith(R"("bind": "127.0.0.1")", R"("bind": "localhost")"), "network.bind",
              "is not an IPv4 address");
  expectError(simBoardWith(R"("rig": "rig_2proj_2cam.json")", R"("rig": "missing.json")"), "rig",
              "missing.json");
  expectError(simBoardWith(R"("hal": "sim")", R"("hal": "linux")"), "sim",
              "only a board with \"hal\": \"sim\"");
  expectError(simBoardWith(R"("scene": "turntable")", R"("scene": "turntable", "replay": "x")"),
              "sim", "exactly one of");
  expectError(simBoardWith(R"("depth_unit_m")", R"("depth_units_m")"), "",
              "did you mean \"depth_unit_m\"");
  expectError(simBoardWith("stripemux-board/1", "stripemux-rig/1"), "format", "this is a rig.json");
  expectError(simBoardWith(R"("depth_unit_m")", R"("threads": 0, "depth_unit_m")"), "threads",
              "from 1 to 64");
  expectError(simBoardWith(R"("depth_unit_m")", R"("pipelined": "yes", "depth_unit_m")"),
              "pipelined", "true or false");
}

// The board's name goes on the wire to every host: an id, not free text.
TEST(BoardJson, TheNameIsAnId) {
  expectError(simBoardWith(R"("name": "sim")", R"("name": "sim\u001b]0;x\u0007")"), "name",
              "has a character that is not allowed");
  expectError(simBoardWith(R"("name": "sim")", R"("name": "../sim")"), "name",
              "must start with a letter or digit");
}

// A depth unit whose 16 bits cannot hold twice the board's working distance would lose depths.
TEST(BoardJson, DepthUnitMustHoldTheWorkingRange) {
  expectError(simBoardWith(R"("depth_unit_m": 0.0001)", R"("depth_unit_m": 1e-6)"), "depth_unit_m",
              "every depth beyond the limit would be lost");
  EXPECT_TRUE(simBoardWith(R"("depth_unit_m": 0.0001)", R"("depth_unit_m": 2.75e-5)").has_value());
}

TEST(BoardJson, AMissingFileIsNamed) {
  const auto board = loadBoard(kBoards / "no-such-board");
  ASSERT_FALSE(board.has_value());
  EXPECT_NE(board.error().message().find("no-such-board"), std::string::npos);
}

}  // namespace
}  // namespace smx::config
