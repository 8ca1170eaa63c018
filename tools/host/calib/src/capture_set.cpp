#include "smx/calib/capture_set.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <system_error>
#include <utility>

#include "smx/calib/camera_calibration.hpp"

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

std::string fileText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A device whose frame is missing in every pose cannot be solved at all.
std::expected<void, std::string> presentSomewhere(const std::vector<PoseFiles>& poses,
                                                  const std::string& device,
                                                  const std::string& file, const auto& pick) {
  if (std::ranges::any_of(poses, [&](const PoseFiles& p) { return !pick(p).empty(); })) {
    return {};
  }
  return std::unexpected(device + ": " + file + " is missing in every pose (" + poses.front().name +
                         " … " + poses.back().name + "): capture each pose " + "with " + device +
                         " again, or leave " + device + " out of --rig");
}

// Two poses with byte-identical frames are one pose copied: real exposures always differ.
std::expected<void, std::string> checkCopies(const std::vector<PoseFiles>& poses) {
  std::vector<std::string> seen(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (poses[i].off.empty() || poses[i].off[0].empty()) {
      continue;
    }
    seen[i] = fileText(poses[i].off[0]);
    for (std::size_t j = 0; j < i; ++j) {
      if (!seen[j].empty() && seen[j] == seen[i]) {
        return std::unexpected(poses[i].name + " repeats " + poses[j].name + " (" +
                               poses[i].off[0].filename().string() +
                               " is the same file): remove the copy or capture a new pose");
      }
    }
  }
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

std::expected<void, std::string> checkCaptureSet(const CaptureSet& set, const algo::Rig& rig) {
  if (std::cmp_less(set.poses.size(), kMinPoses)) {
    return std::unexpected(
        set.dir.string() + ": " + std::to_string(set.poses.size()) +
        " pose folders (pose00, pose01, …); at least " + std::to_string(kMinPoses) +
        " are needed: capture more poses, the target tilted differently in each");
  }
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    const std::string& cam = rig.cameras[c].id;
    auto ok = presentSomewhere(set.poses, cam, cam + ".png",
                               [c](const PoseFiles& p) -> const fs::path& { return p.off[c]; });
    for (std::size_t j = 0; ok && j < rig.projectors.size(); ++j) {
      const std::string& proj = rig.projectors[j].id;
      std::string file = proj;
      file.append(".").append(cam).append(".png");
      ok = presentSomewhere(set.poses, proj, file,
                            [c, j](const PoseFiles& p) -> const fs::path& { return p.lit[j][c]; });
    }
    if (!ok) {
      return std::unexpected(ok.error());
    }
  }
  if (auto ok = checkCopies(set.poses); !ok) {
    return std::unexpected(ok.error());
  }
  return {};
}

}  // namespace smx::calib
