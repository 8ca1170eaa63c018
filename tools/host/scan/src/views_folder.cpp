#include "smx/scan/views_folder.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <exception>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "smx/config/json_reader.hpp"
#include "smx/config/rig_json.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::scan {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr std::array<std::string_view, 5> kTopKeys = {"format", "depth_unit_m", "mode", "views",
                                                      "turntable_axis"};
constexpr std::array<std::string_view, 4> kViewKeys = {"id", "capture_ns", "turntable_deg", "pose"};

// views.json lists views, not pixels: 10 MB is a few ten thousand views.
constexpr config::DocumentSpec kViewsDocument = {.name = "views.json",
                                                 .format = kViewsFormat,
                                                 .topKeys = kTopKeys,
                                                 .maxBytes = std::size_t{10} << 20U,
                                                 .sizeNote = "",
                                                 .nestingNeeded = 4,
                                                 .maxNesting = 16,
                                                 .otherFormats = {}};
// A stream folder is listed entry by entry; beyond this many entries it is not one.
constexpr std::size_t kMaxFolderEntries = 1000000;

std::string fail(const fs::path& file, std::string_view field, std::string_view problem) {
  std::string out = file.string() + ": ";
  if (!field.empty()) {
    out += std::string(field) + ": ";
  }
  return out + std::string(problem);
}

std::optional<double> finiteNumber(const Json& j) {
  if (!j.is_number()) {
    return std::nullopt;
  }
  const double v = j.get<double>();
  return std::isfinite(v) ? std::optional(v) : std::nullopt;
}

std::expected<Eigen::Vector3d, std::string> vector3(const Json& j, const fs::path& file,
                                                    const std::string& field) {
  if (!j.is_array() || j.size() != 3) {
    return std::unexpected(fail(file, field, "must be an array of 3 numbers"));
  }
  Eigen::Vector3d v;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto x = finiteNumber(j[k]);
    if (!x) {
      return std::unexpected(fail(file, field, "must be an array of 3 finite numbers"));
    }
    v[static_cast<Eigen::Index>(k)] = *x;
  }
  return v;
}

std::expected<TurntableAxis, std::string> axisOf(const Json& j, const fs::path& file,
                                                 const std::string& field,
                                                 std::string_view directionKey) {
  if (!j.is_object() || !j.contains(directionKey) || !j.contains("point")) {
    return std::unexpected(
        fail(file, field,
             R"(must be an object with ")" + std::string(directionKey) + R"(" and "point")"));
  }
  auto direction =
      vector3(j[std::string(directionKey)], file, field + "." + std::string(directionKey));
  if (!direction) {
    return std::unexpected(direction.error());
  }
  auto point = vector3(j["point"], file, field + ".point");
  if (!point) {
    return std::unexpected(point.error());
  }
  if (direction->norm() < 1e-9) {
    return std::unexpected(fail(file, field, "the axis direction must not be zero"));
  }
  return TurntableAxis{direction->normalized(), *point};
}

std::expected<Pose, std::string> poseOf(const Json& j, const fs::path& file,
                                        const std::string& field) {
  if (!j.is_array() || j.size() != 16) {
    return std::unexpected(fail(file, field, "must be 16 numbers (a row-major 4x4 matrix)"));
  }
  Eigen::Matrix4d m;
  for (std::size_t k = 0; k < 16; ++k) {
    const auto v = finiteNumber(j[k]);
    if (!v) {
      return std::unexpected(fail(file, field, "must be 16 finite numbers"));
    }
    m(static_cast<Eigen::Index>(k / 4), static_cast<Eigen::Index>(k % 4)) = *v;
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const bool rigid = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
                     r.determinant() > 0 && m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1));
  if (!rigid) {
    return std::unexpected(
        fail(file, field, "must be a rigid motion (a rotation, a translation, last row 0 0 0 1)"));
  }
  return Pose(m);
}

