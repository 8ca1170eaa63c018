#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <vector>

// The host tool's data and the named scenes in it (plane, sphere, bunny, turntable, ...): a scene
// argument is a scene.json path or one of these names.
namespace smx::sim {

// The data folder: scenes/ (the named scenes and their meshes) and boards/ (the example boards and
// rigs). The first of: $STRIPEMUX_DATA_DIR; the installed share/stripemux beside the running
// executable's bin folder (found through /proc/self/exe, so an installed tree works wherever it
// is); in a build tree, the stripemux-data folder that configuring writes at its top (links into
// the source tree), found from any executable below it. The error names the places looked at.
[[nodiscard]] std::expected<std::filesystem::path, std::string> dataDir();
// The named scenes' folder: $STRIPEMUX_SCENES, else the data folder's scenes/.
[[nodiscard]] std::expected<std::filesystem::path, std::string> sceneDir();
// The names, sorted; none when the folder is not found.
[[nodiscard]] std::vector<std::string> namedScenes();
// A path if `arg` names a file (or looks like one), else the named scene; the error lists the
// names.
[[nodiscard]] std::expected<std::filesystem::path, std::string> resolveScene(
    const std::string& arg);

}  // namespace smx::sim
