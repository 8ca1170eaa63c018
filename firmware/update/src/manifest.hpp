#pragma once

#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "smx/update/bundle.hpp"

// The bundle's manifest JSON (docs/update.md#manifest), read only once its signature is checked.
namespace smx::update {

struct Manifest {
  Version version;
  std::vector<std::string> boards;
  bool allowDowngrade = false;
  std::vector<BundleFile> files;  // offsets filled in, in payload order
};

[[nodiscard]] std::expected<Manifest, UpdateError> parseManifest(std::string_view text);
[[nodiscard]] std::string manifestJson(const Manifest& manifest);

// Why `name` is not a bundle file name, or nothing when it is one.
[[nodiscard]] std::optional<std::string> nameProblem(std::string_view name);

}  // namespace smx::update
