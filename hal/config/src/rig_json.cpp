#include "smx/config/rig_json.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <exception>
#include <map>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "smx/algo/demux.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/config/identifier.hpp"
#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"
#include "smx/config/json_paths.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/json_text.hpp"
#include "smx/config/rotation_check.hpp"

namespace smx::config {
namespace {

using Json = nlohmann::json;
using Status = std::expected<void, RigError>;

// Physical plausibility (docs/rig-format.md, "Limits"): values no real rig has are typos or
// hostile, and refusing them here keeps every later allocation and computation bounded.
// 8192: larger than any projector and than the cameras a board decodes at video rate; 8192² RGB
// is 200 MB, so a rig can never make a command allocate more than a few GB.
constexpr int kMaxImageSidePx = 8192;
// Smaller images cannot hold a code window of stripes or one demultiplexing tile.
constexpr int kMinImageSidePx = 16;
// Focal lengths from 0.1 (a fisheye's 157 degree field) to 100 (0.6 degree) times the image side.
constexpr double kMinFocalPerSide = 0.1;
constexpr double kMaxFocalPerSide = 100.0;
// Lens distortion coefficients beyond this bend a ray by more than any lens a scanner uses.
constexpr double kMaxDistortion = 100.0;
// A rig fits in a room: every translation component within 100 m of the world origin.
constexpr double kMaxTranslationM = 100.0;
constexpr double kMaxAngleDeg = 360.0;
// A stripe narrower than a projector pixel cannot be shown.
constexpr double kMinStripePx = 1.0;
// Boards read at most this many cameras (the wire numbers them in one byte).
constexpr std::size_t kMaxCameras = 16;
constexpr std::string_view kKStructure = "K is [fx 0 cx; 0 fy cy; 0 0 1]";

constexpr std::array<std::string_view, 3> kTopKeys = {"format", "cameras", "projectors"};
constexpr std::array<std::string_view, 7> kCameraKeys = {"id",   "width", "height", "K",
                                                         "dist", "R",     "t"};
constexpr std::array<std::string_view, 8> kProjectorKeys = {"id",   "width", "height", "K",
                                                            "dist", "R",     "t",      "pattern"};
constexpr std::array<std::string_view, 3> kPatternKeys = {"angle_deg", "stripe_px", "offset_px"};

// A rig.json is a few kB and 4 levels deep; the bounds keep a hostile or mistaken input (a video
// file, /dev/zero, "[[[[...") from costing the board more than a few MB.
constexpr DocumentSpec kRigDocument = {.name = "rig.json",
                                       .format = kRigFormat,
                                       .topKeys = kTopKeys,
                                       .maxBytes = std::size_t{1} << 20U,
                                       .sizeNote = "",
                                       .nestingNeeded = 4,
                                       .maxNesting = 16,
                                       .otherFormats = {}};

std::unexpected<RigError> fail(std::string field, std::string problem) {
  return std::unexpected(RigError{{}, std::move(field), std::move(problem)});
}

std::unexpected<RigError> fail(FieldError e) {
  return fail(std::move(e.field), std::move(e.problem));
}

// Unknown keys are errors; the closest allowed key, or `hint`, is suggested.
Status checkKeys(const Json& obj, const std::string& path, Keys allowed,
                 std::string_view hint = {}) {
  if (const auto key = unknownKey(obj, allowed)) {
    return fail(path, unknownKeyProblem(*key, allowed, hint));
  }
  return {};
}

std::expected<double, RigError> readNumber(const Json& v, const std::string& path) {
  if (!v.is_number()) {
    return fail(path, "must be a number, got " + describe(v));
  }
  const double d = v.get<double>();
  if (!std::isfinite(d)) {
    return fail(path, "must be a finite number, got " + formatNumber(d));
  }
  return d;
}

std::expected<std::string, RigError> readString(const Json& v, const std::string& path) {
  if (!v.is_string()) {
    return fail(path, "must be a string, got " + describe(v));
  }
  return v.get<std::string>();
}

std::string sizeProblem(double v) {
  if (v != std::floor(v) || v < 1) {
    return "must be a positive integer (pixels), got " + formatNumber(v);
  }
  return "must be from " + std::to_string(kMinImageSidePx) + " to " +
         std::to_string(kMaxImageSidePx) + " pixels, got " + formatNumber(v);
}

std::expected<int, RigError> readSize(const Json& v, const std::string& path) {
  auto d = readNumber(v, path);
  if (!d) {
    return std::unexpected(d.error());
  }
  // 640.0 is accepted: it is an integer, only written differently.
  if (*d != std::floor(*d) || *d < kMinImageSidePx || *d > kMaxImageSidePx) {
    return fail(path, sizeProblem(*d));
  }
  return static_cast<int>(*d);
}

template <std::size_t N>
Status readArray(const Json& v, const std::string& path, std::string_view what,
                 std::array<double, N>& out) {
  if (!v.is_array() || v.size() != N) {
    return fail(path, "must be an array of " + std::to_string(N) + " numbers (" +
                          std::string(what) + "), got " + describe(v));
  }
  for (std::size_t i = 0; i < N; ++i) {
    auto d = readNumber(v[i], element(path, i));
    if (!d) {
      return std::unexpected(d.error());
    }
    out[i] = *d;
  }
  return {};
}

// --- value rules, shared by parseRig() and validateRig() ---

Status checkFinite(std::span<const double> values, const std::string& path) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return fail(element(path, i), "must be a finite number, got " + formatNumber(values[i]));
    }
  }
  return {};
}

