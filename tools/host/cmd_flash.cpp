// `stripemux flash`: upload a signed firmware bundle to a device, wait for it to come back and
// report what it runs (docs/update.md, docs/cli.md).
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "command_failure.hpp"
#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "smx/update/bundle.hpp"
#include "smx/update/file_io.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

// The device rolled back the update: it runs the firmware before (the reason is printed).
constexpr int kExitRolledBack = 4;
constexpr auto kFlashAnswerTimeout = std::chrono::milliseconds(10000);
// Verification and extraction of a bundle of the largest size on a slow SD card.
constexpr auto kInstallTimeout = std::chrono::milliseconds(300'000);
constexpr auto kRetryDelay = std::chrono::milliseconds(500);

struct FlashOptions {
  std::string device;
  std::string file;
  bool status = false;
  double waitS = 120;  // for the device to come back and settle
};

std::string describe(const UpdateStatusReport& s) {
  const std::string running =
      "running " + s.runningVersion +
      (s.runningSlot == "factory" ? " (the factory firmware)" : " in slot " + s.runningSlot);
  switch (s.outcome) {
    case protocol::UpdateOutcomeCode::kInstalled:
      return "installed " + s.updateVersion + "; " + running;
    case protocol::UpdateOutcomeCode::kRolledBack:
      return "rolled back " + s.updateVersion + ": " + printable(s.reason) + "; " + running;
    case protocol::UpdateOutcomeCode::kNone:
      break;
  }
  return "no update; " + running;
}

// A bar on a terminal; otherwise nothing (the device's steps are the plain lines).
void showSent(const CliStreams& io, bool tty, std::uint64_t sent, std::uint64_t total) {
  if (!tty) {
    return;
  }
  constexpr std::size_t kWidth = 40;
  const auto filled = static_cast<std::size_t>(kWidth * sent / total);
  io.err << "\rsending [" << std::string(filled, '#') << std::string(kWidth - filled, ' ') << "] "
         << (100 * sent / total) << "%" << (sent == total ? "\n" : "") << std::flush;
}

// The device's update status once it is back and settled (a trial decided), retrying the
// connection while it restarts.
std::expected<UpdateStatusReport, CommandFailure> awaitSettled(const FlashOptions& opts) {
  const auto deadline = std::chrono::steady_clock::now() + secondsOption(opts.waitS);
  std::string last = "no answer";
  while (std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(kRetryDelay);
    auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
    if (!client) {
      last = client.error();
      continue;
    }
    auto status = client->updateStatus(kFlashAnswerTimeout);
    if (!status) {
      last = status.error();
      continue;
    }
    if (status->outcome != protocol::UpdateOutcomeCode::kNone) {
      return *status;
    }
    last = "the new firmware has not passed its self-test yet";
  }
  return std::unexpected(CommandFailure{
      kExitDeviceOrIo, "the device did not come back within " +
                           std::to_string(static_cast<int>(opts.waitS)) + " s: " + last});
}

std::expected<std::string, CommandFailure> runStatus(const FlashOptions& opts) {
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return std::unexpected(CommandFailure{kExitDeviceOrIo, client.error()});
  }
  auto status = client->updateStatus(kFlashAnswerTimeout);
  if (!status) {
    return std::unexpected(CommandFailure{kExitDeviceOrIo, status.error()});
  }
  return describe(*status) + "\n";
}

std::expected<std::string, CommandFailure> runFlash(const FlashOptions& opts,
                                                    const CliStreams& io) {
  auto bytes = update::readFile(opts.file, update::kMaxBundleSize);
  if (!bytes) {
    return std::unexpected(CommandFailure{kExitBadInput, bytes.error().message});
  }
  if (auto shape = update::checkBundleShape(*bytes); !shape) {
    return std::unexpected(CommandFailure{kExitBadInput, opts.file + ": " + shape.error().message});
  }
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return std::unexpected(CommandFailure{kExitDeviceOrIo, client.error()});
  }
  io.err << "flashing " << opts.file << " (" << bytes->size() << " bytes) to "
         << client->info().address << ", running " << printable(client->info().firmwareVersion)
         << "\n";
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  auto flashed = client->flash(
      *bytes, [&](std::uint64_t sent, std::uint64_t total) { showSent(io, tty, sent, total); },
      [&](const protocol::FlashProgress& p) { io.err << "device: " << printable(p.text) << "\n"; },
      kInstallTimeout);
  client->close();
  if (!flashed) {
    return std::unexpected(CommandFailure{flashed.error().refused ? kExitBadInput : kExitDeviceOrIo,
                                          flashed.error().message});
  }
  io.err << "waiting for the device to restart\n";
  auto settled = awaitSettled(opts);
  if (!settled) {
    return std::unexpected(settled.error());
  }
  if (settled->outcome == protocol::UpdateOutcomeCode::kRolledBack) {
    return std::unexpected(CommandFailure{kExitRolledBack, describe(*settled)});
  }
  return describe(*settled) + "\n";
}

}  // namespace

void addFlashCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<FlashOptions>();
  auto* cmd = app.add_subcommand(
      "flash",
      "Install a signed firmware bundle on a device and report what it runs after "
      "(docs/update.md)");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->check(deviceAddressValidator())
      ->required();
  cmd->add_option("FILE", opts->file, "the bundle (stripemux bundle)");
  cmd->add_flag("--status", opts->status, "print the device's last update and what it runs");
  cmd->add_option("--wait", opts->waitS,
                  "seconds to wait for the device to come back after the upload (default 120)")
      ->check(CLI::Range(1.0, 3600.0));
  cmd->callback([opts, &io, &exitCode] {
    if (opts->status == !opts->file.empty()) {
      io.err << "stripemux flash: give either FILE or --status\n";
      exitCode = kExitUsage;
      return;
    }
    const auto result = opts->status ? runStatus(*opts) : runFlash(*opts, io);
    if (!result) {
      io.err << "stripemux flash: " << printable(result.error().message) << "\n";
      exitCode = result.error().code;
      return;
    }
    io.out << *result;
    exitCode = kExitOk;
  });
}

}  // namespace smx::host
