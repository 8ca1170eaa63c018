#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "smx/hal/board_hal.hpp"
#include "smx/hal/steady_clock.hpp"
#include "smx/linux/gpiod_trigger.hpp"
#include "smx/linux/gpiod_turntable.hpp"
#include "smx/linux/libcamera_open.hpp"
#include "smx/linux/v4l2_camera.hpp"
#include "smx/linux/v4l2_io.hpp"
#include "smx/net/tcp_link.hpp"

// The factory of the Linux backend: V4L2 cameras, libgpiod trigger lines, a TCP link and the
// monotonic clock, opened from the board file.
namespace smx::hal {

namespace {

class LinuxBoardHal final : public BoardHal {
 public:
  LinuxBoardHal() = default;

  [[nodiscard]] Hal hal() override {
    return Hal{.cameras = cameraPointers_,
               .trigger = *trigger_,
               .link = *link_,
               .clock = clock_,
               .turntable = turntable_.get()};
  }

  lnx::SystemV4l2Io io_;  // declared first: the cameras use it until they are destroyed
  std::vector<std::unique_ptr<lnx::V4l2Camera>> cameras_;
  std::vector<std::unique_ptr<Camera>> libcameraCameras_;
  std::vector<Camera*> cameraPointers_;
  std::unique_ptr<lnx::GpiodTrigger> trigger_;
  std::unique_ptr<lnx::GpiodTurntable> turntable_;
  std::unique_ptr<net::TcpLink> link_;
  SteadyClock clock_;
};

std::string cameraField(std::size_t index) {
  return "cameras[" + std::to_string(index) + "]";
}

// The board file must list the rig's devices in the rig's order (the loader checks this too;
// a mismatch here would silently pair a camera with another camera's calibration).
std::string rigMismatch(const BoardConfig& board, const algo::Rig& rig) {
  if (board.cameras.size() != rig.cameras.size()) {
    return "cameras: the board has " + std::to_string(board.cameras.size()) + " cameras, the rig " +
           std::to_string(rig.cameras.size());
  }
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    if (board.cameras[i].id != rig.cameras[i].id) {
      return cameraField(i) + ".id: '" + board.cameras[i].id + "', the rig's camera " +
             std::to_string(i) + " is '" + rig.cameras[i].id + "'";
    }
  }
  if (board.trigger.lines.size() != rig.projectors.size()) {
    return "trigger.lines: the board has " + std::to_string(board.trigger.lines.size()) +
           " lines, the rig " + std::to_string(rig.projectors.size()) + " projectors";
  }
  for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
    if (board.trigger.lines[i].role != rig.projectors[i].id) {
      return "trigger.lines[" + std::to_string(i) + "].role: '" + board.trigger.lines[i].role +
             "', the rig's projector " + std::to_string(i) + " is '" + rig.projectors[i].id + "'";
    }
  }
  return {};
}

}  // namespace

std::string_view halBackend() {
  return "linux";
}

std::expected<std::unique_ptr<BoardHal>, std::string> createBoardHal(const BoardConfig& board,
                                                                     const algo::Rig& rig) {
  if (const std::string mismatch = rigMismatch(board, rig); !mismatch.empty()) {
    return std::unexpected("board '" + board.name + "': " + mismatch);
  }
  auto result = std::make_unique<LinuxBoardHal>();
  for (std::size_t i = 0; i < board.cameras.size(); ++i) {
    const CameraConfig& config = board.cameras[i];
    if (config.device.starts_with(lnx::kLibcameraPrefix)) {
      const std::string_view device = config.device;
      auto camera = lnx::openLibcameraCamera(device.substr(lnx::kLibcameraPrefix.size()), config.id,
                                             config.buffers);
      if (!camera) {
        return std::unexpected(cameraField(i) + ".device: " + camera.error());
      }
      if (auto granted = (*camera)->configure(config.format); !granted) {
        return std::unexpected(cameraField(i) + ".format: " + config.device + ": " +
                               granted.error().message);
      }
      result->cameraPointers_.push_back(camera->get());
      result->libcameraCameras_.push_back(std::move(*camera));
      continue;
    }
    if (!config.device.starts_with("/dev/")) {
      return std::unexpected(cameraField(i) + ".device: '" + config.device +
                             "' is neither a V4L2 device path (/dev/videoN) nor libcamera:<id>");
    }
    auto camera = lnx::V4l2Camera::create(config.device, config.id, config.buffers, result->io_);
    if (!camera) {
      return std::unexpected(cameraField(i) + ": " + camera.error());
    }
    auto granted = (*camera)->configure(config.format);
    if (!granted) {
      return std::unexpected(
          cameraField(i) + ".format: " + config.device + " cannot deliver " +
          std::to_string(config.format.width) + "x" + std::to_string(config.format.height) + " " +
          std::string(toString(config.format.pixelFormat)) + ": " + granted.error().message);
    }
    result->cameraPointers_.push_back(camera->get());
    result->cameras_.push_back(std::move(*camera));
  }
  auto trigger = lnx::GpiodTrigger::create(board.trigger);
  if (!trigger) {
    return std::unexpected(trigger.error());
  }
  result->trigger_ = std::move(*trigger);
  if (board.turntable) {
    auto turntable = lnx::GpiodTurntable::create(*board.turntable);
    if (!turntable) {
      return std::unexpected(turntable.error());
    }
    result->turntable_ = std::move(*turntable);
  }
  auto link = net::TcpLink::create(board.network);
  if (!link) {
    return std::unexpected(link.error());
  }
  result->link_ = std::move(*link);
  return result;
}

}  // namespace smx::hal
