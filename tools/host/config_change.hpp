#pragma once

#include <expected>
#include <string>
#include <string_view>
#include <vector>

// `stripemux config set KEY=VALUE…` as a change document, shared by the command and the live
// view's settings panel (docs/config.md).
namespace smx::host {

struct ConfigChangeFailure {
  int code;  // the command's exit code for it (cli.hpp)
  std::string message;
};

// KEY=VALUE… as a stripemux-config/1 change. A value is JSON when it reads as JSON (numbers),
// else a word (compression=rvl); projectors=ID,ID is a list; rig=FILE embeds that rig.json. The
// device checks the values.
[[nodiscard]] std::expected<std::string, ConfigChangeFailure> changeFromAssignments(
    const std::vector<std::string>& assign);

// The setting keys, comma-separated, for messages.
[[nodiscard]] std::string settingKeysList();
[[nodiscard]] bool isSettingKey(std::string_view key);

}  // namespace smx::host
