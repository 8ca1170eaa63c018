#include "smx/config/json_paths.hpp"

#include <cstddef>
#include <string>
#include <string_view>

namespace smx::config {

std::string member(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string element(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

}  // namespace smx::config
