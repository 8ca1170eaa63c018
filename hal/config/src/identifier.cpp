#include "smx/config/identifier.hpp"

#include <nlohmann/json.hpp>

namespace smx::config {
namespace {

// The id as JSON with every non-ASCII byte escaped, cut to a readable length: the message
// itself must carry no control characters or escape sequences.
std::string shown(std::string_view id) {
  constexpr std::size_t kMaxShown = 40;
  const std::string_view cut = id.substr(0, kMaxShown);
  return nlohmann::json(std::string(cut))
             .dump(-1, ' ', true, nlohmann::json::error_handler_t::replace) +
         (cut.size() < id.size() ? "..." : "");
}

}  // namespace

std::optional<std::string> identifierProblem(std::string_view id) {
  const std::string rule = "; ids are 1 to " + std::to_string(kMaxIdentifierLength) +
                           " characters of A-Z a-z 0-9 _ - . starting with a letter or digit";
  if (id.empty()) {
    return "must not be empty" + rule;
  }
  if (id.size() > kMaxIdentifierLength) {
    return "is " + std::to_string(id.size()) + " characters long" + rule;
  }
  if (!isIdentifierStart(id.front())) {
    return "must start with a letter or digit, got " + shown(id) + rule;
  }
  for (const char c : id) {
    if (!isIdentifierChar(c)) {
      return shown(id) + " has a character that is not allowed in an id" + rule;
    }
  }
  return std::nullopt;
}

}  // namespace smx::config
