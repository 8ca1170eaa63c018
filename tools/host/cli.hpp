#pragma once

#include <ostream>
#include <span>
#include <string>

// The `stripemux` command line. Exit codes (docs/cli.md):
//   0 ok, 1 usage error, 2 rejected input (a bad file; the message names it and the field),
//   3 device or I/O error.
namespace smx::host {

enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 1,
  kExitBadInput = 2,
  kExitDeviceOrIo = 3,
};

struct CliStreams {
  std::ostream& out;
  std::ostream& err;
};

// args excludes the program name.
[[nodiscard]] int runCli(std::span<const std::string> args, const CliStreams& io);

}  // namespace smx::host