// A camera's image of a view, its size checked against the rig before its pixels exist.
std::expected<CameraRange, std::string> readCamera(const algo::Camera& camera,
                                                   const fs::path& depthFile,
                                                   const std::optional<fs::path>& colourFile) {
  const std::string owner = "camera " + camera.id + " of the rig";
  const auto limit = sim::PngSizeLimit::exactly(camera.width, camera.height, owner);
  std::error_code ec;
  if (!fs::is_regular_file(depthFile, ec)) {
    return std::unexpected(depthFile.string() + ": missing (every view has every camera's depth)");
  }
  auto depth = sim::readPngGray16(depthFile, limit);
  if (!depth) {
    return std::unexpected(depth.error());
  }
  CameraRange range;
  range.width = depth->width;
  range.height = depth->height;
  range.depth = std::move(depth->pixels);
  if (colourFile && fs::is_regular_file(*colourFile, ec)) {
    auto colour = sim::readPngRgb8(*colourFile, limit);
    if (!colour) {
      return std::unexpected(colour.error());
    }
    range.colour.reserve(colour->pixels.size());
    for (const auto& p : colour->pixels) {
      range.colour.push_back({p.r, p.g, p.b});
    }
  }
  return range;
}

std::expected<ScanMode, std::string> modeOf(const Json& j, const fs::path& file) {
  if (j == "turntable") {
    return ScanMode::kTurntable;
  }
  if (j == "handheld") {
    return ScanMode::kHandheld;
  }
  if (j == "stream") {
    return ScanMode::kStream;
  }
  return std::unexpected(fail(file, "mode", R"(must be "turntable", "handheld" or "stream")"));
}

std::string_view modeName(ScanMode mode) {
  switch (mode) {
    case ScanMode::kTurntable:
      return "turntable";
    case ScanMode::kHandheld:
      return "handheld";
    case ScanMode::kStream:
      return "stream";
  }
  return "stream";
}

std::expected<void, std::string> readScanViews(const fs::path& dir, std::size_t maxViews,
                                               ViewsFolder& folder) {
  const fs::path file = dir / "views" / "views.json";
  auto text = config::readDocumentFile(file, kViewsDocument);
  if (!text) {
    return std::unexpected(fail(file, text.error().field, text.error().problem));
  }
  auto doc = config::parseDocument(*text, kViewsDocument);
  if (!doc) {
    return std::unexpected(fail(file, doc.error().field, doc.error().problem));
  }
  const auto unit = doc->contains("depth_unit_m") ? finiteNumber((*doc)["depth_unit_m"])
                                                  : std::optional<double>(1e-4);
  if (!unit || *unit <= 0 || *unit > 0.01) {
    return std::unexpected(fail(file, "depth_unit_m", "must be a number in (0, 0.01] metres"));
  }
  if (doc->contains("mode")) {
    auto mode = modeOf((*doc)["mode"], file);
    if (!mode) {
      return std::unexpected(mode.error());
    }
    folder.mode = *mode;
  }
  if (doc->contains("turntable_axis") && !folder.axis) {
    auto axis = axisOf((*doc)["turntable_axis"], file, "turntable_axis", "direction");
    if (!axis) {
      return std::unexpected(axis.error());
    }
    folder.axis = *axis;
  }
  const Json& views = (*doc)["views"];
  if (!views.is_array()) {
    return std::unexpected(fail(file, "views", "must be an array"));
  }
  if (views.size() > maxViews) {
    return std::unexpected(fail(file, "views",
                                "has " + std::to_string(views.size()) + " views, at most " +
                                    std::to_string(maxViews) + " are read"));
  }
  for (std::size_t i = 0; i < views.size(); ++i) {
    const std::string field = "views[" + std::to_string(i) + "]";
    const Json& v = views[i];
    if (!v.is_object()) {
      return std::unexpected(fail(file, field, "must be an object"));
    }
    if (auto key = config::unknownKey(v, kViewKeys)) {
      return std::unexpected(fail(file, field, config::unknownKeyProblem(*key, kViewKeys)));
    }
    if (!v.contains("id") || !v["id"].is_string()) {
      return std::unexpected(fail(file, field + ".id", "must be a string"));
    }
    RangeView view;
    view.id = v["id"].get<std::string>();
    if (auto problem = viewIdProblem(view.id)) {
      return std::unexpected(fail(file, field + ".id", *problem));
    }
    for (const auto& other : folder.views) {
      if (other.id == view.id) {
        return std::unexpected(fail(file, field + ".id", "\"" + view.id + "\" is listed twice"));
      }
    }
    view.depthUnitM = *unit;
    if (v.contains("capture_ns")) {
      if (!v["capture_ns"].is_number_integer()) {
        return std::unexpected(fail(file, field + ".capture_ns", "must be an integer"));
      }
      view.captureNs = v["capture_ns"].get<std::int64_t>();
    }
    if (v.contains("turntable_deg")) {
      const auto deg = finiteNumber(v["turntable_deg"]);
      if (!deg || std::abs(*deg) > 36000) {
        return std::unexpected(
            fail(file, field + ".turntable_deg", "must be a finite number of degrees"));
      }
      view.turntableDeg = *deg;
    }
    std::optional<Pose> pose;
    if (v.contains("pose")) {
      auto p = poseOf(v["pose"], file, field + ".pose");
      if (!p) {
        return std::unexpected(p.error());
      }
      pose = *p;
    }
    const fs::path viewDir = dir / "views" / view.id;
    for (const auto& camera : folder.rig.cameras) {
      auto range = readCamera(camera, viewDir / (camera.id + ".depth.png"),
                              viewDir / (camera.id + ".colour.png"));
      if (!range) {
        return std::unexpected(range.error());
      }
      view.cameras.push_back(std::move(*range));
    }
    folder.views.push_back(std::move(view));
    folder.poses.push_back(pose);
  }
  return {};
}

