#pragma once

#include <cstddef>
#include <string>
#include <string_view>

// Field paths as the user reads them in an error: "projectors[1].R", "objects[0].pose.t[2]".
// Every reader builds them the same way, so messages about different files look alike.
namespace smx::config {

// `path`.`key`, or `key` alone at the top level (empty path).
[[nodiscard]] std::string member(const std::string& path, std::string_view key);

// `path`[`index`].
[[nodiscard]] std::string element(const std::string& path, std::size_t index);

}  // namespace smx::config
