#pragma once

#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/config/board_json.hpp"
#include "smx/config/json_errors.hpp"

// config.json, format `stripemux-config/1` (docs/config.md): what an owner changes on a device
// over its board.json, kept in the device's state directory. Every setting is optional; an absent
// one is the board's. The same document is a request to change settings: its keys replace the
// stored ones, the others stay. Init-time code (allocates); never throws.
namespace smx::config {

inline constexpr std::string_view kDeviceConfigFormat = "stripemux-config/1";
// Bounds the request and the stored file: a rig.json is a few KiB.
inline constexpr std::size_t kDeviceConfigMaxBytes = std::size_t{1} << 16U;

// What range frames may travel as: the host picks from `kAny` (RVL unless told otherwise).
enum class Compression : std::uint8_t { kAny, kRvl, kNone };

// exposureUs and gain: 0 is "the camera's own", as set, so that a change can go back to it.
struct DeviceConfig {
  std::optional<int> fps;         // camera frame rate, 1…120
  std::optional<int> exposureUs;  // every camera's exposure time, 1…1 000 000 µs
  std::optional<double> gain;     // every camera's sensor gain, 1…64
  std::optional<std::vector<std::string>> projectors;  // lit and decoded, in the rig's order
  std::optional<int> projectorPower;                   // percent of full, 1…100
  std::optional<Compression> compression;              // what the device sends range frames as
  std::optional<double> depthMinM;                     // depths nearer are dropped
  std::optional<double> depthMaxM;                     // depths farther are dropped
  std::optional<int> confidenceMin;                    // depths less confident are dropped, 1…255
  std::optional<algo::Rig> rig;  // the rig the device decodes with (a calibration)
};

// The settings keys, in the order documents list them.
[[nodiscard]] std::span<const std::string_view> deviceConfigKeys();

// Parses and checks `text` against `board`: every value in range, a rig with the board's cameras
// (ids, sizes) and projectors (ids, patterns' order), and a depth window the board's depth unit
// can hold with min < max once combined with `stored` (the settings it would be merged with).
[[nodiscard]] std::expected<DeviceConfig, FieldError> parseDeviceConfig(
    std::string_view text, const Board& board, const DeviceConfig& stored = {});

// Reads `file` and parses it against `board`; an unreadable file is an error with no field.
[[nodiscard]] std::expected<DeviceConfig, FieldError> loadDeviceConfig(
    const std::filesystem::path& file, const Board& board);

// The text of a config.json file, its size checked before it is read (no field in the error).
[[nodiscard]] std::expected<std::string, FieldError> readDeviceConfigText(
    const std::filesystem::path& file);

// The keys `config` sets, in deviceConfigKeys() order.
[[nodiscard]] std::vector<std::string_view> setKeys(const DeviceConfig& config);

// `stored` with every setting `change` has replaced.
[[nodiscard]] DeviceConfig merged(DeviceConfig stored, const DeviceConfig& change);

// The settings as a config.json document (only those set).
[[nodiscard]] std::string toJson(const DeviceConfig& config);

// Every setting as the device runs with it: `config`'s where set, the board's otherwise.
[[nodiscard]] std::string effectiveJson(const DeviceConfig& config, const Board& board);

// `board` as the device runs it with `config`: every camera's frame rate and controls, the
// projectors lit and their power, and the rig.
[[nodiscard]] Board appliedTo(const DeviceConfig& config, Board board);

// The projectors a range capture of `board` lights (bit i: the rig's projector i), and the rig
// its range images are decoded with: only those projectors, so that the demultiplexer looks for
// no pattern that is not there.
[[nodiscard]] std::uint32_t rangeProjectorsMask(const Board& board);
[[nodiscard]] algo::Rig rangeRig(const Board& board);

}  // namespace smx::config