// `name` as <camera id>_<n>.depth.png of a rig camera: the camera's index and n.
std::optional<std::pair<std::size_t, std::uint64_t>> streamFrame(const std::string& name,
                                                                 const algo::Rig& rig) {
  constexpr std::string_view kSuffix = ".depth.png";
  if (name.size() <= kSuffix.size() || !name.ends_with(kSuffix)) {
    return std::nullopt;
  }
  const std::string stem = name.substr(0, name.size() - kSuffix.size());
  const auto underscore = stem.rfind('_');
  if (underscore == std::string::npos) {
    return std::nullopt;
  }
  std::uint64_t n = 0;
  const char* first = stem.data() + underscore + 1;
  const char* last = stem.data() + stem.size();
  const auto [end, ec] = std::from_chars(first, last, n);
  if (ec != std::errc{} || end != last || first == last) {
    return std::nullopt;
  }
  for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
    if (rig.cameras[c].id == std::string_view{stem}.substr(0, underscore)) {
      return std::pair{c, n};
    }
  }
  return std::nullopt;
}

std::expected<void, std::string> readStreamViews(const fs::path& dir, std::size_t maxViews,
                                                 ViewsFolder& folder) {
  folder.mode = ScanMode::kStream;
  double unit = 1e-4;
  const fs::path summary = dir / "summary.json";
  std::error_code ec;
  if (fs::is_regular_file(summary, ec)) {
    // summary.json is stream's own (docs/cli.md); only its depth unit is read.
    config::DocumentSpec spec = kViewsDocument;
    spec.name = "summary.json";
    auto text = config::readDocumentFile(summary, spec);
    if (!text) {
      return std::unexpected(fail(summary, text.error().field, text.error().problem));
    }
    const Json doc = Json::parse(*text, nullptr, false);
    if (doc.is_object() && doc.contains("depth_unit_m")) {
      const auto u = finiteNumber(doc["depth_unit_m"]);
      if (!u || *u <= 0 || *u > 0.01) {
        return std::unexpected(fail(summary, "depth_unit_m", "must be a number in (0, 0.01]"));
      }
      unit = *u;
    }
  }
  std::map<std::uint64_t, std::vector<std::string>> frames;  // n → file per camera
  std::size_t entries = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (++entries > kMaxFolderEntries) {
      return std::unexpected(dir.string() + ": more than " + std::to_string(kMaxFolderEntries) +
                             " entries; not a stream folder");
    }
    const auto frame = streamFrame(it->path().filename().string(), folder.rig);
    if (!frame) {
      continue;
    }
    auto& files = frames[frame->second];
    files.resize(folder.rig.cameras.size());
    files[frame->first] = it->path().filename().string();
  }
  if (ec) {
    return std::unexpected(dir.string() + ": cannot list: " + ec.message());
  }
  for (const auto& [n, files] : frames) {
    if (std::ranges::any_of(files, [](const std::string& f) { return f.empty(); })) {
      continue;  // a frame some camera did not deliver
    }
    if (folder.views.size() == maxViews) {
      return std::unexpected(dir.string() + ": more than " + std::to_string(maxViews) +
                             " frames; at most that many are read");
    }
    RangeView view;
    std::ostringstream id;
    id.width(5);
    id.fill('0');
    id << n;
    view.id = id.str();
    view.depthUnitM = unit;
    for (std::size_t c = 0; c < files.size(); ++c) {
      auto range = readCamera(folder.rig.cameras[c], dir / files[c], std::nullopt);
      if (!range) {
        return std::unexpected(range.error());
      }
      view.cameras.push_back(std::move(*range));
    }
    folder.views.push_back(std::move(view));
    folder.poses.emplace_back();
  }
  if (folder.views.empty()) {
    return std::unexpected(dir.string() +
                           ": no views (neither views/views.json nor <camera>_<n>.depth.png "
                           "of every rig camera)");
  }
  return {};
}

