#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

// Files of the device's state directory (docs/config.md), written so that a crash or power cut at
// any moment leaves the old file or the new one, each whole: the text goes to `<file>.tmp`, is
// flushed to the disk, renamed over the file, and the directory entry is flushed too.
namespace smx::device {

// The steps of writeStateFile() are smx::update::kAtomicWriteSteps (its one atomic writer);
// `<what>.<step>` names a crash point.

// For the fault tests: when the environment variable SMX_CRASH_AT equals `point`, the process
// kills itself with SIGKILL here, as a power cut would stop it.
void crashPoint(std::string_view point);

// Writes `text` as `file`; `what` names the crash points ("config" → "config.renamed").
[[nodiscard]] std::expected<void, std::string> writeStateFile(const std::filesystem::path& file,
                                                              std::string_view text,
                                                              std::string_view what);

// Removes what an interrupted writeStateFile() left (`<file>.tmp`); true if there was one.
bool removeInterruptedWrite(const std::filesystem::path& file);

}  // namespace smx::device
