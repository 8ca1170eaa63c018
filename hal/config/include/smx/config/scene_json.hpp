#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

#include "smx/sim/scene.hpp"

// scene.json, format `stripemux-scene/1`: what the simulated rig looks at (docs/scene-format.md).
// Reading also loads the meshes (mesh_io.hpp) and PNG textures the scene names.
//
// Init-time code: allocates, uses double. parseScene() and loadScene() never throw (even on
// out-of-memory); every failure is a SceneError naming the offending field.
namespace smx::config {

// The `format` value this build reads.
inline constexpr std::string_view kSceneFormat = "stripemux-scene/1";

struct SceneError {
  std::string file;     // set by loadScene(); empty for parseScene()
  std::string field;    // JSON path, e.g. "objects[2].pose.t" or "lighting.ambient[1]"; empty =
                        // the document as a whole
  std::string problem;  // what is wrong, for an end user, e.g. "must be positive, got 0"

  // "file: field: problem", leaving out the empty parts.
  [[nodiscard]] std::string message() const;
};

// Parses and validates a scene.json document and reports the first problem in file order: JSON
// syntax, the format, duplicate keys, unknown keys, then each section and object (types and
// array lengths, then the value rules, then its mesh or texture file). Relative mesh and texture
// paths resolve against `baseDir`; sim::Mesh::path and sim::ImageTexture::path hold the resolved
// paths. Keys left out take the defaults of scene.hpp.
[[nodiscard]] std::expected<sim::Scene, SceneError> parseScene(
    std::string_view jsonText, const std::filesystem::path& baseDir);

// The value rules of scene.json applied to a scene built in memory or changed after reading:
// ranges, rotations, supersampling 1 to sim::kMaxSceneSupersampling, at least one object, and
// meshes and textures loaded. parseScene() applies the same rules as it reads (object names are
// checked only there: they are the file's); the renderer refuses every scene this refuses, with
// this message, and no other. Field paths are as in the JSON.
[[nodiscard]] std::expected<void, SceneError> validateScene(const sim::Scene& scene);

// Reads `file` and parses it with baseDir = the file's directory; an unreadable file is an error
// (SceneError::file names it, as it does for every error found in the file).
[[nodiscard]] std::expected<sim::Scene, SceneError> loadScene(const std::filesystem::path& file);

}  // namespace smx::config
