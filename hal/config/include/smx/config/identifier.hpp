#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

// Ids of cameras, projectors and boards, from any file or the wire. They name output files
// (DIR/<id>.png) and appear on terminals, so they are names and never paths: 1 to 32 characters
// of A-Z a-z 0-9 _ - ., starting with a letter or digit (docs/rig-format.md). That excludes
// "..", "/", NUL, control characters and escape sequences by construction.
namespace smx::config {

inline constexpr std::size_t kMaxIdentifierLength = 32;

// The alphabet, for names built from ids (output file names) that follow the same rule.
[[nodiscard]] constexpr bool isIdentifierStart(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}
[[nodiscard]] constexpr bool isIdentifierChar(char c) {
  return isIdentifierStart(c) || c == '_' || c == '-' || c == '.';
}

// What is wrong with `id` as an identifier ("must start with a letter or digit, got \".x\""), or
// nothing when it is one.
[[nodiscard]] std::optional<std::string> identifierProblem(std::string_view id);

}  // namespace smx::config
