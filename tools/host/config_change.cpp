#include "config_change.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "smx/config/device_config.hpp"
#include "smx/config/rig_json.hpp"
#include "terminal_text.hpp"

namespace smx::host {

using Json = nlohmann::json;

bool isSettingKey(std::string_view key) {
  const auto keys = config::deviceConfigKeys();
  return std::ranges::find(keys, key) != keys.end();
}

std::string settingKeysList() {
  std::string list;
  for (const auto key : config::deviceConfigKeys()) {
    list += (list.empty() ? "" : ", ") + std::string(key);
  }
  return list;
}

namespace {

Json projectorList(const std::string& ids) {
  Json list = Json::array();
  std::size_t from = 0;
  while (from <= ids.size()) {
    const std::size_t comma = std::min(ids.find(',', from), ids.size());
    list.push_back(ids.substr(from, comma - from));
    from = comma + 1;
  }
  return list;
}

}  // namespace

std::expected<std::string, ConfigChangeFailure> changeFromAssignments(
    const std::vector<std::string>& assign) {
  Json doc = Json::object();
  doc["format"] = config::kDeviceConfigFormat;
  for (const std::string& item : assign) {
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq);
    if (eq == std::string::npos || eq + 1 == item.size()) {
      return std::unexpected(ConfigChangeFailure{
          kExitUsage, "set: expected KEY=VALUE, got \"" + printable(item) + "\""});
    }
    if (!isSettingKey(key)) {
      return std::unexpected(ConfigChangeFailure{
          kExitUsage,
          "set: no setting \"" + printable(key) + "\"; settings: " + settingKeysList()});
    }
    const std::string value = item.substr(eq + 1);
    if (key == "rig") {
      // Read and checked here, so that a broken file is named; the device checks it fits.
      const auto rig = config::loadRig(value);
      if (!rig) {
        return std::unexpected(
            ConfigChangeFailure{kExitBadInput, "set rig: " + rig.error().message()});
      }
      doc[key] = Json::parse(config::toJson(*rig));
      continue;
    }
    const Json parsed = Json::parse(value, nullptr, false);
    if (key == "projectors" && !parsed.is_array()) {
      doc[key] = projectorList(value);  // projectors=proj0,proj2
      continue;
    }
    doc[key] = parsed.is_discarded() ? Json(value) : parsed;
  }
  return doc.dump();
}

}  // namespace smx::host
