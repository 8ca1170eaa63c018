#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

// Standard base64 with padding, as minisign writes it. Decoding accepts only the canonical text
// (what encoding the result gives back), so no two texts stand for the same bytes.
namespace smx::update {

[[nodiscard]] std::string toBase64(std::span<const std::uint8_t> bytes);
[[nodiscard]] std::optional<std::vector<std::uint8_t>> fromBase64(std::string_view text);

}  // namespace smx::update
