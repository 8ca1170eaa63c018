#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <vector>

// The named scenes of hal/sim/scenes (plane, sphere, bunny, turntable, ...): a scene argument is
// a scene.json path or one of these names. STRIPEMUX_SCENES overrides the folder.
namespace smx::sim {

[[nodiscard]] std::filesystem::path sceneDir();
[[nodiscard]] std::vector<std::string> namedScenes();
// A path if `arg` names a file (or looks like one), else the named scene; the error lists the
// names.
[[nodiscard]] std::expected<std::filesystem::path, std::string> resolveScene(
    const std::string& arg);

}  // namespace smx::sim
