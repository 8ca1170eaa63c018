#pragma once

#include <cstdio>
#include <string>

// printf-style text for messages (g++ 12 has no <format>).
namespace smx::text {

template <class... Args>
[[nodiscard]] std::string printfText(const char* format, Args... args) {
  const int size = std::snprintf(nullptr, 0, format, args...);
  if (size <= 0) {
    return {};
  }
  std::string text(static_cast<std::size_t>(size) + 1, '\0');
  std::snprintf(text.data(), text.size(), format, args...);
  text.pop_back();
  return text;
}

}  // namespace smx::text
