#pragma once

#include <filesystem>

// The folder tests/fuzz/files: what the inputs of the board and scene targets may name by a
// relative path (a rig, meshes, a texture). The only file of the fuzz build that names the source
// folder.
namespace smx::fuzz {

[[nodiscard]] std::filesystem::path filesDir();

}  // namespace smx::fuzz
