// stripemuxd: the scanner's firmware. Loads a board, opens its devices through the HAL this
// build links, and serves range images to one host at a time until SIGTERM or SIGINT
// (docs/firmware.md). Exit codes: 0 stopped cleanly, 1 usage, 2 rejected board, 3 device error,
// 10 an update was installed (kExitUpdated; the supervisor starts it).
#include <pthread.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <thread>

#include "settings.hpp"
#include "smx/config/board_json.hpp"
#include "smx/device/device.hpp"
#include "smx/device/owners.hpp"
#include "smx/device/secure_link.hpp"
#include "smx/hal/board_hal.hpp"
#include "smx/net/discovery.hpp"
#include "smx/net/tcp_client.hpp"
#include "smx/net/tcp_link.hpp"
#include "smx/protocol/secure_keys.hpp"
#include "supervisor.hpp"
#include "update_service.hpp"

namespace {

using smx::device::Device;

struct Options {
  std::string board;
  int port = -1;
  std::string bind;
  std::string scene;
  std::string replay;
  std::string state;
  bool pair = false;
  bool open = false;
  int fps = 0;
  std::uint64_t frames = 0;
  double statusEveryS = 5;
  double idleTimeoutS = 30;  // DeviceOptions::idleTimeoutNs says why
  bool supervise = false;
  bool supervised = false;  // started by the supervisor: updates are taken
  double trialTimeoutS = 30;
};

// SIGTERM and SIGINT are blocked in every thread and taken here, so the loops see a plain
// atomic flag instead of running code in a signal handler.
void waitForSignal(sigset_t signals, std::atomic<bool>& stop) {
  const timespec tick{.tv_sec = 0, .tv_nsec = 100'000'000};
  while (!stop) {
    if (sigtimedwait(&signals, nullptr, &tick) > 0) {
      stop = true;
    }
  }
}

void printCounters(const Device& device, const char* prefix) {
  const auto s = device.statistics();
  std::printf(
      "%scaptured %llu, decoded %llu, sent %llu, dropped %llu, capture errors %llu, protocol "
      "errors %llu, decode %.1f ms/frame\n",
      prefix, static_cast<unsigned long long>(s.framesCaptured),
      static_cast<unsigned long long>(s.framesDecoded),
      static_cast<unsigned long long>(s.framesSent),
      static_cast<unsigned long long>(s.framesDropped),
      static_cast<unsigned long long>(s.captureErrors),
      static_cast<unsigned long long>(s.protocolErrors), s.decodeTimeUsMean / 1000.0);
  std::fflush(stdout);
}

// Runs the device until a signal (returns true) or until a set-config asks for a restart with
// the stored settings (returns false).
bool serve(Device& device, const Options& opts, std::size_t cameras, std::atomic<bool>& stop) {
  std::jthread network([&] { device.runNetwork(stop); });
  timespec last{};
  clock_gettime(CLOCK_MONOTONIC, &last);
  while (!stop && !device.restartDue()) {
    (void)device.serveRawCapture();  // between range captures, when a host asked for one
    (void)device.serveTurn();        // and a turntable move
    (void)device.captureOnce();
    if (opts.frames > 0 && device.counters().framesCaptured >= opts.frames * cameras) {
      stop = true;
    }
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if (static_cast<double>(now.tv_sec - last.tv_sec) >= opts.statusEveryS) {
      printCounters(device, "status: ");
      last = now;
    }
  }
  network.join();
  return stop;
}

int run(const Options& opts) {
  auto board = smx::config::loadBoard(opts.board);
  if (!board) {
    std::fprintf(stderr, "stripemuxd: %s\n", board.error().message().c_str());
    return 2;
  }
  auto& config = board->config;
  if (opts.port >= 0) {
    config.network.port = static_cast<std::uint16_t>(opts.port);
  }
  if (!opts.bind.empty()) {
    config.network.bindAddress = opts.bind;
  }
  if (!opts.scene.empty() || !opts.replay.empty()) {
    config.sim.scene = opts.scene;
    config.sim.replayDir = opts.replay;
  }
  for (auto& camera : config.cameras) {
    camera.format.fps = opts.fps > 0 ? opts.fps : camera.format.fps;
  }
  // The HAL is the hardware: it stays while the settings change (the simulated world keeps the
  // board's rig, whatever rig the owner installs).
  auto hal = smx::hal::createBoardHal(config, board->rig);
  if (!hal) {
    std::fprintf(stderr, "stripemuxd: board %s: %s\n", config.name.c_str(), hal.error().c_str());
    return 3;
  }
  std::string report;
  auto settings = smx::firmware::Settings::load(opts.state, *board,
                                                smx::firmware::hardwareOf((*hal)->hal()), report);
  std::fputs(report.c_str(), stdout);
  if (!settings) {
    std::fprintf(stderr, "stripemuxd: %s\n", settings.error().c_str());
    return 1;
  }
  // The owner's channel (docs/security.md): with a state directory only paired hosts are served.
  std::optional<smx::device::Owners> owners;
  std::unique_ptr<smx::device::SecureLink> secureLink;
  if (!opts.state.empty() && !opts.open) {
    auto opened = smx::device::Owners::open(opts.state, opts.pair);
    if (!opened) {
      std::fprintf(stderr, "stripemuxd: %s\n", opened.error().c_str());
      return 1;
    }
    owners.emplace(std::move(*opened));
    const smx::hal::Hal devices = (*hal)->hal();
    secureLink = std::make_unique<smx::device::SecureLink>(devices.link, *owners, devices.clock);
    if (auto* tcp = dynamic_cast<smx::net::TcpLink*>(&devices.link)) {
      tcp->hideHolder();
    }
  }
  const auto deviceHal = [&] {
    const smx::hal::Hal devices = (*hal)->hal();
    return secureLink ? smx::hal::Hal{devices.cameras, devices.trigger, *secureLink, devices.clock,
                                      devices.turntable}
                      : devices;
  };
  smx::firmware::UpdateService updates(opts.state, config.name, opts.supervised);
  smx::device::DeviceOptions base;
  base.firmwareVersion = updates.runningVersion();
  base.update = updates.hooks();
  base.idleTimeoutNs = static_cast<std::int64_t>(opts.idleTimeoutS * 1e9);

  const std::uint16_t tcpPort = (*hal)->hal().link.port();
  // Discovery is a convenience: a second device on this machine (tests) goes without it.
  // An owned device answers without its board name: paired hosts learn it in the capabilities,
  // over the owner's channel (docs/security.md "Discovery").
  auto discovery =
      smx::net::DiscoveryResponder::create(config.network.bindAddress, smx::net::kDiscoveryPort,
                                           tcpPort, owners ? std::string() : config.name);
  std::atomic<bool> stop = false;
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  const std::jthread signalThread(waitForSignal, signals, std::ref(stop));
  std::jthread discoveryThread([&] {
    while (discovery && !stop) {
      (void)(*discovery)->serviceOnce(100'000'000);
    }
  });

  bool started = false;
  while (!stop) {
    auto options = settings->deviceOptions(base);
    options.setConfig = [&](const smx::protocol::SetConfig& request) {
      return settings->change(request);
    };
    const smx::config::Board running = settings->board();
    auto device = Device::create(running, deviceHal(), options);
    if (!device && started) {
      // Checked before they were stored, yet refused (a camera that cannot run at that rate):
      // the settings before are the ones the device last ran with.
      std::printf("settings refused by the device: %s; going back to the settings before\n",
                  device.error().c_str());
      if (auto reverted = settings->revert(); !reverted) {
        std::printf("%s\n", reverted.error().c_str());
      }
      device = Device::create(settings->board(), deviceHal(), settings->deviceOptions(base));
    }
    if (!device) {
      std::fprintf(stderr, "stripemuxd: board %s: %s\n", config.name.c_str(),
                   device.error().c_str());
      stop = true;
      return 3;
    }
    const auto& rig = running.rig;
    if (!started) {
      std::printf(
          "stripemuxd %s: board %s (%s HAL), %zu cameras %dx%d, %zu projectors, %zu KiB "
          "working memory\n",
          updates.runningVersion().c_str(), config.name.c_str(),
          std::string(smx::hal::halBackend()).c_str(), rig.cameras.size(),
          rig.cameras.front().width, rig.cameras.front().height, rig.projectors.size(),
          (*device)->arenaBytes() / 1024);
      std::printf("listening on %s\n",
                  smx::net::toString({config.network.bindAddress, tcpPort}).c_str());
      if (!discovery) {
        std::printf("discovery off: %s\n", discovery.error().c_str());
      }
      if (owners) {
        std::printf("owner's channel: device key %s, %zu paired hosts\n",
                    smx::protocol::fingerprint(owners->identity().publicKey).c_str(),
                    owners->pairedHosts());
        secureLink->announcePairing();
      } else {
        std::printf("%s: anyone on the network can use this device\n",
                    opts.open ? "--open" : "no --state");
      }
    }
    if (updates.onTrial()) {
      if (auto marked = updates.selfTestAndMarkGood(**device); !marked) {
        std::fprintf(stderr, "stripemuxd: %s\n", marked.error().c_str());
        stop = true;
        return 3;
      }
      std::printf("slot %s: self-test passed, marked good\n", updates.runningSlot().c_str());
    }
    std::printf("settings: %s\n", settings->describe().c_str());
    std::fflush(stdout);
    started = true;
    if (serve(**device, opts, rig.cameras.size(), stop)) {
      printCounters(**device, "stopped: ");
      break;
    }
    if ((*device)->updateDue()) {
      printCounters(**device, "update installed, exiting for the supervisor: ");
      stop = true;
      return smx::firmware::kExitUpdated;
    }
    printCounters(**device, "restarting with new settings: ");
    for (smx::hal::Camera* camera : (*hal)->hal().cameras) {
      (void)camera->stop();
    }
  }
  stop = true;
  discoveryThread.join();
  return 0;
}

int parseAndRun(int argc, char** argv) {
  CLI::App app{"stripemuxd: the stripemux scanner firmware"};
  app.set_version_flag("--version", SMX_VERSION);
  Options opts;
  app.add_option("--board", opts.board, "board folder or board.json (boards/<name>)")->required();
  app.add_option("--port", opts.port, "TCP port (overrides the board; 0: any free port)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--bind", opts.bind,
                 "IPv4 or IPv6 address to listen on (overrides the board; \"::\": every "
                 "address, IPv4 too)");
  app.add_option("--scene", opts.scene, "simulated board: render this scene");
  app.add_option("--replay", opts.replay,
                 "simulated board: replay <dir>/<camera-id>_<n>.png instead of rendering");
  app.add_option("--state", opts.state,
                 "state directory: the owner's settings (config.json), keys and paired hosts, kept "
                 "across restarts; the device then serves paired hosts only");
  app.add_flag("--pair", opts.pair,
               "with --state: open pairing (print a code) although hosts are paired already");
  app.add_flag("--open", opts.open,
               "with --state: serve any host in the clear, no pairing (development and tests; "
               "never on a real board)");
  app.add_option("--fps", opts.fps, "camera frame rate (overrides the board)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--frames", opts.frames, "stop after this many captures (0: run until SIGTERM)");
  app.add_option("--status-every", opts.statusEveryS, "seconds between status lines")
      ->check(CLI::PositiveNumber);
  app.add_option("--idle-timeout", opts.idleTimeoutS,
                 "seconds a host may send nothing (not streaming) or read nothing before it is "
                 "disconnected (default 30; 0: never)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_flag("--supervise", opts.supervise,
               "run as the supervisor: start the active slot's firmware (docs/update.md)");
  app.add_option("--trial-timeout", opts.trialTimeoutS,
                 "--supervise: seconds a new firmware has to pass its self-test (default 30)")
      ->check(CLI::Range(1.0, 3600.0));
  app.add_flag("--supervised", opts.supervised, "started by the supervisor")->group("");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  if (opts.supervise) {
    if (opts.state.empty()) {
      std::fprintf(stderr, "stripemuxd: --supervise needs --state\n");
      return 1;
    }
    return smx::firmware::supervise(
        {opts.state, opts.board, opts.trialTimeoutS, smx::firmware::passedOn(argc, argv)});
  }
  return run(opts);
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread: every thread inherits the blocked signals.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  try {
    return parseAndRun(argc, argv);
  } catch (const std::exception& e) {  // out of memory at start-up, a thread that cannot start
    std::fprintf(stderr, "stripemuxd: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "stripemuxd: unexpected error\n");
  }
  return 3;
}
