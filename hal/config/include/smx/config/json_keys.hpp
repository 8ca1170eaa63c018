#pragma once

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

// Unknown keys are errors, not ignored: a misspelt optional key would otherwise fall back to its
// default without a word. The message names the allowed keys and the one the user probably meant.
namespace smx::config {

// The keys (or other words) allowed at one place of a document.
using Keys = std::span<const std::string_view>;

[[nodiscard]] bool equalIgnoringCase(std::string_view a, std::string_view b);

// The allowed word the user probably meant ("k" -> "K", "strip_px" -> "stripe_px", "colors" ->
// "colours"): the same word in another case, a prefix of at least 3 characters, or the nearest
// within two edits and fewer than half the word ("fx" is not "id"). Empty when nothing is close.
[[nodiscard]] std::string_view closestWord(std::string_view word, Keys allowed);

// The first key of the object `obj` that is not allowed.
[[nodiscard]] std::optional<std::string> unknownKey(const nlohmann::json& obj, Keys allowed);

// `unknown key "k" (did you mean "K"?); allowed keys: ...`. A non-empty `hint` replaces the
// suggestion: `unknown key "pattern" (cameras have no pattern); allowed keys: ...`.
[[nodiscard]] std::string unknownKeyProblem(std::string_view key, Keys allowed,
                                            std::string_view hint = {});

}  // namespace smx::config
