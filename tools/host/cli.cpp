#include "cli.hpp"

#include <vector>

#include "commands.hpp"
#include "smx/net/discovery.hpp"
#include "terminal_text.hpp"

namespace smx::host {

int runCli(std::span<const std::string> args, const CliStreams& io) {
  CLI::App app{"stripemux — multi-projector colour structured-light 3D scanner tool", "stripemux"};
  app.set_version_flag("--version", "stripemux " SMX_VERSION);
  app.require_subcommand(0, 1);

  int exitCode = kExitOk;
  addPatternCommand(app, io, exitCode);
  addSimCommand(app, io, exitCode);
  addDemuxCommand(app, io, exitCode);
  addDecodeCommand(app, io, exitCode);
  addCheckCommand(app, io, exitCode);
  addEvalCommand(app, io, exitCode);
  addInfoCommand(app, io, exitCode);
  addStreamCommand(app, io, exitCode);
  addCalibrateCommand(app, io, exitCode);
  addCaptureCommand(app, io, exitCode);
  addConfigCommand(app, io, exitCode);
  addKeygenCommand(app, io, exitCode);
  addBundleCommand(app, io, exitCode);
  addVerifyBundleCommand(app, io, exitCode);
  addPairCommand(app, io, exitCode);
  addFlashCommand(app, io, exitCode);
  addTurntableCommand(app, io, exitCode);
  addFuseCommand(app, io, exitCode);
  addScanCommand(app, io, exitCode);
  addViewCommand(app, io, exitCode);

  std::vector<const char*> argv{"stripemux"};
  for (const auto& a : args) {
    argv.push_back(a.c_str());
  }
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, io.out, io.err);
    return code == 0 ? kExitOk : kExitUsage;
  }
  if (app.get_subcommands().empty()) {
    io.out << app.help();
    // Like a depth camera's tools: with no command, also list the devices that answer.
    const auto found = net::discoverDevices({"255.255.255.255", "127.0.0.1"}, net::kDiscoveryPort,
                                            std::chrono::milliseconds(300));
    io.out << "\nDevices:";
    if (!found || found->empty()) {
      io.out << " none answered (start one with stripemuxd --board boards/sim; a device "
             << "elsewhere: stripemux info --device HOST)\n";
    } else {
      io.out << "\n";
      for (const auto& device : *found) {
        // Discovery answers are unauthenticated: a spoofed one must not steer the terminal.
        io.out << "  " << printable(device.address) << "  "
               << (device.board.empty() ? std::string("owned (stripemux pair)")
                                        : "board " + printable(device.board))
               << "\n";
      }
    }
  }
  return exitCode;
}

}  // namespace smx::host
