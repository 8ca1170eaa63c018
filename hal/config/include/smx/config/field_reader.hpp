#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"
#include "smx/config/json_paths.hpp"
#include "smx/config/json_text.hpp"

// Typed reads of configuration values with errors that name the field, shared by the readers of
// rig.json, board.json and scene.json.
namespace smx::config {

enum class Range : std::uint8_t { kAny, kPositive, kNonNegative, kFraction };

// Reads values into a document whose members already hold the defaults, and keeps the first
// problem: once one is found the remaining reads do nothing, so the reading code stays a plain
// sequence and the report is the first problem in reading order. Readers of one document kind
// (rig.json, board.json, scene.json) derive from it for their own types.
class FieldReader {
 public:
  [[nodiscard]] bool ok() const { return !error_.has_value(); }
  [[nodiscard]] const std::optional<FieldError>& firstError() const { return error_; }

  void fail(std::string field, std::string problem) {
    if (!error_) {
      error_ = FieldError{std::move(field), std::move(problem)};
    }
  }

  // `v` must be an object (`what`, for the message) holding only `allowed` keys; `hint` is said
  // about an unknown key when no allowed key is close to it.
  bool object(const nlohmann::json& v, const std::string& path, std::string_view what, Keys allowed,
              std::string_view hint = {}) {
    if (!ok()) {
      return false;
    }
    if (!v.is_object()) {
      fail(path, "must be an object (" + std::string(what) + "), got " + describe(v));
      return false;
    }
    if (const auto key = config::unknownKey(v, allowed)) {
      fail(path, config::unknownKeyProblem(*key, allowed, hint));
      return false;
    }
    return true;
  }

  // The value of an optional key, or nullptr when it is absent (or reading has failed).
  [[nodiscard]] const nlohmann::json* find(const nlohmann::json& obj, std::string_view key) const {
    if (!ok()) {
      return nullptr;
    }
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  std::optional<double> number(const nlohmann::json& v, const std::string& path, Range range) {
    if (!ok()) {
      return std::nullopt;
    }
    if (!v.is_number()) {
      fail(path, "must be a number, got " + describe(v));
      return std::nullopt;
    }
    const double d = v.get<double>();
    return check(d, path, range) ? std::optional<double>(d) : std::nullopt;
  }

  // The rule of `range` for a value already read: what number() says of the same value.
  bool check(double d, const std::string& path, Range range) {
    if (!ok()) {
      return false;
    }
    const std::string got = ", got " + formatNumber(d);
    if (!std::isfinite(d)) {
      fail(path, "must be a finite number" + got);
    } else if (range == Range::kPositive && !(d > 0)) {
      fail(path, "must be positive" + got);
    } else if (range == Range::kNonNegative && d < 0) {
      fail(path, "must not be negative" + got);
    } else if (range == Range::kFraction && (d < 0 || d > 1)) {
      fail(path, "must be between 0 and 1" + got);
    } else {
      return true;
    }
    return false;
  }

  // check() of every element, element(path, i) naming it.
  template <class Values>
  void checkEach(const Values& values, const std::string& path, Range range) {
    std::size_t i = 0;
    for (const double d : values) {
      check(d, element(path, i++), range);
    }
  }

  void number(const nlohmann::json& obj, const std::string& path, std::string_view key, Range range,
              double& out) {
    if (const nlohmann::json* v = find(obj, key); v != nullptr) {
      out = number(*v, member(path, key), range).value_or(out);
    }
  }

  // An integer lo ... hi (2.0 is accepted as 2: it is an integer, only written differently).
  void integer(const nlohmann::json& obj, const std::string& path, std::string_view key, int lo,
               int hi, std::string_view what, int& out) {
    const nlohmann::json* v = find(obj, key);
    if (v == nullptr) {
      return;
    }
    const std::string at = member(path, key);
    const auto d = number(*v, at, Range::kAny);
    if (!d) {
      return;
    }
    if (*d != std::floor(*d) || *d < lo || *d > hi) {
      fail(at, integerProblem(*d, lo, hi, what));
      return;
    }
    out = static_cast<int>(*d);
  }

  // The rule of integer() for a value already read.
  void check(int v, const std::string& path, int lo, int hi, std::string_view what) {
    if (v < lo || v > hi) {
      fail(path, integerProblem(v, lo, hi, what));
    }
  }

  void boolean(const nlohmann::json& obj, const std::string& path, std::string_view key,
               bool& out) {
    if (const nlohmann::json* v = find(obj, key); v != nullptr) {
      if (!v->is_boolean()) {
        fail(member(path, key), "must be true or false, got " + describe(*v));
        return;
      }
      out = v->get<bool>();
    }
  }

  // A required, non-empty string.
  std::optional<std::string> text(const nlohmann::json& obj, const std::string& path,
                                  std::string_view key, std::string_view missingHint) {
    if (!ok()) {
      return std::nullopt;
    }
    const std::string at = member(path, key);
    const nlohmann::json* v = find(obj, key);
    if (v == nullptr) {
      fail(at, "required field is missing; " + std::string(missingHint));
    } else if (!v->is_string()) {
      fail(at, "must be a string, got " + describe(*v));
    } else if (v->get_ref<const std::string&>().empty()) {
      fail(at, "must not be empty");
    } else {
      return v->get<std::string>();
    }
    return std::nullopt;
  }

  // An array of N numbers (`what` says what they are, for the message).
  template <std::size_t N>
  std::optional<std::array<double, N>> numbers(const nlohmann::json& v, const std::string& path,
                                               std::string_view what, Range range) {
    if (!ok()) {
      return std::nullopt;
    }
    if (!v.is_array() || v.size() != N) {
      fail(path, "must be an array of " + std::to_string(N) + " numbers (" + std::string(what) +
                     "), got " + describe(v));
      return std::nullopt;
    }
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      const auto d = number(v[i], element(path, i), range);
      if (!d) {
        return std::nullopt;
      }
      out[i] = *d;
    }
    return out;
  }

 private:
  static std::string integerProblem(double v, int lo, int hi, std::string_view what) {
    return "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + " (" +
           std::string(what) + "), got " + formatNumber(v);
  }

  std::optional<FieldError> error_;
};

}  // namespace smx::config