Status checkSize(int v, const std::string& path) {
  if (v < kMinImageSidePx || v > kMaxImageSidePx) {
    return fail(path, sizeProblem(v));
  }
  return {};
}

Status checkIntrinsics(const std::array<double, 9>& intrinsics, const std::string& path) {
  for (std::size_t i = 0; i < intrinsics.size(); ++i) {
    const double k = intrinsics[i];
    const std::string got = ", got " + formatNumber(k);
    const std::string at = element(path, i);
    if (i == 0 && !(k > 0)) {
      return fail(at, "fx must be positive" + got);
    }
    if (i == 4 && !(k > 0)) {
      return fail(at, "fy must be positive" + got);
    }
    if (i == 1 && k != 0) {
      return fail(at, "skew must be 0 (" + std::string(kKStructure) + ")" + got);
    }
    if ((i == 3 || i == 6 || i == 7) && k != 0) {
      return fail(at, "must be 0 (" + std::string(kKStructure) + ")" + got);
    }
    if (i == 8 && k != 1) {
      return fail(at, "must be 1 (" + std::string(kKStructure) + ")" + got);
    }
  }
  return {};
}

// Called after checkIntrinsics: K has its structure, fx and fy are positive.
Status checkIntrinsicsPlausible(const algo::DeviceModel& d, const std::string& path) {
  struct Entry {
    std::size_t index;
    double lo;
    double hi;
    const char* what;
  };
  const double w = d.width;
  const double h = d.height;
  const std::array<Entry, 4> entries = {{
      {0, kMinFocalPerSide * w, kMaxFocalPerSide * w, "fx (0.1 to 100 times the width)"},
      {2, -w, 2 * w, "cx (from -width to 2 times the width)"},
      {4, kMinFocalPerSide * h, kMaxFocalPerSide * h, "fy (0.1 to 100 times the height)"},
      {5, -h, 2 * h, "cy (from -height to 2 times the height)"},
  }};
  for (const auto& e : entries) {
    const double k = d.K[e.index];
    if (k < e.lo || k > e.hi) {
      return fail(element(path, e.index), std::string(e.what) + " must be from " +
                                              formatNumber(e.lo) + " to " + formatNumber(e.hi) +
                                              " pixels, got " + formatNumber(k));
    }
  }
  return {};
}

Status checkWithin(std::span<const double> values, double limit, const std::string& path,
                   const char* what) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::abs(values[i]) > limit) {
      return fail(element(path, i), std::string(what) + " must be from -" + formatNumber(limit) +
                                        " to " + formatNumber(limit) + ", got " +
                                        formatNumber(values[i]));
    }
  }
  return {};
}

Status checkRotation(const std::array<double, 9>& r, const std::string& path) {
  if (auto problem = rotationProblem(r)) {
    return fail(path, std::move(*problem));
  }
  return {};
}

