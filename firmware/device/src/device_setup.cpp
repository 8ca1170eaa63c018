// Device::create: everything the loops need, allocated once.
#include <algorithm>
#include <cmath>

#include "smx/config/device_config.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/device/device.hpp"

namespace smx::device {

namespace {
using Fail = std::unexpected<std::string>;
constexpr std::size_t kControlBytes = 4096;  // replies besides the capabilities
// A set-config's settings, and the config message that answers it.
constexpr std::size_t kConfigBytes = config::kDeviceConfigMaxBytes + 64;
static_assert(kConfigBytes >= protocol::kFlashChunkBytes, "a flash-data chunk fits the parser");
}  // namespace

Device::Device(const config::Board& board, hal::Hal hal, const DeviceOptions& options)
    : hal_(hal),
      options_(options),
      depthUnitNm_(static_cast<std::uint32_t>(std::lround(board.config.depthUnitM * 1e9))),
      allProjectorsMask_(static_cast<std::uint32_t>((1U << board.rig.projectors.size()) - 1U)),
      rangeProjectorsMask_(config::rangeProjectorsMask(board)),
      leadNs_(board.config.trigger.leadNs),
      startNs_(hal.clock.nowNs()),
      // Each camera's decoder may hold a slot while writing, besides the queued frames. Every
      // slot has room for the confidence plane: a host may ask for it at any start.
      queue_(options.queueSlots + board.rig.cameras.size() + 1,
             protocol::rangeFrameBound(board.rig.cameras.front().width,
                                       board.rig.cameras.front().height, true)),
      parser_(kConfigBytes) {}

// A capture still decoding uses the queue and the counters, which go before the decoding thread.
Device::~Device() {
  finishCapture();
}

std::expected<std::unique_ptr<Device>, std::string> Device::create(const config::Board& board,
                                                                   hal::Hal hal,
                                                                   const DeviceOptions& options) {
  const algo::Rig& rig = board.rig;
  if (options.compressionsMask == 0 || options.configJson.size() > kConfigBytes) {
    return Fail("device options: no compression allowed, or settings beyond " +
                std::to_string(kConfigBytes) + " bytes");
  }
  if (hal.cameras.size() != rig.cameras.size() || rig.cameras.empty()) {
    return Fail("the board has " + std::to_string(hal.cameras.size()) +
                " cameras but its rig has " + std::to_string(rig.cameras.size()));
  }
  for (const auto& camera : rig.cameras) {
    if (camera.width != rig.cameras.front().width || camera.height != rig.cameras.front().height) {
      return Fail("the cameras of a board must share one image size (camera " + camera.id + ")");
    }
  }
  auto device = std::unique_ptr<Device>(new Device(board, hal, options));
  if (device->rangeProjectorsMask_ == 0) {
    return Fail("projectors: none of the chosen projectors is on the board");
  }
  if (auto power = hal.trigger.setPower(board.config.trigger.powerPercent); !power) {
    return Fail(std::string("projector_power: ") + power.error().message);
  }
  const algo::Rig decodeRig = config::rangeRig(board);
  algo::PipelineOptions pipelineOptions = options.pipeline;
  pipelineOptions.depthUnitM = board.config.depthUnitM;
  device->cameras_.resize(rig.cameras.size());
  device->frames_.resize(rig.cameras.size());
  device->next_.resize(rig.cameras.size());
  const auto cameraCount = static_cast<int>(rig.cameras.size());
  const int threads = options.decodeThreads > 0  ? options.decodeThreads
                      : board.config.threads > 0 ? board.config.threads
                                                 : cameraCount;
  // The cameras decode in parallel; threads beyond one per camera split each camera's frame
  // (its projectors on lanes, its merge in bands) on a pool of the camera's own.
  const int perCamera = std::max(1, threads / cameraCount);
  device->workers_ = std::make_unique<WorkerPool>(std::min(threads, cameraCount) - 1);
  pipelineOptions.lanes = perCamera;
  if (options.pipelined || board.config.pipelined) {
    device->decoding_ = std::make_unique<BackgroundJob>();
  }
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const std::string& id = rig.cameras[i].id;
    const auto setup = algo::prepareCameraPipeline(decodeRig, static_cast<int>(i), pipelineOptions);
    if (!setup) {
      return Fail("camera " + id + ": " + setup.error());
    }
    const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
    if (!bytes) {
      return Fail("camera " + id + ": " + bytes.error().message);
    }
    CameraSlot& slot = device->cameras_[i];
    slot.jobs = std::make_unique<WorkerPool>(perCamera - 1);
    slot.memory.resize(*bytes);
    slot.arena = std::make_unique<algo::Arena>(slot.memory);
    auto pipeline = algo::CameraPipeline::create(*setup, *slot.arena);
    if (!pipeline) {
      return Fail("camera " + id + ": " + pipeline.error().message);
    }
    slot.pipeline = std::make_unique<algo::CameraPipeline>(*pipeline);

    hal::Camera& camera = *hal.cameras[i];
    const auto format = camera.configure(board.config.cameras[i].format);
    if (!format) {
      return Fail("camera " + id + ": cannot configure " + board.config.cameras[i].device + ": " +
                  format.error().message);
    }
    const std::int64_t periodNs = 1'000'000'000 / std::max(1, format->fps);
    device->framePeriodNs_ = i == 0 ? periodNs : std::min(device->framePeriodNs_, periodNs);
    if (const auto set = camera.setControls(board.config.cameras[i].controls); !set) {
      return Fail("camera " + id + ": exposure or gain: " + set.error().message);
    }
    if (const auto started = camera.start(); !started) {
      return Fail("camera " + id + ": cannot start streaming: " + started.error().message);
    }
  }

  const std::string rigJson = config::toJson(rig);
  const protocol::Capabilities caps{
      .board = board.config.name,
      .firmwareVersion = options.firmwareVersion,
      .halBackend = hal::halBackend(),
      .depthUnitNm = device->depthUnitNm_,
      .cameras = static_cast<std::uint8_t>(rig.cameras.size()),
      .projectors = static_cast<std::uint8_t>(rig.projectors.size()),
      .width = static_cast<std::uint16_t>(rig.cameras.front().width),
      .height = static_cast<std::uint16_t>(rig.cameras.front().height),
      .fps = static_cast<std::uint16_t>(board.config.cameras.front().format.fps),
      .compressionsMask = options.compressionsMask,
      .rigJson = rigJson};
  device->capabilities_.resize(protocol::kHeaderBytes + 1024 + rigJson.size());
  const auto encoded = protocol::encode(caps, device->capabilities_);
  if (!encoded) {
    return Fail(std::string("capabilities: ") + encoded.error().message);
  }
  device->capabilities_.resize(encoded->size());
  device->control_.resize(device->capabilities_.size() + kControlBytes + 2 * kConfigBytes);
  // Every camera's bands of one raw capture, or the error that replaces them.
  device->raw_.resize(std::max<std::size_t>(
      kControlBytes, rig.cameras.size() * protocol::rawFrameBound(rig.cameras.front().width,
                                                                  rig.cameras.front().height)));
  return device;
}

std::size_t Device::arenaBytes() const {
  std::size_t total = 0;
  for (const CameraSlot& slot : cameras_) {
    total += slot.memory.size();
  }
  return total;
}

}  // namespace smx::device
