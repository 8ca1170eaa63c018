#include "supervisor.hpp"

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include "smx/device/state_file.hpp"
#include "smx/update/slots.hpp"
#include "update_service.hpp"

namespace smx::firmware {
namespace {

namespace fs = std::filesystem;
using update::BootRecord;

// A slot on trial is started once: a second start (the firmware or the supervisor died during
// the first) is a failed trial.
constexpr int kMaxTries = 1;
constexpr double kRestartDelayS = 1.0;

void say(const std::string& text) {
  std::printf("supervisor: %s\n", text.c_str());
  std::fflush(stdout);
}

double nowS() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// What runs: a slot's firmware and board, or the factory's.
struct Firmware {
  std::optional<std::string> slot;
  fs::path binary;
  fs::path board;
};

fs::path boardName(const fs::path& board) {
  const fs::path folder = board.filename() == "board.json" ? board.parent_path() : board;
  return folder.lexically_normal().filename().empty()
             ? folder.lexically_normal().parent_path().filename()
             : folder.lexically_normal().filename();
}

Firmware firmwareOf(const SuperviseOptions& o, const std::optional<std::string>& slot) {
  if (!slot) {
    return {std::nullopt, fs::read_symlink("/proc/self/exe"), o.board};
  }
  const fs::path root = fs::path(o.state) / "slots" / *slot;
  const fs::path board = root / "boards" / boardName(o.board);
  std::error_code ec;
  return {slot, root / "bin" / "stripemuxd",
          fs::is_directory(board, ec) ? board : fs::path(o.board)};
}

// A slot the supervisor can start: its manifest and its firmware are there.
bool complete(const SuperviseOptions& o, const std::string& slot) {
  std::error_code ec;
  return update::readSlotManifest(o.state, slot).has_value() &&
         fs::is_regular_file(fs::path(o.state) / "slots" / slot / "bin" / "stripemuxd", ec);
}

// Switches back to the slot before (the factory firmware if it is gone) and records why.
bool rollBack(const SuperviseOptions& o, BootRecord record, const std::string& why) {
  std::optional<std::string> back;
  if (!record.previous.empty() && record.previous != record.pending &&
      complete(o, record.previous)) {
    back = record.previous;
  }
  if (auto switched = update::switchActive(o.state, back); !switched) {
    say("cannot switch back: " + switched.error().message);
    return false;
  }
  device::crashPoint("supervise.rollback-switched");
  record.previous.clear();
  record.pending.clear();
  record.tries = 0;
  record.markedGood = true;
  record.outcome = update::UpdateOutcome::kRolledBack;
  record.reason = why;
  if (auto written = update::writeBootRecord(o.state, record); !written) {
    say("cannot record the rollback: " + written.error().message);
    return false;
  }
  say("rolled back to " + back.value_or("the factory firmware") + ": " + why);
  return true;
}

// Finishes or undoes what the disk says is in progress, then says what to run; nullopt when
// the state directory cannot be used. `trial` tells whether it is a slot's trial start.
std::optional<Firmware> decide(const SuperviseOptions& o, bool& trial) {
  trial = false;
  for (int round = 0; round < 3; ++round) {
    auto record = update::readBootRecord(o.state);
    auto active = update::activeSlot(o.state);
    if (!record || !active) {
      const auto& e = !record ? record.error() : active.error();
      say("the state directory is unusable: " + e.message + "; running the factory firmware");
      return firmwareOf(o, std::nullopt);
    }
    if (!record->pending.empty() && *active != record->pending) {
      // Stopped before the switch, or after a rollback's switch: what is active is whole.
      record->pending.clear();
      record->markedGood = true;
      if (record->outcome == update::UpdateOutcome::kNone) {
        record->outcome = update::UpdateOutcome::kRolledBack;
        record->reason = "the update was interrupted before its slot was marked good";
      }
      if (!update::writeBootRecord(o.state, *record)) {
        return std::nullopt;
      }
      continue;
    }
    const std::optional<std::string>& slot = *active;
    if (slot.has_value() && !complete(o, *slot)) {
      if (!rollBack(o, *record, "slot " + *slot + " is incomplete")) {
        return std::nullopt;
      }
      continue;
    }
    if (!record->pending.empty() && !record->markedGood) {
      if (record->tries >= kMaxTries) {
        if (!rollBack(o, *record, "the firmware was started and did not mark itself good")) {
          return std::nullopt;
        }
        continue;
      }
      ++record->tries;
      if (!update::writeBootRecord(o.state, *record)) {
        return std::nullopt;
      }
      trial = true;
    }
    return firmwareOf(o, *active);
  }
  return std::nullopt;
}

pid_t start(const Firmware& firmware, const SuperviseOptions& o) {
  std::vector<std::string> args = {firmware.binary.string(),
                                   "--board",
                                   firmware.board.string(),
                                   "--state",
                                   o.state,
                                   "--supervised"};
  args.insert(args.end(), o.daemon.begin(), o.daemon.end());
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& arg : args) {
    argv.push_back(arg.data());
  }
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // The firmware dies with its supervisor, so that a restarted supervisor owns the device;
    // a supervisor that died before the prctl is seen by the parent's pid.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) {
      ::_exit(127);
    }
    sigset_t none;
    sigemptyset(&none);
    pthread_sigmask(SIG_SETMASK, &none, nullptr);
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "supervisor: cannot run %s\n", argv[0]);
    ::_exit(127);
  }
  return pid;
}

