#include "smx/config/json_text.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>

namespace smx::config {

using Json = nlohmann::json;

std::string formatNumber(double v) {
  if (!std::isfinite(v)) {
    return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  }
  if (v == 0.0 && std::signbit(v)) {
    return "-0.0";  // "-0" would read back as the integer 0
  }
  const double magnitude = std::abs(v);
  const bool plain = magnitude == 0 || (magnitude >= 1e-4 && magnitude < 1e16);
  std::array<char, 64> buf{};
  const auto r =
      plain ? std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed)
            : std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return {buf.data(), r.ptr};
}

std::string formatDeviation(double v) {
  std::array<char, 32> buf{};
  const auto r =
      std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::general, 3);
  return {buf.data(), r.ptr};
}

std::string jsonQuote(std::string_view s) {
  return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string describe(const Json& v) {
  constexpr std::size_t kMaxShown = 40;
  switch (v.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return std::string("a boolean (") + (v.get<bool>() ? "true" : "false") + ")";
    case Json::value_t::string: {
      const auto& s = v.get_ref<const std::string&>();
      return "a string (" +
             (s.size() <= kMaxShown ? jsonQuote(s) : jsonQuote(s.substr(0, kMaxShown)) + "...") +
             ")";
    }
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " element" : " elements");
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return "a number (" + formatNumber(v.get<double>()) + ")";
    case Json::value_t::binary:
    case Json::value_t::discarded:
      break;
  }
  return "an unexpected value";
}

std::string joined(std::span<const std::string_view> words) {
  std::string out;
  for (const auto w : words) {
    out += (out.empty() ? "" : ", ") + std::string(w);
  }
  return out;
}

}  // namespace smx::config
