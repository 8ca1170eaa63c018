#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

// The printed calibration target, as DIR/target.json describes it (`stripemux-target/1`,
// docs/calibration.md).
namespace smx::calib {

inline constexpr std::string_view kTargetFormat = "stripemux-target/1";

// A checkerboard of (cols + 1) × (rows + 1) squares. Its frame: origin at the first inner
// corner, x along the cols direction, y along the rows direction, z into the board; metres.
// cols + rows is odd so that a half turn of the board changes which colour the corner square
// has, and every view names the same corner first.
struct Target {
  int cols = 0;  // inner corners along x
  int rows = 0;  // inner corners along y
  double squareM = 0.0;
};

struct TargetPoint {
  double x = 0.0;
  double y = 0.0;
};

// Parses target.json text; errors are "field: problem".
[[nodiscard]] std::expected<Target, std::string> parseTarget(std::string_view json);
// Reads and parses `file`; errors name the file.
[[nodiscard]] std::expected<Target, std::string> loadTarget(const std::filesystem::path& file);

// The inner corners in the target frame (z = 0), row by row, x fastest.
[[nodiscard]] std::vector<TargetPoint> innerCorners(const Target& target);

}  // namespace smx::calib
