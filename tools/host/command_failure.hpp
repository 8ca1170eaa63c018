#pragma once

#include <string>

namespace smx::host {

// Why a command stopped: its exit code (cli.hpp) and the message for standard error.
struct CommandFailure {
  int code;
  std::string message;
};

}  // namespace smx::host
