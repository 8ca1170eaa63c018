#pragma once

#include <cstdint>
#include <expected>
#include <filesystem>
#include <string>

#include "smx/device/device.hpp"
#include "smx/hal/unique_fd.hpp"

// The daemon's side of a firmware update (docs/update.md): the upload into
// DIR/upload.partial, verification against DIR/keys, the slot, the boot record and the switch;
// and, in a slot on trial, the self-test that marks it good.
namespace smx::firmware {

// The daemon's exit code after installing an update: the supervisor starts the new slot.
inline constexpr int kExitUpdated = 10;

class UpdateService {
 public:
  // `stateDir` empty or not `supervised`: updates are refused (nothing would start the new
  // slot). `board` is the board's name, checked against the bundle's list.
  UpdateService(std::filesystem::path stateDir, std::string board, bool supervised);

  // The slot this firmware runs from ("factory" without an active link) and its version.
  [[nodiscard]] const std::string& runningSlot() const { return slot_; }
  [[nodiscard]] const std::string& runningVersion() const { return version_; }
  // True when this start is a slot's trial: the self-test must mark it good.
  [[nodiscard]] bool onTrial() const { return onTrial_; }
  [[nodiscard]] device::UpdateHooks hooks();
  // The self-test of a slot on trial (one capture decoded), then the mark in boot.json.
  [[nodiscard]] std::expected<void, std::string> selfTestAndMarkGood(device::Device& device);

 private:
  [[nodiscard]] std::expected<void, std::string> begin(std::uint64_t size);
  [[nodiscard]] std::expected<void, std::string> append(std::span<const std::byte> bytes);
  [[nodiscard]] std::expected<void, std::string> install(
      const device::UpdateHooks::Progress& progress);
  [[nodiscard]] device::UpdateStatusInfo status() const;

  std::filesystem::path dir_;
  std::string board_;
  bool enabled_;
  std::string slot_ = "factory";
  std::string version_;
  bool onTrial_ = false;
  hal::UniqueFd upload_;
};

}  // namespace smx::firmware
