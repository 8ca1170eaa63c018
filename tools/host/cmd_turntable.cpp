// `stripemux turntable`: read and turn a device's turntable (docs/cli.md, docs/protocol.md).
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

constexpr auto kStatusTimeout = std::chrono::milliseconds(10000);
// A request of more turns than this is a typo (and its wait would be hours at 1 deg/s).
constexpr double kMaxTurnDeg = 3600.0;
// The slowest and most patient board (docs/boards.md: speed ≥ 1 deg/s, settle ≤ 10 s) bounds how
// long a move may take; the answer comes after the move, so that is the wait.
constexpr double kSlowestDegS = 1.0;
constexpr auto kMaxSettle = std::chrono::milliseconds(10000);
constexpr auto kAnswerMargin = std::chrono::milliseconds(5000);

struct TurntableOptions {
  std::string device;
  std::optional<double> turnDeg;
  std::optional<double> toDeg;
};

std::int64_t microDeg(double deg) {
  return std::llround(deg * 1e6);
}

std::chrono::milliseconds moveTimeout(double deg) {
  const auto motion = std::chrono::milliseconds(
      static_cast<std::int64_t>(std::ceil(std::abs(deg) / kSlowestDegS * 1000.0)));
  return motion + kMaxSettle + kAnswerMargin;
}

std::string describe(const protocol::TurntableState& s) {
  std::array<char, 64> angle{};
  std::snprintf(angle.data(), angle.size(), "%.6f", static_cast<double>(s.angleUdeg) / 1e6);
  std::string out = "turntable: present\n";
  out += "angle: " + std::string(angle.data()) + " deg\n";
  out += "position: " + std::to_string(s.position) + " steps\n";
  out += "steps per turn: " + std::to_string(s.stepsPerTurn) + "\n";
  out += "settled at: " +
         (s.settledNs == 0 ? std::string("never moved") : std::to_string(s.settledNs) + " ns") +
         " (device clock)\n";
  return out;
}

int run(const TurntableOptions& opts, const CliStreams& io) {
  const auto fail = [&](int code, const std::string& message) {
    io.err << "stripemux turntable: " << printable(message) << "\n";
    return code;
  };
  const std::optional<double> angle = opts.turnDeg ? opts.turnDeg : opts.toDeg;
  if (angle && (!std::isfinite(*angle) || std::abs(*angle) > kMaxTurnDeg)) {
    return fail(kExitUsage, "the angle must be from -3600 to 3600 degrees");
  }
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return fail(kExitDeviceOrIo, client.error());
  }
  const std::string where = client->info().address + ": ";
  auto state = client->turntableStatus(kStatusTimeout);
  if (state && !state->present) {
    state = std::unexpected(TurntableFailure{true, "the device has no turntable"});
  }
  if (state && angle) {
    // An absolute move turns by the difference: the wait follows from it.
    const double by = opts.toDeg ? *angle - static_cast<double>(state->angleUdeg) / 1e6 : *angle;
    state = client->turnTurntable(
        opts.toDeg ? protocol::TurnMode::kAbsolute : protocol::TurnMode::kRelative,
        microDeg(*angle), moveTimeout(by));
  }
  if (!state) {
    return fail(state.error().absent ? kExitBadInput : kExitDeviceOrIo,
                where + state.error().message);
  }
  io.out << describe(*state);
  return kExitOk;
}

}  // namespace

void addTurntableCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<TurntableOptions>();
  auto* cmd = app.add_subcommand(
      "turntable",
      "Show a device's turntable (angle, steps per turn), or turn it and wait until "
      "it has settled");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->check(deviceAddressValidator())
      ->required();
  auto* turn = cmd->add_option("--turn", opts->turnDeg,
                               "turn by DEG degrees (positive: right-handed about the rig's "
                               "turntable axis)");
  auto* to = cmd->add_option("--to", opts->toDeg,
                             "turn to DEG degrees (0: where the table stood at start-up)");
  turn->excludes(to);
  cmd->callback([opts, &io, &exitCode] { exitCode = run(*opts, io); });
}

}  // namespace smx::host