void putPose(Json& j, const Pose& pose) {
  Json m = Json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      m.push_back(pose.matrix()(r, c));
    }
  }
  j = std::move(m);
}

}  // namespace

std::optional<std::string> viewIdProblem(std::string_view id) {
  if (id.empty() || id.size() > 64) {
    return "a view id has 1 to 64 characters";
  }
  for (const char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) {
      return "a view id is a name of A-Z a-z 0-9 _ -, not a path (\"" + std::string(id) + "\")";
    }
  }
  return std::nullopt;
}

std::expected<ViewsFolder, std::string> readViewsFolder(const fs::path& dir, std::size_t maxViews) {
  try {
    ViewsFolder folder;
    const fs::path rigFile = dir / "rig.json";
    // rig.json's "turntable" is the other part of this format; parseRig refuses keys it does not
    // know, so the axis is taken out before.
    config::DocumentSpec rigSpec = kViewsDocument;
    rigSpec.name = "rig.json";
    auto text = config::readDocumentFile(rigFile, rigSpec);
    if (!text) {
      return std::unexpected(fail(rigFile, text.error().field, text.error().problem));
    }
    Json rigDoc = Json::parse(*text, nullptr, false);
    if (rigDoc.is_object() && rigDoc.contains("turntable")) {
      auto axis = axisOf(rigDoc["turntable"], rigFile, "turntable", "axis");
      if (!axis) {
        return std::unexpected(axis.error());
      }
      folder.axis = *axis;
      rigDoc.erase("turntable");
      *text = rigDoc.dump();
    }
    auto rig = config::parseRig(*text);
    if (!rig) {
      auto error = rig.error();
      error.file = rigFile.string();
      return std::unexpected(error.message());
    }
    folder.rig = std::move(*rig);
    std::error_code ec;
    auto read = fs::exists(dir / "views" / "views.json", ec)
                    ? readScanViews(dir, maxViews, folder)
                    : readStreamViews(dir, maxViews, folder);
    if (!read) {
      return std::unexpected(read.error());
    }
    return folder;
  } catch (const std::exception& e) {  // out of memory, a filesystem error
    return std::unexpected(dir.string() + ": cannot read the views: " + e.what());
  }
}

std::string viewsJson(ScanMode mode, double depthUnitM, const std::vector<ViewEntry>& views,
                      const std::optional<TurntableAxis>& axis) {
  Json doc;
  doc["format"] = kViewsFormat;
  doc["depth_unit_m"] = depthUnitM;
  doc["mode"] = modeName(mode);
  if (axis) {
    doc["turntable_axis"] = {
        {"direction", {axis->direction.x(), axis->direction.y(), axis->direction.z()}},
        {"point", {axis->point.x(), axis->point.y(), axis->point.z()}}};
  }
  Json list = Json::array();
  for (const auto& v : views) {
    Json j;
    j["id"] = v.id;
    j["capture_ns"] = v.captureNs;
    if (v.turntableDeg) {
      j["turntable_deg"] = *v.turntableDeg;
    }
    if (v.pose) {
      putPose(j["pose"], *v.pose);
    }
    list.push_back(std::move(j));
  }
  doc["views"] = std::move(list);
  return doc.dump(2) + "\n";
}

std::string posesJson(const std::vector<std::string>& ids, const std::vector<Pose>& poses) {
  Json doc;
  doc["format"] = "stripemux-poses/1";
  Json list = Json::array();
  for (std::size_t i = 0; i < std::min(ids.size(), poses.size()); ++i) {
    Json j;
    j["id"] = ids[i];
    putPose(j["pose"], poses[i]);
    list.push_back(std::move(j));
  }
  doc["poses"] = std::move(list);
  return doc.dump(2) + "\n";
}

}  // namespace smx::scan