class IdRegistry {
 public:
  Status add(const std::string& id, const std::string& path) {
    if (auto problem = identifierProblem(id)) {
      return fail(member(path, "id"), std::move(*problem));
    }
    const auto [it, inserted] = owners_.emplace(id, path);
    if (!inserted) {
      return fail(member(path, "id"), jsonQuote(id) + " is already the id of " + it->second +
                                          "; ids must be unique across cameras and projectors");
    }
    return {};
  }

 private:
  std::map<std::string, std::string, std::less<>> owners_;
};

Status checkDevice(const algo::DeviceModel& d, const std::string& path, IdRegistry& ids) {
  if (auto s = ids.add(d.id, path); !s) {
    return s;
  }
  if (auto s = checkSize(d.width, member(path, "width")); !s) {
    return s;
  }
  if (auto s = checkSize(d.height, member(path, "height")); !s) {
    return s;
  }
  if (auto s = checkFinite(d.K, member(path, "K")); !s) {
    return s;
  }
  if (auto s = checkIntrinsics(d.K, member(path, "K")); !s) {
    return s;
  }
  if (auto s = checkIntrinsicsPlausible(d, member(path, "K")); !s) {
    return s;
  }
  if (auto s = checkFinite(d.dist, member(path, "dist")); !s) {
    return s;
  }
  if (auto s =
          checkWithin(d.dist, kMaxDistortion, member(path, "dist"), "a distortion coefficient");
      !s) {
    return s;
  }
  if (auto s = checkFinite(d.R, member(path, "R")); !s) {
    return s;
  }
  if (auto s = checkRotation(d.R, member(path, "R")); !s) {
    return s;
  }
  if (auto s = checkFinite(d.t, member(path, "t")); !s) {
    return s;
  }
  return checkWithin(d.t, kMaxTranslationM, member(path, "t"), "a translation (metres)");
}

Status checkPattern(const algo::Projector& projector, const std::string& path) {
  const algo::StripePattern& p = projector.pattern;
  const std::array<double, 3> values = {p.angleDeg, p.stripePx, p.offsetPx};
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return fail(member(path, kPatternKeys[i]),
                  "must be a finite number, got " + formatNumber(values[i]));
    }
  }
  if (!(p.stripePx > 0)) {
    return fail(member(path, "stripe_px"), "must be positive, got " + formatNumber(p.stripePx));
  }
  if (p.stripePx < kMinStripePx) {
    return fail(member(path, "stripe_px"),
                "must be at least 1 (a stripe narrower than a projector pixel cannot be shown), "
                "got " +
                    formatNumber(p.stripePx));
  }
  if (std::abs(p.angleDeg) > kMaxAngleDeg) {
    return fail(member(path, "angle_deg"),
                "must be from -360 to 360 degrees, got " + formatNumber(p.angleDeg));
  }
  if (const int visible = algo::visibleStripes(projector); visible < algo::stripe::kWindowStripes) {
    return fail(path, "shows " + std::to_string(visible) + " whole stripes in the " +
                          std::to_string(projector.width) + "x" + std::to_string(projector.height) +
                          " projector image; a stripe is identified by a window of " +
                          std::to_string(algo::stripe::kWindowStripes) +
                          ", so stripe_px or offset_px is wrong");
  }
  return {};
}

// One of the rig's device lists: its key, what one device is called, and how many there may be.
struct DeviceList {
  std::string_view key;
  std::string_view what;
  std::size_t most;
  std::string_view why;  // of the bound, for the message; may be empty
};
constexpr DeviceList kCameraList = {"cameras", "camera", kMaxCameras, ""};
constexpr DeviceList kProjectorList = {
    "projectors", "projector", algo::kMaxProjectors,
    " (the method separates up to 3 pattern orientations in one image)"};

Status checkCount(std::size_t n, const DeviceList& list) {
  const std::string path(list.key);
  if (n == 0) {
    return fail(path, "at least one " + std::string(list.what) + " is required, got none");
  }
  if (n > list.most) {
    return fail(path, "at most " + std::to_string(list.most) + " " + std::string(list.what) + "s" +
                          std::string(list.why) + ", got " + std::to_string(n));
  }
  return {};
}

// --- reading: JSON structure -> Rig ---

