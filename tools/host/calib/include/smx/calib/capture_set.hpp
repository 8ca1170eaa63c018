#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <vector>

#include "smx/algo/rig.hpp"
#include "smx/calib/target.hpp"

// A folder of calibration captures (docs/calibration.md): target.json and pose<NN>/ folders,
// each with <cam>.png (every projector off) and <proj>.<cam>.png (only that projector on).
namespace smx::calib {

struct PoseFiles {
  std::string name;  // "pose00"
  // Per camera of the rig: the projector-off image, or empty when the pose has none.
  std::vector<std::filesystem::path> off;
  // [projector][camera]: that projector's image, or empty.
  std::vector<std::vector<std::filesystem::path>> lit;
};

struct CaptureSet {
  std::filesystem::path dir;
  Target target;
  std::vector<PoseFiles> poses;    // in name order
  std::vector<std::string> notes;  // files missing in some poses, for the report
};

// Reads target.json and lists the pose folders. Ids of the rig name the files; anything that
// is not a pose folder is ignored; frames missing in some poses are notes. Errors: no
// target.json, a bad one, no pose folder.
[[nodiscard]] std::expected<CaptureSet, std::string> openCaptureSet(
    const std::filesystem::path& dir, const algo::Rig& rig);

// Whether the set can calibrate `rig` at all, before any image is read: fewer than kMinPoses
// poses, a camera's or projector's frame missing in every pose, or a pose folder copied from
// another (byte-identical frames) are errors naming what to do.
[[nodiscard]] std::expected<void, std::string> checkCaptureSet(const CaptureSet& set,
                                                               const algo::Rig& rig);

}  // namespace smx::calib
