#include "update_service.hpp"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <optional>
#include <system_error>

#include "smx/device/state_file.hpp"
#include "smx/update/bundle.hpp"
#include "smx/update/slots.hpp"

namespace smx::firmware {
namespace {

namespace fs = std::filesystem;
using protocol::FlashStep;

constexpr const char* kUpload = "upload.partial";
// Captures the self-test tries before it gives up (a few seconds at the board's rate).
constexpr int kSelfTestCaptures = 50;

std::string systemError(const std::string& what) {
  return what + ": " + std::generic_category().message(errno);
}

std::string updateError(const update::UpdateError& e) {
  return std::string(update::reasonName(e.reason)) + ": " + e.message;
}

}  // namespace

UpdateService::UpdateService(fs::path stateDir, std::string board, bool supervised)
    : dir_(std::move(stateDir)),
      board_(std::move(board)),
      enabled_(!dir_.empty() && supervised),
      version_(SMX_VERSION) {
  if (dir_.empty()) {
    return;
  }
  const auto active = update::activeSlot(dir_);
  const std::optional<std::string> slot = active.value_or(std::nullopt);
  if (!slot.has_value()) {
    return;
  }
  slot_ = *slot;
  if (const auto manifest = update::readSlotManifest(dir_, slot_)) {
    version_ = update::toString(manifest->version);
  }
  const auto record = update::readBootRecord(dir_);
  onTrial_ = record && record->pending == slot_ && !record->markedGood;
  if (onTrial_) {
    device::crashPoint("update.first-start");
  }
}

device::UpdateHooks UpdateService::hooks() {
  if (!enabled_) {
    return {};
  }
  return {.begin = [this](std::uint64_t size) { return begin(size); },
          .data = [this](std::span<const std::byte> bytes) { return append(bytes); },
          .end = [this](const device::UpdateHooks::Progress& p) { return install(p); },
          .status = [this] { return status(); }};
}

std::expected<void, std::string> UpdateService::begin(std::uint64_t size) {
  if (size == 0 || size > update::kMaxBundleSize) {
    return std::unexpected("flash-begin: a bundle of " + std::to_string(size) +
                           " bytes; the limit is " + std::to_string(update::kMaxBundleSize));
  }
  // The upload and the extracted slot are on the disk together.
  struct statvfs fsStat {};
  if (::statvfs(dir_.c_str(), &fsStat) != 0) {
    return std::unexpected(systemError("statvfs " + dir_.string()));
  }
  const std::uint64_t free = static_cast<std::uint64_t>(fsStat.f_bavail) * fsStat.f_frsize;
  if (free / 2 < size) {
    return std::unexpected("flash-begin: a bundle of " + std::to_string(size) + " bytes needs " +
                           std::to_string(2 * size) + " bytes free in " + dir_.string() +
                           ", there are " + std::to_string(free));
  }
  const fs::path file = dir_ / kUpload;
  upload_.reset(::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600));
  if (!upload_.valid()) {
    return std::unexpected(systemError("cannot create " + file.string()));
  }
  return {};
}

std::expected<void, std::string> UpdateService::append(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const auto n = ::write(upload_.get(), bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) {
      continue;
    }
    if (n <= 0) {
      upload_.reset();
      return std::unexpected(systemError("cannot write " + (dir_ / kUpload).string()));
    }
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return {};
}

std::expected<void, std::string> UpdateService::install(
    const device::UpdateHooks::Progress& progress) {
  const fs::path file = dir_ / kUpload;
  if (::fsync(upload_.get()) != 0) {
    return std::unexpected(systemError("cannot flush " + file.string()));
  }
  upload_.reset();
  device::crashPoint("update.received");
  progress(FlashStep::kReceived, "received");

  auto keys = update::readTrustedKeys(dir_);
  if (!keys) {
    return std::unexpected("trusted keys: " + updateError(keys.error()));
  }
  if (keys->empty()) {
    return std::unexpected(
        "this device trusts no key: install the public key of the bundles' "
        "signer as " +
        (dir_ / "keys" / "NAME.pub").string() + " (stripemux keygen writes one) and restart it");
  }
  auto installed = update::parseVersion(version_, "running version");
  if (!installed) {
    return std::unexpected(updateError(installed.error()));
  }
  // The bundle is read into memory whole to be verified (docs/update.md#upload).
  auto bundle = update::verifyBundleFile(file, *keys, {.board = board_, .installed = *installed});
  if (!bundle) {
    return std::unexpected(updateError(bundle.error()));
  }
  const std::string version = update::toString(bundle->info().version);
  device::crashPoint("update.verified");
  progress(FlashStep::kVerified, "verified " + version + " for board " + board_);

  auto active = update::activeSlot(dir_);
  if (!active) {
    return std::unexpected(updateError(active.error()));
  }
  const std::string slot = update::inactiveSlot(*active);
  if (auto written = update::writeSlot(dir_, slot, *bundle); !written) {
    return std::unexpected(updateError(written.error()));
  }
  device::crashPoint("update.slot-written");
  if (auto synced = update::syncDirectory(dir_ / "slots"); !synced) {
    return std::unexpected(updateError(synced.error()));
  }
  device::crashPoint("update.slot-synced");
  progress(FlashStep::kSlotWritten, "written to slot " + slot);

  const update::BootRecord record{.previous = active->value_or(""),
                                  .pending = slot,
                                  .tries = 0,
                                  .markedGood = false,
                                  .outcome = update::UpdateOutcome::kNone,
                                  .reason = "",
                                  .version = version};
  if (auto recorded = update::writeBootRecord(dir_, record); !recorded) {
    return std::unexpected(updateError(recorded.error()));
  }
  device::crashPoint("update.pending-recorded");
  if (auto switched = update::switchActive(dir_, slot); !switched) {
    return std::unexpected(updateError(switched.error()));
  }
  device::crashPoint("update.switched");
  ::unlink(file.c_str());
  progress(FlashStep::kSwitched, "slot " + slot + " is active, on trial");
  progress(FlashStep::kRestarting, "restarting into " + version);
  return {};
}

device::UpdateStatusInfo UpdateService::status() const {
  device::UpdateStatusInfo info;
  info.runningSlot = slot_;
  info.runningVersion = version_;
  if (const auto record = update::readBootRecord(dir_)) {
    info.outcome = static_cast<protocol::UpdateOutcomeCode>(record->outcome);
    info.updateVersion = record->version;
    info.reason = record->reason;
  } else {
    info.reason = updateError(record.error());
  }
  return info;
}

std::expected<void, std::string> UpdateService::selfTestAndMarkGood(device::Device& device) {
  for (int i = 0; i < kSelfTestCaptures && device.counters().framesDecoded == 0; ++i) {
    (void)device.captureOnce();
  }
  if (device.counters().framesDecoded == 0) {
    return std::unexpected("self-test: no capture decoded in " + std::to_string(kSelfTestCaptures) +
                           " tries");
  }
  auto record = update::readBootRecord(dir_);
  if (!record) {
    return std::unexpected("boot.json: " + record.error().message);
  }
  device::crashPoint("update.before-mark-good");
  record->pending.clear();
  record->tries = 0;
  record->markedGood = true;
  record->outcome = update::UpdateOutcome::kInstalled;
  record->reason.clear();
  if (auto written = update::writeBootRecord(dir_, *record); !written) {
    return std::unexpected("boot.json: " + written.error().message);
  }
  onTrial_ = false;
  return {};
}

}  // namespace smx::firmware