// Applies `read(value, path)` to obj[key]; a missing key is an error.
template <class Read>
auto readField(const Json& obj, const std::string& path, std::string_view key, Read read)
    -> decltype(read(obj, path)) {
  const std::string at = member(path, key);
  const auto it = obj.find(key);
  if (it == obj.end()) {
    return fail(at, "required field is missing");
  }
  return read(*it, at);
}

template <std::size_t N>
Status readArrayField(const Json& obj, const std::string& path, std::string_view key,
                      std::string_view what, std::array<double, N>& out) {
  return readField(obj, path, key, [&](const Json& v, const std::string& at) {
    return readArray(v, at, what, out);
  });
}

Status readDeviceModel(const Json& obj, const std::string& path, algo::DeviceModel& d) {
  auto id = readField(obj, path, "id", readString);
  if (!id) {
    return std::unexpected(id.error());
  }
  d.id = std::move(*id);
  auto width = readField(obj, path, "width", readSize);
  if (!width) {
    return std::unexpected(width.error());
  }
  d.width = *width;
  auto height = readField(obj, path, "height", readSize);
  if (!height) {
    return std::unexpected(height.error());
  }
  d.height = *height;
  if (auto s = readArrayField(obj, path, "K", "row-major 3x3 camera matrix", d.K); !s) {
    return s;
  }
  if (auto s = readArrayField(obj, path, "dist", "k1 k2 p1 p2 k3", d.dist); !s) {
    return s;
  }
  if (auto s = readArrayField(obj, path, "R", "row-major 3x3 rotation", d.R); !s) {
    return s;
  }
  return readArrayField(obj, path, "t", "translation in metres", d.t);
}

Status readPattern(const Json& obj, const std::string& path, algo::StripePattern& p) {
  if (!obj.is_object()) {
    return fail(
        path, R"(must be an object {"angle_deg", "stripe_px", "offset_px"}, got )" + describe(obj));
  }
  if (auto s = checkKeys(obj, path, kPatternKeys); !s) {
    return s;
  }
  const std::array<double*, 3> outs = {&p.angleDeg, &p.stripePx, &p.offsetPx};
  for (std::size_t i = 0; i < outs.size(); ++i) {
    auto v = readField(obj, path, kPatternKeys[i], readNumber);
    if (!v) {
      return std::unexpected(v.error());
    }
    *outs[i] = *v;
  }
  return {};
}

template <class Device>
Status readDevice(const Json& obj, const std::string& path, IdRegistry& ids, Device& d) {
  constexpr bool kIsProjector = std::is_same_v<Device, algo::Projector>;
  if (auto s = kIsProjector ? checkKeys(obj, path, kProjectorKeys)
                            : checkKeys(obj, path, kCameraKeys,
                                        obj.contains("pattern") ? "cameras have no pattern" : "");
      !s) {
    return s;
  }
  if (auto s = readDeviceModel(obj, path, d); !s) {
    return s;
  }
  if (auto s = checkDevice(d, path, ids); !s) {
    return s;
  }
  if constexpr (kIsProjector) {
    const std::string at = member(path, "pattern");
    if (auto s = readField(
            obj, path, "pattern",
            [&](const Json& v, const std::string&) { return readPattern(v, at, d.pattern); });
        !s) {
      return s;
    }
    return checkPattern(d, at);
  }
  return {};
}

template <class Device>
std::expected<std::vector<Device>, RigError> readDevices(const Json& doc, const DeviceList& list,
                                                         IdRegistry& ids) {
  const std::string path(list.key);
  const std::string what(list.what);
  const auto it = doc.find(list.key);
  if (it == doc.end()) {
    return fail(path, "required field is missing");
  }
  if (!it->is_array()) {
    return fail(path, "must be an array of " + what + "s, got " + describe(*it));
  }
  if (auto s = checkCount(it->size(), list); !s) {
    return std::unexpected(s.error());
  }
  std::vector<Device> devices(it->size());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const Json& obj = (*it)[i];
    const std::string at = element(path, i);
    if (!obj.is_object()) {
      return fail(at, "must be an object (one " + what + "), got " + describe(obj));
    }
    if (auto s = readDevice(obj, at, ids, devices[i]); !s) {
      return std::unexpected(s.error());
    }
  }
  return devices;
}

