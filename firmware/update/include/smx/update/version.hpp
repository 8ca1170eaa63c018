#pragma once

#include <compare>
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>

#include "smx/update/update_error.hpp"

namespace smx::update {

// MAJOR.MINOR.PATCH, each a decimal number without leading zeros, at most 999999.
struct Version {
  std::uint32_t major = 0;
  std::uint32_t minor = 0;
  std::uint32_t patch = 0;
  auto operator<=>(const Version&) const = default;
};

[[nodiscard]] std::expected<Version, UpdateError> parseVersion(std::string_view text,
                                                               std::string_view field);
[[nodiscard]] std::string toString(const Version& version);

}  // namespace smx::update
