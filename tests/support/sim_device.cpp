#include "sim_device.hpp"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "source_dir.hpp"

namespace smx::test {

using namespace std::chrono_literals;

config::Board sourceBoard(std::string_view folder) {
  const auto file = sourceDir() / "boards" / folder;
  auto loaded = config::loadBoard(file);
  if (!loaded) {
    throw std::runtime_error(file.string() + ": " + loaded.error().message());
  }
  loaded->config.network.port = 0;
  return std::move(*loaded);
}

config::Board renderingScene(config::Board board, const std::string& scene, const algo::Rig& rig) {
  board.config.sim.scene = scene;
  board.config.sim.replayDir.clear();
  board.rig = rig;
  board.config.cameras.resize(rig.cameras.size());
  for (auto& camera : board.config.cameras) {
    camera.format.fps = 1000;
  }
  return board;
}

SimDevice::SimDevice(config::Board board, const SimDeviceOptions& options)
    : board_(std::move(board)) {
  auto made = hal::createBoardHal(board_.config, options.renderedRig.value_or(board_.rig));
  if (!made) {
    throw std::runtime_error("simulated board: " + made.error());
  }
  boardHal_ = std::move(*made);
  control_ = sim::simBoardControl(*boardHal_);
  if (control_ == nullptr) {
    throw std::runtime_error("simulated board: the HAL is not the sim backend's");
  }
  auto madeDevice = device::Device::create(board_, boardHal_->hal(), options.device);
  if (!madeDevice) {
    throw std::runtime_error("device: " + madeDevice.error());
  }
  device_ = std::move(*madeDevice);
  network_ = std::jthread([this] { device_->runNetwork(stopNetwork_); });
  switch (options.loops) {
    case SimLoops::kNetwork:
      break;
    case SimLoops::kServe:
      // The capture loop of stripemuxd without its range captures.
      capture_ = std::jthread([this] {
        while (!stopCapture_) {
          const bool served = device_->serveRawCapture();
          if (!device_->serveTurn() && !served) {
            std::this_thread::sleep_for(1ms);
          }
        }
      });
      break;
    case SimLoops::kCapture:
      startCapture();
      break;
  }
}

SimDevice::~SimDevice() {
  // The capture loop first: a turn or raw capture it serves is answered by the network loop.
  stopCapture_ = true;
  if (capture_.joinable()) {
    capture_.join();
  }
  stopNetwork_ = true;
  if (network_.joinable()) {
    network_.join();
  }
}

void SimDevice::startCapture() {
  if (!capture_.joinable()) {
    capture_ = std::jthread([this] { device_->runCapture(stopCapture_); });
  }
}

bool SimDevice::serveOne() {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!device_->rawCaptureRequested() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(1ms);
  }
  return device_->serveRawCapture();
}

std::uint16_t SimDevice::port() const {
  return boardHal_->hal().link.port();
}

std::string SimDevice::address() const {
  return "127.0.0.1:" + std::to_string(port());
}

}  // namespace smx::test
