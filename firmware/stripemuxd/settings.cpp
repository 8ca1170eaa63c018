#include "settings.hpp"

#include <system_error>
#include <utility>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/device/state_file.hpp"

namespace smx::firmware {
namespace {

namespace fs = std::filesystem;

constexpr const char* kConfigFile = "config.json";

algo::PipelineOptions pipelineOptions(const config::DeviceConfig& c, const config::Board& board,
                                      algo::PipelineOptions base) {
  base.depthUnitM = board.config.depthUnitM;
  base.minDepthM = c.depthMinM.value_or(0.0);
  base.maxDepthM = c.depthMaxM.value_or(base.maxDepthM);
  base.minConfidence = c.confidenceMin.value_or(1);
  return base;
}

std::expected<void, std::string> checkHardware(const config::DeviceConfig& c,
                                               const Hardware& hardware) {
  if (c.exposureUs.value_or(0) != 0 && !hardware.cameras.exposure) {
    return std::unexpected("exposure_us: the board's cameras have no exposure control");
  }
  if (c.gain.value_or(0.0) != 0.0 && !hardware.cameras.gain) {
    return std::unexpected("gain: the board's cameras have no gain control");
  }
  if (c.projectorPower.value_or(100) != 100 && !hardware.dimmable) {
    return std::unexpected(
        "projector_power: the board's trigger lines only switch its projectors on and off");
  }
  return {};
}

// What Device::create() would refuse about the settings, before they are stored.
std::expected<void, std::string> checkSettings(const config::DeviceConfig& c,
                                               const config::Board& physical,
                                               const Hardware& hardware) {
  if (auto fits = checkHardware(c, hardware); !fits) {
    return fits;
  }
  const config::Board board = config::appliedTo(c, physical);
  const auto options = pipelineOptions(c, board, {});
  const algo::Rig rig = config::rangeRig(board);
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    if (const auto setup = algo::prepareCameraPipeline(rig, static_cast<int>(i), options); !setup) {
      return std::unexpected("the device cannot decode camera " + board.rig.cameras[i].id +
                             " with these settings: " + setup.error());
    }
  }
  return {};
}

std::string fieldMessage(const config::FieldError& e) {
  return config::errorMessage("", e.field, e.problem);
}

}  // namespace

Hardware hardwareOf(const hal::Hal& hal) {
  Hardware hardware{.cameras = {.exposure = true, .gain = true},
                    .dimmable = hal.trigger.dimmable()};
  for (const hal::Camera* camera : hal.cameras) {
    const hal::CameraControlSupport support = camera->controlSupport();
    hardware.cameras.exposure = hardware.cameras.exposure && support.exposure;
    hardware.cameras.gain = hardware.cameras.gain && support.gain;
  }
  return hardware;
}

std::expected<Settings, std::string> Settings::load(const fs::path& stateDir, config::Board board,
                                                    Hardware hardware, std::string& report) {
  Settings settings(stateDir, std::move(board), hardware);
  if (stateDir.empty()) {
    return settings;
  }
  std::error_code ec;
  if (!fs::is_directory(stateDir, ec)) {
    return std::unexpected("state directory " + stateDir.string() + " is not a directory");
  }
  const fs::path file = stateDir / kConfigFile;
  if (device::removeInterruptedWrite(file)) {
    report += "removed " + file.string() + ".tmp, left by an interrupted write\n";
  }
  if (!fs::exists(file, ec)) {
    return settings;
  }
  // Written whole or not at all, so a bad file is one the board no longer accepts (another
  // board.json, a hand edit): the device still starts, with the board's settings.
  auto stored = config::loadDeviceConfig(file, settings.board_);
  std::expected<void, std::string> fits =
      stored ? checkSettings(*stored, settings.board_, settings.hardware_)
             : std::expected<void, std::string>{};
  if (!stored || !fits) {
    const fs::path rejected = stateDir / "config.json.rejected";
    fs::rename(file, rejected, ec);
    report += file.string() + ": " + (stored ? fits.error() : fieldMessage(stored.error())) +
              "; running with the board's settings (the file is kept as " + rejected.string() +
              ")\n";
    return settings;
  }
  settings.stored_ = *stored;
  settings.previous_ = *stored;
  return settings;
}

device::DeviceOptions Settings::deviceOptions(device::DeviceOptions base) const {
  const config::Board running = board();
  base.pipeline = pipelineOptions(stored_, running, base.pipeline);
  // Bit c: protocol::Compression c (0 none, 1 RVL).
  switch (stored_.compression.value_or(config::Compression::kAny)) {
    case config::Compression::kRvl:
      base.compressionsMask = 1U << 1U;
      break;
    case config::Compression::kNone:
      base.compressionsMask = 1U << 0U;
      break;
    case config::Compression::kAny:
      break;
  }
  base.configJson = config::effectiveJson(stored_, board_);
  return base;
}

std::expected<std::string, std::string> Settings::change(const protocol::SetConfig& request) {
  if (stateDir_.empty()) {
    return std::unexpected("this device keeps no settings (stripemuxd runs without --state)");
  }
  const bool reset = request.mode == protocol::SetConfigMode::kReset;
  const config::DeviceConfig base = reset ? config::DeviceConfig{} : stored_;
  config::DeviceConfig change;
  if (!(reset && request.json.empty())) {
    auto parsed = config::parseDeviceConfig(request.json, board_, base);
    if (!parsed) {
      return std::unexpected(fieldMessage(parsed.error()));
    }
    change = std::move(*parsed);
  }
  const config::DeviceConfig next = config::merged(base, change);
  if (auto fits = checkSettings(next, board_, hardware_); !fits) {
    return std::unexpected(fits.error());
  }
  if (auto stored = store(next); !stored) {
    return std::unexpected(stored.error());
  }
  return config::effectiveJson(stored_, board_);
}

std::expected<void, std::string> Settings::revert() {
  return store(previous_);
}

std::expected<void, std::string> Settings::store(const config::DeviceConfig& next) {
  if (auto written =
          device::writeStateFile(stateDir_ / kConfigFile, config::toJson(next), "config");
      !written) {
    return std::unexpected("the settings were not stored: " + written.error());
  }
  previous_ = std::exchange(stored_, next);
  return {};
}

std::string Settings::describe() const {
  std::string keys;
  for (const std::string_view key : config::setKeys(stored_)) {
    keys += (keys.empty() ? "" : ", ") + std::string(key);
  }
  if (keys.empty()) {
    return stateDir_.empty() ? "the board's (no state directory)" : "the board's";
  }
  return (stateDir_ / kConfigFile).string() + " (" + keys + ")";
}

}  // namespace smx::firmware
