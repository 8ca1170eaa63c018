#pragma once

#include <optional>
#include <string_view>

// The page's files (web/), compiled in so that the tool serves the page it was built with.
namespace smx::view {

struct WebAsset {
  std::string_view contentType;
  std::string_view body;
};

// index.html, view.js, style.css; nullopt for any other name.
[[nodiscard]] std::optional<WebAsset> webAsset(std::string_view name);

}  // namespace smx::view
