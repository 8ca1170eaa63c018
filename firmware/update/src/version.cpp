#include "smx/update/version.hpp"

#include <array>

namespace smx::update {
namespace {

constexpr std::uint32_t kMaxPart = 999999;

std::expected<std::uint32_t, UpdateError> parsePart(std::string_view part, std::string_view text,
                                                    std::string_view field) {
  const auto bad = [&] {
    return std::unexpected(UpdateError{UpdateReason::kMalformed,
                                       std::string(field) + ": \"" + std::string(text) +
                                           "\" is not MAJOR.MINOR.PATCH (numbers 0..999999)"});
  };
  if (part.empty() || part.size() > 6 || (part.size() > 1 && part.front() == '0')) {
    return bad();
  }
  std::uint32_t value = 0;
  for (const char c : part) {
    if (c < '0' || c > '9') {
      return bad();
    }
    value = value * 10 + static_cast<std::uint32_t>(c - '0');
  }
  return value;
}

}  // namespace

std::expected<Version, UpdateError> parseVersion(std::string_view text, std::string_view field) {
  std::array<std::uint32_t, 3> parts{};
  std::string_view rest = text;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto dot = i + 1 < parts.size() ? rest.find('.') : std::string_view::npos;
    if (i + 1 < parts.size() && dot == std::string_view::npos) {
      return std::unexpected(UpdateError{
          UpdateReason::kMalformed,
          std::string(field) + ": \"" + std::string(text) + "\" is not MAJOR.MINOR.PATCH"});
    }
    const auto part = parsePart(rest.substr(0, dot), text, field);
    if (!part) {
      return std::unexpected(part.error());
    }
    parts[i] = *part;
    rest = dot == std::string_view::npos ? std::string_view{} : rest.substr(dot + 1);
  }
  static_assert(kMaxPart < 1000000);
  return Version{parts[0], parts[1], parts[2]};
}

std::string toString(const Version& version) {
  return std::to_string(version.major) + "." + std::to_string(version.minor) + "." +
         std::to_string(version.patch);
}

}  // namespace smx::update
