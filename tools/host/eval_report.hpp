#pragma once

#include <expected>
#include <filesystem>
#include <string>

#include "smx/eval/suite.hpp"

// The evaluation report: docs/results.md and its PNG plots, written from a suite's figures.
namespace smx::host {

// Writes <dir>/results.md and <dir>/results/*.png; plots an earlier run left there are removed,
// so none is stale. `command` is the command line quoted in the report as the way to regenerate it.
[[nodiscard]] std::expected<void, std::string> writeEvalReport(const std::filesystem::path& dir,
                                                               const eval::Report& report,
                                                               const std::string& command);

}  // namespace smx::host
