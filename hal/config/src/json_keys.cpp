#include "smx/config/json_keys.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "smx/config/json_text.hpp"

namespace smx::config {
namespace {

std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t replace = diagonal + (a[i - 1] == b[j - 1] ? 0U : 1U);
      row[j] = std::min({above + 1, row[j - 1] + 1, replace});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

bool equalIgnoringCase(std::string_view a, std::string_view b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) ==
           std::tolower(static_cast<unsigned char>(y));
  });
}

std::string_view closestWord(std::string_view word, Keys allowed) {
  std::string_view best;
  std::size_t bestDistance = 3;  // only suggest within two edits ...
  for (const auto candidate : allowed) {
    if (equalIgnoringCase(word, candidate)) {
      return candidate;
    }
    const bool prefix = std::min(word.size(), candidate.size()) >= 3 &&
                        (word.starts_with(candidate) || candidate.starts_with(word));
    const std::size_t d = prefix ? 1 : editDistance(word, candidate);
    if (d < bestDistance &&
        2 * d < word.size()) {  // ... and fewer than half the word: not "fx"->"id"
      best = candidate;
      bestDistance = d;
    }
  }
  return best;
}

std::optional<std::string> unknownKey(const nlohmann::json& obj, Keys allowed) {
  for (const auto& [key, value] : obj.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      return key;
    }
  }
  return std::nullopt;
}

std::string unknownKeyProblem(std::string_view key, Keys allowed, std::string_view hint) {
  std::string problem = "unknown key " + jsonQuote(key);
  if (!hint.empty()) {
    problem += " (" + std::string(hint) + ")";
  } else if (const auto guess = closestWord(key, allowed); !guess.empty()) {
    problem += " (did you mean " + jsonQuote(guess) + "?)";
  }
  return problem + "; allowed keys: " + joined(allowed);
}

}  // namespace smx::config
