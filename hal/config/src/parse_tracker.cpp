#include "parse_tracker.hpp"

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "smx/config/json_paths.hpp"
#include "smx/config/json_text.hpp"

namespace smx::config {

bool ParseTracker::onEvent(nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
  using E = nlohmann::json::parse_event_t;
  switch (event) {
    case E::object_start:
    case E::array_start:
      valueStarts();
      stack_.push_back({event == E::array_start, 0, {}, {}});
      break;
    case E::object_end:
    case E::array_end:
      stack_.pop_back();
      break;
    case E::key:
      if (!stack_.empty()) {
        Frame& f = stack_.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second && !duplicate_) {
          duplicate_ = FieldError{pathTo(stack_.size() - 1),
                                  "key " + jsonQuote(f.key) + " appears more than once"};
        }
      }
      break;
    case E::value:
      valueStarts();
      break;
  }
  return true;
}

std::string ParseTracker::currentPath() const {
  if (stack_.empty()) {
    return {};
  }
  const Frame& f = stack_.back();
  const std::string parent = pathTo(stack_.size() - 1);
  return f.isArray ? element(parent, f.count) : member(parent, f.key);
}

void ParseTracker::valueStarts() {
  if (!stack_.empty() && stack_.back().isArray) {
    ++stack_.back().count;
  }
}

std::string ParseTracker::pathTo(std::size_t depth) const {
  std::string path;
  for (std::size_t i = 0; i < depth; ++i) {
    const Frame& f = stack_[i];
    path = f.isArray ? element(path, f.count - 1) : member(path, f.key);
  }
  return path;
}

}  // namespace smx::config
