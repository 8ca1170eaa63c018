#include <algorithm>

#include "bundle_layout.hpp"
#include "smx/update/bundle.hpp"

namespace smx::update {

std::expected<void, UpdateError> checkBundleShape(std::span<const std::byte> bytes) {
  const auto matches = [&](std::size_t at, const std::array<char, 8>& magic) {
    return std::ranges::equal(bytes.subspan(at, magic.size()), magic,
                              [](std::byte b, char c) { return b == static_cast<std::byte>(c); });
  };
  if (bytes.size() < kHeaderSize + kTrailerSize) {
    return std::unexpected(UpdateError{
        UpdateReason::kTruncated,
        std::to_string(bytes.size()) + " bytes, shorter than a bundle's " +
            std::to_string(kHeaderSize + kTrailerSize) + " bytes of header and trailer"});
  }
  if (bytes.size() > kMaxBundleSize) {
    return std::unexpected(UpdateError{
        UpdateReason::kTooLarge, std::to_string(bytes.size()) + " bytes, more than the limit of " +
                                     std::to_string(kMaxBundleSize)});
  }
  if (!matches(0, layout::kMagic)) {
    return std::unexpected(
        UpdateError{UpdateReason::kMalformed, "not a stripemux bundle (no SMXBNDL1 magic)"});
  }
  if (!matches(bytes.size() - layout::kEndMagic.size(), layout::kEndMagic)) {
    return std::unexpected(UpdateError{UpdateReason::kTruncated,
                                       "the bundle's end (SMXSIGN1) is missing: truncated?"});
  }
  return {};
}

}  // namespace smx::update
