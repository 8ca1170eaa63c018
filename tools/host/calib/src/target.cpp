#include "smx/calib/target.hpp"

#include <array>
#include <cmath>
#include <exception>

#include "smx/config/field_reader.hpp"
#include "smx/config/json_reader.hpp"

namespace smx::calib {
namespace {

constexpr std::array<std::string_view, 4> kTopKeys = {"format", "type", "inner_corners",
                                                      "square_m"};
constexpr std::array<std::string_view, 1> kTypes = {"checkerboard"};
constexpr config::DocumentSpec kTargetDocument = {.name = "target.json",
                                                  .format = kTargetFormat,
                                                  .topKeys = kTopKeys,
                                                  .maxBytes = std::size_t{1} << 12U,
                                                  .sizeNote = "",
                                                  .nestingNeeded = 2,
                                                  .maxNesting = 8,
                                                  .otherFormats = {}};

// Fewer corners than this and a board is not told apart from other squares in a room; more and
// the detector's cost grows with no gain in accuracy.
constexpr int kMinCorners = 3;
constexpr int kMaxCorners = 64;
constexpr double kMinSquareM = 0.002;
constexpr double kMaxSquareM = 0.5;

std::string message(const config::FieldError& e) {
  return e.field.empty() ? e.problem : e.field + ": " + e.problem;
}

}  // namespace

std::expected<Target, std::string> parseTarget(std::string_view json) {
  try {
    auto doc = config::parseDocument(json, kTargetDocument);
    if (!doc) {
      return std::unexpected(message(doc.error()));
    }
    config::FieldReader r;
    const auto type = r.text(*doc, "", "type", "\"checkerboard\"");
    if (type && *type != kTypes[0]) {
      return std::unexpected(R"(type: must be "checkerboard" (the only target type), got ")" +
                             *type + "\"");
    }
    Target target;
    const nlohmann::json* corners = r.find(*doc, "inner_corners");
    if (corners == nullptr && r.ok()) {
      return std::unexpected("inner_corners: required field is missing; [COLS, ROWS]");
    }
    if (const auto n = corners != nullptr ? r.numbers<2>(*corners, "inner_corners", "COLS, ROWS",
                                                         config::Range::kPositive)
                                          : std::nullopt) {
      for (std::size_t i = 0; i < 2; ++i) {
        const double v = (*n)[i];
        const std::string at = "inner_corners[" + std::to_string(i) + "]";
        if (v != std::floor(v) || v < kMinCorners || v > kMaxCorners) {
          r.fail(at, "must be an integer from " + std::to_string(kMinCorners) + " to " +
                         std::to_string(kMaxCorners) + ", got " + config::formatNumber(v));
        }
      }
      target.cols = static_cast<int>((*n)[0]);
      target.rows = static_cast<int>((*n)[1]);
    }
    const nlohmann::json* square = r.find(*doc, "square_m");
    if (square == nullptr && r.ok()) {
      return std::unexpected("square_m: required field is missing; the square's side in metres");
    }
    r.number(*doc, "", "square_m", config::Range::kPositive, target.squareM);
    if (r.ok() && (target.squareM < kMinSquareM || target.squareM > kMaxSquareM)) {
      r.fail("square_m",
             "must be from 0.002 to 0.5 m, got " + config::formatNumber(target.squareM));
    }
    if (r.ok() && (target.cols + target.rows) % 2 == 0) {
      r.fail("inner_corners",
             "one count must be odd and the other even (e.g. [9, 6]): on a board with both even "
             "or both odd a half turn looks the same, so its corners cannot be named");
    }
    if (!r.ok()) {
      return std::unexpected(message(r.firstError().value_or(config::FieldError{})));
    }
    return target;
  } catch (const std::exception& e) {
    return std::unexpected(std::string("cannot read target.json: ") + e.what());
  }
}

std::expected<Target, std::string> loadTarget(const std::filesystem::path& file) {
  const auto text = config::readDocumentFile(file, kTargetDocument);
  if (!text) {
    return std::unexpected(file.string() + ": " + message(text.error()));
  }
  auto target = parseTarget(*text);
  if (!target) {
    return std::unexpected(file.string() + ": " + target.error());
  }
  return target;
}

std::vector<TargetPoint> innerCorners(const Target& target) {
  std::vector<TargetPoint> points;
  points.reserve(static_cast<std::size_t>(target.cols) * static_cast<std::size_t>(target.rows));
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      points.push_back({c * target.squareM, r * target.squareM});
    }
  }
  return points;
}

}  // namespace smx::calib
