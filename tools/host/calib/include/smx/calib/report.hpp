#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "smx/calib/calibrate.hpp"

// The calibration report (docs/calibration.md): report.json and its short text summary.
namespace smx::calib {

inline constexpr std::string_view kReportFormat = "stripemux-calibration-report/1";

[[nodiscard]] nlohmann::ordered_json reportJson(const Calibration& calibration);
[[nodiscard]] std::string reportText(const Calibration& calibration);

}  // namespace smx::calib
