#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

#include "smx/algo/rig.hpp"

// rig.json, format `stripemux-rig/1`: read, validate and write a rig (docs/rig-format.md).
//
// Init-time code: allocates, uses double. parseRig(), loadRig() and validateRig() never throw
// (even on out-of-memory); every failure is a RigError naming the offending field.
namespace smx::config {

// The `format` value this build reads and writes.
inline constexpr std::string_view kRigFormat = "stripemux-rig/1";

struct RigError {
  std::string file;     // set by loadRig(); empty for text and in-memory rigs
  std::string field;    // JSON path, e.g. "projectors[1].R" or "cameras[0].K[4]"; empty = document
  std::string problem;  // what is wrong, for an end user, e.g. "must be a number, got a string"

  // "file: field: problem", leaving out the empty parts.
  [[nodiscard]] std::string message() const;
};

// Parses and validates a rig.json document and reports the first problem: JSON syntax, the
// format, duplicate keys, unknown top-level keys, then each camera and projector in order
// (unknown keys, types and array lengths first, then the value rules of validateRig()).
[[nodiscard]] std::expected<algo::Rig, RigError> parseRig(std::string_view jsonText);

// Reads `path` and parses it; an unreadable file is an error (RigError::file names it).
[[nodiscard]] std::expected<algo::Rig, RigError> loadRig(const std::filesystem::path& path);

// The value rules of rig.json applied to a rig built in memory (counts, ids, sizes, finite
// numbers, K structure, rotations, stripe width). parseRig() applies them after reading; call this
// before toJson() when the rig did not come from parseRig(). Field paths are as in the JSON.
[[nodiscard]] std::expected<void, RigError> validateRig(const algo::Rig& rig);

// Writes `rig` as rig.json text. Numbers are written as the shortest text that reads back to the
// same double, so parseRig(toJson(rig)) reproduces a valid rig exactly. Non-finite numbers are
// written as null (JSON has no NaN or infinity), which parseRig() rejects.
[[nodiscard]] std::string toJson(const algo::Rig& rig);

}  // namespace smx::config
