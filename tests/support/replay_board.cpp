#include "replay_board.hpp"

#include <sstream>
#include <stdexcept>
#include <vector>

#include "cli.hpp"
#include "smx/config/rig_json.hpp"
#include "source_dir.hpp"

namespace smx::test {

namespace fs = std::filesystem;

namespace {
fs::path boardsDir() {
  return smx::test::sourceDir() / "boards";
}
}  // namespace

std::string replayRigFile(int cameras) {
  return cameras == 1 ? "rig_2proj_1cam.json" : "rig_2proj_2cam.json";
}

fs::path replayFrames(int cameras, int frames) {
  const std::string rig = replayRigFile(cameras);
  fs::path dir = fs::temp_directory_path() / ("smx_replay_" + rig + "_" + std::to_string(frames));
  if (fs::exists(dir / ("cam0_" + std::to_string(frames - 1) + ".png"))) {
    return dir;
  }
  std::ostringstream out;
  std::ostringstream err;
  const std::vector<std::string> args = {"sim",
                                         "--rig",
                                         (boardsDir() / "sim" / rig).string(),
                                         "--scene",
                                         "turntable",
                                         "--frames",
                                         std::to_string(frames),
                                         "--no-truth",
                                         "--out",
                                         dir.string()};
  if (host::runCli(args, {out, err}) != 0) {
    throw std::runtime_error("rendering replay frames: " + err.str());
  }
  return dir;
}

config::Board replayBoard(int cameras, int frames) {
  auto loaded = config::loadBoard(boardsDir() / "sim");
  if (!loaded) {
    throw std::runtime_error(loaded.error().message());
  }
  config::Board board = std::move(*loaded);
  board.config.sim.scene.clear();
  board.config.sim.replayDir = replayFrames(cameras, frames);
  board.config.network.port = 0;
  for (auto& camera : board.config.cameras) {
    camera.format.fps = 1000;
  }
  if (cameras == 1) {
    board.rig = config::loadRig(boardsDir() / "sim" / replayRigFile(1)).value();
    board.config.cameras.resize(1);
  }
  return board;
}

}  // namespace smx::test
