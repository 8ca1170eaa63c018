#include "smx/calib/capture_set.hpp"

#include <algorithm>
#include <cctype>
#include <system_error>

namespace smx::calib {
namespace fs = std::filesystem;
namespace {

// "pose" and two digits: names, never paths, whatever else the folder holds.
bool isPoseName(const std::string& name) {
  return name.size() == 6 && name.starts_with("pose") &&
         std::isdigit(static_cast<unsigned char>(name[4])) != 0 &&
         std::isdigit(static_cast<unsigned char>(name[5])) != 0;
}

fs::path existing(const fs::path& file, std::vector<std::string>& notes, const std::string& what) {
  std::error_code ec;
  if (fs::is_regular_file(file, ec)) {
    return file;
  }
  notes.push_back(what + " missing: " + file.string());
  return {};
}

}  // namespace

std::expected<CaptureSet, std::string> openCaptureSet(const fs::path& dir, const algo::Rig& rig) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return std::unexpected(dir.string() + ": not a folder of captures");
  }
  auto target = loadTarget(dir / "target.json");
  if (!target) {
    return std::unexpected(target.error());
  }
  CaptureSet set{.dir = dir, .target = *target, .poses = {}, .notes = {}};
  std::vector<std::string> names;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (isPoseName(name) && it->is_directory(ec)) {
      names.push_back(name);
    }
  }
  if (ec) {
    return std::unexpected(dir.string() + ": cannot list the folder: " + ec.message());
  }
  if (names.empty()) {
    return std::unexpected(dir.string() +
                           ": no pose folders (pose00, pose01, …): capture the target first");
  }
  std::ranges::sort(names);
  for (const std::string& name : names) {
    PoseFiles pose{.name = name, .off = {}, .lit = {}};
    const fs::path poseDir = dir / name;
    for (const auto& camera : rig.cameras) {
      pose.off.push_back(
          existing(poseDir / (camera.id + ".png"), set.notes, name + ": " + camera.id + " frame"));
    }
    for (const auto& projector : rig.projectors) {
      auto& files = pose.lit.emplace_back();
      for (const auto& camera : rig.cameras) {
        files.push_back(existing(poseDir / (projector.id + "." + camera.id + ".png"), set.notes,
                                 name + ": " + projector.id + " frame of " + camera.id));
      }
    }
    set.poses.push_back(std::move(pose));
  }
  return set;
}

}  // namespace smx::calib