std::expected<algo::Rig, RigError> parseRigImpl(std::string_view text) {
  auto doc = parseDocument(text, kRigDocument);
  if (!doc) {
    return fail(std::move(doc.error()));
  }
  IdRegistry ids;
  algo::Rig rig;
  auto cameras = readDevices<algo::Camera>(*doc, kCameraList, ids);
  if (!cameras) {
    return std::unexpected(cameras.error());
  }
  rig.cameras = std::move(*cameras);
  auto projectors = readDevices<algo::Projector>(*doc, kProjectorList, ids);
  if (!projectors) {
    return std::unexpected(projectors.error());
  }
  rig.projectors = std::move(*projectors);
  return rig;
}

// --- writing ---

std::string jsonNumber(double v) {
  return std::isfinite(v) ? formatNumber(v) : "null";
}

std::string jsonNumbers(std::span<const double> values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += (i == 0 ? "" : ", ") + jsonNumber(values[i]);
  }
  return out + "]";
}

void writeDevice(std::string& out, const algo::DeviceModel& d, const algo::StripePattern* pattern) {
  out += "    {\n";
  out += "      \"id\": " + jsonQuote(d.id) + ",\n";
  out += "      \"width\": " + std::to_string(d.width) + ",\n";
  out += "      \"height\": " + std::to_string(d.height) + ",\n";
  out += "      \"K\": " + jsonNumbers(d.K) + ",\n";
  out += "      \"dist\": " + jsonNumbers(d.dist) + ",\n";
  out += "      \"R\": " + jsonNumbers(d.R) + ",\n";
  out += "      \"t\": " + jsonNumbers(d.t);
  if (pattern != nullptr) {
    out += ",\n      \"pattern\": {\"angle_deg\": " + jsonNumber(pattern->angleDeg) +
           ", \"stripe_px\": " + jsonNumber(pattern->stripePx) +
           ", \"offset_px\": " + jsonNumber(pattern->offsetPx) + "}";
  }
  out += "\n    }";
}

template <class Device>
void writeDevices(std::string& out, std::string_view key, const std::vector<Device>& devices) {
  out += "  \"" + std::string(key) + "\": [";
  for (std::size_t i = 0; i < devices.size(); ++i) {
    out += i == 0 ? "\n" : ",\n";
    if constexpr (std::is_same_v<Device, algo::Projector>) {
      writeDevice(out, devices[i], &devices[i].pattern);
    } else {
      writeDevice(out, devices[i], nullptr);
    }
  }
  out += devices.empty() ? "]" : "\n  ]";
}

}  // namespace

std::string RigError::message() const {
  return errorMessage(file, field, problem);
}

std::expected<algo::Rig, RigError> parseRig(std::string_view jsonText) {
  try {
    return parseRigImpl(jsonText);
  } catch (const std::exception& e) {
    // Out of memory or a library surprise: still an error value, never an exception.
    return fail("", std::string("cannot read the rig: ") + e.what());
  }
}

std::expected<algo::Rig, RigError> loadRig(const std::filesystem::path& path) {
  return loadDocument(path, kRigDocument, [](const std::string& text) { return parseRig(text); });
}

std::expected<void, RigError> validateRig(const algo::Rig& rig) {
  try {
    IdRegistry ids;
    if (auto s = checkCount(rig.cameras.size(), kCameraList); !s) {
      return s;
    }
    for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
      if (auto s = checkDevice(rig.cameras[i], element("cameras", i), ids); !s) {
        return s;
      }
    }
    if (auto s = checkCount(rig.projectors.size(), kProjectorList); !s) {
      return s;
    }
    for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
      const std::string at = element("projectors", i);
      if (auto s = checkDevice(rig.projectors[i], at, ids); !s) {
        return s;
      }
      if (auto s = checkPattern(rig.projectors[i], member(at, "pattern")); !s) {
        return s;
      }
    }
    return {};
  } catch (const std::exception& e) {
    return fail("", std::string("cannot check the rig: ") + e.what());
  }
}

std::string toJson(const algo::Rig& rig) {
  std::string out = "{\n  \"format\": " + jsonQuote(kRigFormat) + ",\n";
  writeDevices(out, "cameras", rig.cameras);
  out += ",\n";
  writeDevices(out, "projectors", rig.projectors);
  out += "\n}\n";
  return out;
}

}  // namespace smx::config