std::string describeExit(int status) {
  if (WIFSIGNALED(status)) {
    return "was killed by signal " + std::to_string(WTERMSIG(status));
  }
  return "exited with code " + std::to_string(WEXITSTATUS(status));
}

bool markedGood(const SuperviseOptions& o) {
  const auto record = update::readBootRecord(o.state);
  return record && record->markedGood;
}

}  // namespace

std::vector<std::string> passedOn(int argc, char** argv) {
  std::vector<std::string> out;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--supervise" || arg == "--supervised") {
      continue;
    }
    const bool taken = arg.starts_with("--trial-timeout") || arg.starts_with("--board") ||
                       arg.starts_with("--state");
    if (taken) {
      i += arg.find('=') == std::string_view::npos ? 1 : 0;  // "--board X" or "--board=X"
      continue;
    }
    out.emplace_back(arg);
  }
  return out;
}

int supervise(const SuperviseOptions& o) {
  std::error_code ec;
  if (!fs::is_directory(o.state, ec)) {
    std::fprintf(stderr, "stripemuxd: --supervise: state directory %s is not a directory\n",
                 o.state.c_str());
    return 1;
  }
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  while (true) {
    bool trial = false;
    const auto firmware = decide(o, trial);
    if (!firmware) {
      std::fprintf(stderr, "stripemuxd: --supervise: cannot write to %s\n", o.state.c_str());
      return 1;
    }
    say("starting " + (firmware->slot ? "slot " + *firmware->slot : "the factory firmware") +
        (trial ? " on trial" : ""));
    const pid_t child = start(*firmware, o);
    if (child < 0) {
      say("cannot start the firmware");
      return 1;
    }
    if (trial) {
      device::crashPoint("supervise.trial-started");
    }
    const double started = nowS();
    int status = 0;
    bool stopping = false;
    bool timedOut = false;
    const timespec tick{.tv_sec = 0, .tv_nsec = 100'000'000};
    while (::waitpid(child, &status, WNOHANG) == 0) {
      if (sigtimedwait(&signals, nullptr, &tick) > 0 && !stopping) {
        stopping = true;
        ::kill(child, SIGTERM);
      }
      if (trial && markedGood(o)) {
        trial = false;  // passed: from here on it is the running firmware
      }
      if (trial && !stopping && !timedOut && nowS() - started > o.trialTimeoutS) {
        timedOut = true;
        ::kill(child, SIGKILL);
      }
    }
    if (stopping) {
      say("stopped: the firmware " + describeExit(status));
      return 0;
    }
    if (trial && !markedGood(o)) {  // it may have marked itself good just before it ended
      const auto record = update::readBootRecord(o.state);
      const std::string why =
          timedOut ? "the firmware did not mark itself good within " +
                         std::to_string(static_cast<int>(o.trialTimeoutS)) + " s"
                   : "the firmware " + describeExit(status) + " before marking itself good";
      if (!record || !rollBack(o, *record, why)) {
        return 1;
      }
      continue;
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == kExitUpdated) {
      say("the firmware installed an update");
      continue;
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) <= 2) {
      // Stopped, or its options or board refused: starting it again would not help.
      say("the firmware " + describeExit(status) + "; stopping");
      return WEXITSTATUS(status);
    }
    say("the firmware " + describeExit(status) + "; restarting it");
    const timespec delay{.tv_sec = static_cast<time_t>(kRestartDelayS), .tv_nsec = 0};
    nanosleep(&delay, nullptr);
  }
}

}  // namespace smx::firmware
