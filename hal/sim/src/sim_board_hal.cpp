// The sim backend's factory: the simulated board's cameras and trigger lines, the real TCP link
// and clock of the PC it runs on.
#include <memory>
#include <string>
#include <vector>

#include "sim_camera.hpp"
#include "sim_trigger.hpp"
#include "sim_turntable.hpp"
#include "smx/config/scene_json.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/hal/steady_clock.hpp"
#include "smx/net/tcp_link.hpp"
#include "smx/sim/named_scenes.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/renderer.hpp"
#include "smx/sim/sim_board.hpp"

namespace smx::hal {

namespace {

namespace fs = std::filesystem;
using Fail = std::unexpected<std::string>;

class SimBoardHal final : public BoardHal, public sim::SimBoardControl {
 public:
  [[nodiscard]] Hal hal() override {
    return Hal{.cameras = cameraPointers_,
               .trigger = *trigger_,
               .link = *link_,
               .clock = clock_,
               .turntable = turntable_.get()};
  }

  void injectTimeouts(int camera, int count) override { at(camera).injectTimeouts(count); }
  void disconnect(int camera) override { at(camera).setConnected(false); }
  void reconnect(int camera) override { at(camera).setConnected(true); }
  void dropFrames(int camera, int count) override { at(camera).dropFrames(count); }
  [[nodiscard]] std::vector<sim::TriggerEdge> triggerEdges() const override {
    return trigger_->edges();
  }
  [[nodiscard]] std::uint32_t lastExposureMask(int camera) const override {
    return cameras_.at(static_cast<std::size_t>(camera))->lastExposureMask();
  }
  [[nodiscard]] std::uint64_t framesDelivered(int camera) const override {
    return cameras_.at(static_cast<std::size_t>(camera))->delivered();
  }

  static std::expected<std::unique_ptr<SimBoardHal>, std::string> create(const BoardConfig& board,
                                                                         const algo::Rig& rig);

 private:
  sim::SimCamera& at(int camera) { return *cameras_.at(static_cast<std::size_t>(camera)); }

  SteadyClock clock_;
  std::unique_ptr<sim::Renderer> renderer_;
  std::vector<std::vector<sim::RgbImage>> replay_;  // per camera
  std::unique_ptr<sim::SimTrigger> trigger_;
  std::unique_ptr<sim::SimTurntable> turntable_;
  std::vector<std::unique_ptr<sim::SimCamera>> cameras_;
  std::vector<Camera*> cameraPointers_;
  std::unique_ptr<net::TcpLink> link_;
};

// <dir>/<camera-id>_<n>.png for n = 0, 1, ... while the files exist.
std::expected<std::vector<sim::RgbImage>, std::string> loadReplay(const fs::path& dir,
                                                                  const algo::Camera& camera) {
  std::vector<sim::RgbImage> frames;
  while (true) {
    const fs::path file = dir / (camera.id + "_" + std::to_string(frames.size()) + ".png");
    if (!fs::exists(file)) {
      break;
    }
    // The camera's size is checked against the file's header, before the pixels are allocated.
    const std::string owner = "camera " + camera.id;
    auto image =
        sim::readPngRgb8(file, sim::PngSizeLimit::exactly(camera.width, camera.height, owner));
    if (!image) {
      return Fail(image.error());
    }
    frames.push_back(std::move(*image));
  }
  if (frames.empty()) {
    return Fail("sim.replay: no frames for camera " + camera.id + " (expected " +
                (dir / (camera.id + "_0.png")).string() + ")");
  }
  return frames;
}

std::expected<std::unique_ptr<SimBoardHal>, std::string> SimBoardHal::create(
    const BoardConfig& board, const algo::Rig& rig) {
  auto out = std::make_unique<SimBoardHal>();
  if (!board.sim.replayDir.empty()) {
    for (const auto& camera : rig.cameras) {
      auto frames = loadReplay(board.sim.replayDir, camera);
      if (!frames) {
        return Fail(frames.error());
      }
      out->replay_.push_back(std::move(*frames));
    }
  } else {
    auto scenePath = sim::resolveScene(board.sim.scene);
    if (!scenePath) {
      return Fail("sim.scene: " + scenePath.error());
    }
    auto scene = config::loadScene(*scenePath);
    if (!scene) {
      return Fail("sim.scene: " + scene.error().message());
    }
    auto renderer = sim::Renderer::create(rig, *scene);
    if (!renderer) {
      return Fail("sim.scene: " + renderer.error());
    }
    out->renderer_ = std::move(*renderer);
  }

  std::vector<std::string> roles;
  roles.reserve(board.trigger.lines.size());
  for (const auto& line : board.trigger.lines) {
    roles.push_back(line.role);
  }
  // Replayed images were taken at one power: only rendered light can be dimmed.
  out->trigger_ =
      std::make_unique<sim::SimTrigger>(std::move(roles), out->clock_, out->replay_.empty());
  if (board.turntable) {
    out->turntable_ = std::make_unique<sim::SimTurntable>(*board.turntable, out->clock_);
  }
  for (std::size_t i = 0; i < board.cameras.size(); ++i) {
    const CameraConfig& config = board.cameras[i];
    const sim::SimCameraSource source{.renderer = out->renderer_.get(),
                                      .rigCamera = static_cast<int>(i),
                                      .seed = board.sim.seed,
                                      .replay = out->replay_.empty() ? nullptr : &out->replay_[i],
                                      .turntable = out->turntable_.get()};
    out->cameras_.push_back(std::make_unique<sim::SimCamera>(
        config.id, source, *out->trigger_, out->clock_, config.format, config.buffers));
    out->cameraPointers_.push_back(out->cameras_.back().get());
  }
  auto link = net::TcpLink::create(board.network);
  if (!link) {
    return Fail("network: " + link.error());
  }
  out->link_ = std::move(*link);
  return out;
}

}  // namespace

std::string_view halBackend() {
  return "sim";
}

std::expected<std::unique_ptr<BoardHal>, std::string> createBoardHal(const BoardConfig& board,
                                                                     const algo::Rig& rig) {
  if (board.backend != halBackend()) {
    return Fail("board '" + board.name + "' needs the " + board.backend +
                " HAL, but this stripemuxd was built with the sim HAL");
  }
  auto made = SimBoardHal::create(board, rig);
  if (!made) {
    return Fail(made.error());
  }
  return std::unique_ptr<BoardHal>(std::move(*made));
}

}  // namespace smx::hal

namespace smx::sim {

SimBoardControl* simBoardControl(hal::BoardHal& board) {
  return dynamic_cast<SimBoardControl*>(&board);
}

}  // namespace smx::sim
