// `stripemux config`: read and change a device's settings (docs/config.md, docs/cli.md).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "config_change.hpp"
#include "config_presets.hpp"
#include "device_client.hpp"
#include "device_option.hpp"
#include "smx/config/device_config.hpp"
#include "smx/config/json_errors.hpp"
#include "smx/config/rig_json.hpp"
#include "terminal_text.hpp"

namespace smx::host {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr auto kConfigAnswerTimeout = std::chrono::milliseconds(10000);

struct ConfigOptions {
  std::string device;
  std::string key;                  // get KEY
  std::vector<std::string> assign;  // set KEY=VALUE…
  std::string source;               // apply FILE|PRESET
};

using Failure = ConfigChangeFailure;
using Result = std::expected<std::string, Failure>;

// apply FILE|PRESET: a path (it has a '/' or ends in .json) or a preset's name.
std::expected<std::string, Failure> changeFromSource(const std::string& source) {
  const bool looksLikeFile =
      source.find('/') != std::string::npos || fs::path(source).extension() == ".json";
  if (!looksLikeFile) {
    for (const ConfigPreset& preset : configPresets()) {
      if (preset.name == source) {
        return std::string(preset.json);
      }
    }
    std::string names;
    for (const ConfigPreset& preset : configPresets()) {
      names += (names.empty() ? "" : ", ") + std::string(preset.name);
    }
    return std::unexpected(Failure{kExitUsage, "apply: no preset \"" + printable(source) +
                                                   "\" (presets: " + names +
                                                   "; a file needs a .json name or a path)"});
  }
  auto text = config::readDeviceConfigText(source);
  if (!text) {
    return std::unexpected(Failure{
        kExitBadInput,
        "apply: " + config::errorMessage(source, text.error().field, text.error().problem)});
  }
  return std::move(*text);
}

// The settings without the rig, one per line, and what the rig is.
std::string describeSettings(const std::string& json) {
  const Json doc = Json::parse(json, nullptr, false);
  if (!doc.is_object()) {
    return printable(json) + "\n";
  }
  std::string out;
  for (const auto key : config::deviceConfigKeys()) {
    const auto it = doc.find(std::string(key));
    if (it == doc.end()) {
      continue;
    }
    if (key == "rig") {
      out += "rig: " + std::to_string(it->value("cameras", Json::array()).size()) + " cameras, " +
             std::to_string(it->value("projectors", Json::array()).size()) +
             " projectors (stripemux config get rig prints it)\n";
    } else {
      out += std::string(key) + ": " + printable(it->dump()) + "\n";
    }
  }
  return out;
}

Result connectAnd(
    const ConfigOptions& opts,
    const std::function<std::expected<std::string, std::string>(DeviceClient&)>& ask) {
  if (opts.device.empty()) {
    return std::unexpected(Failure{kExitUsage, "--device HOST is required"});
  }
  auto client = DeviceClient::connect(opts.device, kDeviceConnectTimeout);
  if (!client) {
    return std::unexpected(Failure{kExitDeviceOrIo, client.error()});
  }
  auto answer = ask(*client);
  if (!answer) {
    // The device refuses a setting with the key's name: rejected input, as a bad file is.
    const bool refused = answer.error().find("set-config:") != std::string::npos;
    return std::unexpected(Failure{refused ? kExitBadInput : kExitDeviceOrIo,
                                   client->info().address + ": " + answer.error()});
  }
  return std::move(*answer);
}

Result runGet(const ConfigOptions& opts) {
  if (!opts.key.empty() && !isSettingKey(opts.key)) {
    return std::unexpected(Failure{kExitUsage, "get: no setting \"" + printable(opts.key) +
                                                   "\"; settings: " + settingKeysList()});
  }
  auto json = connectAnd(opts, [](DeviceClient& c) { return c.getConfig(kConfigAnswerTimeout); });
  if (!json || opts.key.empty()) {
    return json;
  }
  const Json doc = Json::parse(*json, nullptr, false);
  const auto it = doc.is_object() ? doc.find(opts.key) : doc.end();
  if (it == doc.end()) {
    return std::unexpected(
        Failure{kExitDeviceOrIo, "the device's settings have no \"" + opts.key + "\""});
  }
  return (it->is_string() ? it->get<std::string>() : it->dump(2)) + "\n";
}

Result runChange(const ConfigOptions& opts, protocol::SetConfigMode mode,
                 const std::string& change) {
  auto json = connectAnd(
      opts, [&](DeviceClient& c) { return c.setConfig(mode, change, kConfigAnswerTimeout); });
  if (!json) {
    return json;
  }
  return "stored; the device restarts with:\n" + describeSettings(*json);
}

std::string presetList() {
  std::string out;
  for (const ConfigPreset& preset : configPresets()) {
    out += std::string(preset.name) + ": " + std::string(preset.summary) + "\n    " +
           std::string(preset.json) + "\n";
  }
  return out;
}

int report(const Result& result, const CliStreams& io) {
  if (!result) {
    io.err << "stripemux config: " << printable(result.error().message) << "\n";
    return result.error().code;
  }
  io.out << *result;
  return kExitOk;
}

}  // namespace

void addConfigCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<ConfigOptions>();
  auto* cmd = app.add_subcommand("config", "Read and change a device's settings (docs/config.md)");
  cmd->add_option("--device", opts->device, "HOST[:PORT] of the device (default port 5555)")
      ->check(deviceAddressValidator());
  cmd->require_subcommand(1);

  auto* get = cmd->add_subcommand("get", "Print the settings the device runs with, or one");
  get->add_option("KEY", opts->key, "one setting: " + settingKeysList());
  get->callback([opts, &io, &exitCode] { exitCode = report(runGet(*opts), io); });

  auto* set = cmd->add_subcommand(
      "set",
      "Change settings: KEY=VALUE… (rig=FILE installs a rig.json); the device stores "
      "them and restarts with them");
  set->add_option("KEY=VALUE", opts->assign, "settings: " + settingKeysList())->required();
  set->callback([opts, &io, &exitCode] {
    auto change = changeFromAssignments(opts->assign);
    exitCode = report(change ? runChange(*opts, protocol::SetConfigMode::kChange, *change)
                             : Result(std::unexpected(change.error())),
                      io);
  });

  auto* apply = cmd->add_subcommand(
      "apply", "Change the settings a config.json file or a preset names (others stay)");
  apply->add_option("FILE|PRESET", opts->source, "a stripemux-config/1 file or a preset name")
      ->required();
  apply->callback([opts, &io, &exitCode] {
    auto change = changeFromSource(opts->source);
    exitCode = report(change ? runChange(*opts, protocol::SetConfigMode::kChange, *change)
                             : Result(std::unexpected(change.error())),
                      io);
  });

  auto* reset = cmd->add_subcommand("reset", "Drop every stored setting: the board's apply");
  reset->callback([opts, &io, &exitCode] {
    exitCode = report(runChange(*opts, protocol::SetConfigMode::kReset, ""), io);
  });

  auto* presets = cmd->add_subcommand("presets", "List the presets `apply` knows");
  presets->callback([&io, &exitCode] {
    io.out << presetList();
    exitCode = kExitOk;
  });
}

}  // namespace smx::host
