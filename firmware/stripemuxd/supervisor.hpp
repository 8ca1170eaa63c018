#pragma once

#include <string>
#include <vector>

// `stripemuxd --supervise` (docs/update.md#supervisor): runs the active slot's firmware (or the
// factory one), gives a slot on trial a set time to mark itself good, and rolls back to the
// slot before (or the factory firmware) when it does not.
namespace smx::firmware {

struct SuperviseOptions {
  std::string state;                // the state directory
  std::string board;                // the factory firmware's board (folder or board.json)
  double trialTimeoutS = 30;        // for a slot on trial to mark itself good
  std::vector<std::string> daemon;  // the daemon's other options, passed on as they are
};

// The daemon's command line without the options the supervisor sets or takes itself
// (--supervise, --supervised, --trial-timeout, --board, --state).
[[nodiscard]] std::vector<std::string> passedOn(int argc, char** argv);

// Returns the exit code: 0 after SIGTERM or SIGINT (passed on to the firmware), 1 for a state
// directory it cannot use.
[[nodiscard]] int supervise(const SuperviseOptions& options);

}  // namespace smx::firmware
