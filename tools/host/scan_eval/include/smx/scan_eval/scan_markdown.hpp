#pragma once

#include <string>

#include "smx/scan_eval/handheld_eval.hpp"
#include "smx/scan_eval/turntable_eval.hpp"

namespace smx::scan_eval {

// docs/scan-results.md: the figures beside the targets, and the command that made them.
[[nodiscard]] std::string scanResultsMarkdown(const TurntableEvalResult& turntable,
                                              const HandheldEvalResult& handheld,
                                              const std::string& command);

}  // namespace smx::scan_eval
