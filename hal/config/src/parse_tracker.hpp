#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "smx/config/json_errors.hpp"

// Follows the JSON path while nlohmann parses, for two things nlohmann does not report by path:
// a duplicated key (nlohmann keeps the last one without a word; a second "t" is a mistake) and the
// value it stopped at (a number too large for a double ends the parse with "number overflow").
// Private to parseDocument().
namespace smx::config {

class ParseTracker {
 public:
  // The parser callback: records `event` and keeps every value (returns true).
  bool onEvent(nlohmann::json::parse_event_t event, const nlohmann::json& parsed);

  // The first key that appeared twice in one object, with the object's path.
  [[nodiscard]] const std::optional<FieldError>& duplicate() const { return duplicate_; }

  // The path of the value being read now (the one that made nlohmann stop).
  [[nodiscard]] std::string currentPath() const;

 private:
  // One path component per frame; whole paths are built only for an error, so deep nesting
  // costs linear memory, not quadratic.
  struct Frame {
    bool isArray;
    std::size_t count;  // elements started so far (arrays)
    std::string key;    // key being read (objects)
    std::set<std::string, std::less<>> keys;
  };

  void valueStarts();

  // Path of the container held by stack_[depth].
  [[nodiscard]] std::string pathTo(std::size_t depth) const;

  std::vector<Frame> stack_;
  std::optional<FieldError> duplicate_;
};

}  // namespace smx::config
