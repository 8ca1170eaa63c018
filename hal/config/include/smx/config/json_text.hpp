#pragma once

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <string_view>

// How values appear in error messages: numbers, quoted strings, "got ..." descriptions of what was
// found, lists of allowed words. One place, so every reader words them alike.
namespace smx::config {

// Shortest text that reads back to the same double: plain notation where people expect it
// (100000, 0.0125), exponent notation for the extremes; "-0.0" for negative zero ("-0" would read
// back as the integer 0), "nan", "inf" and "-inf" for the non-finite.
[[nodiscard]] std::string formatNumber(double v);

// Measured deviations (|R*R^T - I|, ...): three significant digits are plenty.
[[nodiscard]] std::string formatDeviation(double v);

// `s` as a JSON string literal; invalid UTF-8 is replaced, so the result is always printable.
[[nodiscard]] std::string jsonQuote(std::string_view s);

// What `v` is, for "got ..." in wrong-type messages: "a string ("800")", "an array of 8
// elements", "a number (1.5)", "null". Long strings are cut after 40 characters.
[[nodiscard]] std::string describe(const nlohmann::json& v);

// "a, b, c".
[[nodiscard]] std::string joined(std::span<const std::string_view> words);

}  // namespace smx::config
