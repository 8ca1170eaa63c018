#pragma once

#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "smx/update/bundle.hpp"
#include "smx/update/file_io.hpp"
#include "smx/update/keys.hpp"
#include "smx/update/update_error.hpp"

// The firmware slots of a state directory (docs/update.md#slots):
//   DIR/slots/<id>/        an extracted, verified bundle, with its manifest as slot.json
//   DIR/active             symlink to slots/<id>; none: the factory firmware
//   DIR/boot.json          the boot record (BootRecord), written atomically
//   DIR/keys/*.pub         the trusted public keys
// Slot ids are "a" and "b", chosen here, never taken from a bundle.
namespace smx::update {

inline constexpr const char* kSlotIds[] = {"a", "b"};
inline constexpr const char* kSlotManifest = "slot.json";

enum class UpdateOutcome : std::uint8_t { kNone = 0, kInstalled = 1, kRolledBack = 2 };
[[nodiscard]] const char* toString(UpdateOutcome outcome);

// What the supervisor and the firmware agree on across restarts and crashes.
struct BootRecord {
  std::string previous;  // the slot to go back to ("": the factory firmware)
  std::string pending;   // the slot on trial ("": none)
  int tries = 0;         // starts of the pending slot so far
  bool markedGood = true;
  UpdateOutcome outcome = UpdateOutcome::kNone;  // of the last update
  std::string reason;                            // why it was rolled back
  std::string version;                           // the last update's version
  auto operator<=>(const BootRecord&) const = default;
};

[[nodiscard]] bool isSlotId(std::string_view id);
// The other slot than `active` (the one an update is written to).
[[nodiscard]] std::string inactiveSlot(const std::optional<std::string>& active);

// A missing boot.json is the default record; a malformed one is an error naming the field.
[[nodiscard]] std::expected<BootRecord, UpdateError> readBootRecord(
    const std::filesystem::path& dir);
[[nodiscard]] std::string bootRecordJson(const BootRecord& record);
[[nodiscard]] std::expected<BootRecord, UpdateError> parseBootRecord(std::string_view text);
[[nodiscard]] std::expected<void, UpdateError> writeBootRecord(const std::filesystem::path& dir,
                                                               const BootRecord& record,
                                                               const StepHook& onStep = {});

// The slot `active` points to; nullopt for none (factory). A link to anything but slots/a or
// slots/b is an error.
[[nodiscard]] std::expected<std::optional<std::string>, UpdateError> activeSlot(
    const std::filesystem::path& dir);
// Points `active` at slots/<id> (a new link active.tmp renamed over it, the directory fsynced),
// or removes it for nullopt (the factory firmware).
[[nodiscard]] std::expected<void, UpdateError> switchActive(const std::filesystem::path& dir,
                                                            const std::optional<std::string>& id);

// The slot's version and boards as its slot.json records them; an error for an incomplete slot.
[[nodiscard]] std::expected<BundleInfo, UpdateError> readSlotManifest(
    const std::filesystem::path& dir, const std::string& id);
// Removes the slot (and what an interrupted extraction left), then extracts the bundle into it
// and writes slot.json; everything is fsynced.
[[nodiscard]] std::expected<void, UpdateError> writeSlot(const std::filesystem::path& dir,
                                                         const std::string& id,
                                                         const VerifiedBundle& bundle);

// Every DIR/keys/*.pub. An unreadable key file is an error naming it.
[[nodiscard]] std::expected<std::vector<PublicKey>, UpdateError> readTrustedKeys(
    const std::filesystem::path& dir);

}  // namespace smx::update
