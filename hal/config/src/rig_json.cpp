#include "smx/config/rig_json.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <exception>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "smx/algo/demux.hpp"
#include "smx/algo/pattern_image.hpp"
#include "smx/config/field_reader.hpp"
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

constexpr std::array<std::string_view, 4> kTopKeys = {"format", "cameras", "projectors",
                                                      "turntable"};
constexpr std::array<std::string_view, 2> kTurntableKeys = {"axis", "point"};
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

std::string sizeProblem(double v) {
  if (v != std::floor(v) || v < 1) {
    return "must be a positive integer (pixels), got " + formatNumber(v);
  }
  return "must be from " + std::to_string(kMinImageSidePx) + " to " +
         std::to_string(kMaxImageSidePx) + " pixels, got " + formatNumber(v);
}

// The generic reads, plus the rig's required fields: rig.json has no defaults, every key of a
// device is required.
class Reader : public FieldReader {
 public:
  [[nodiscard]] std::unexpected<RigError> error() const {
    const auto e = firstError().value_or(FieldError{});
    return std::unexpected(RigError{{}, e.field, e.problem});
  }

  // obj[key], or nullptr and an error when it is missing.
  const Json* required(const Json& obj, const std::string& path, std::string_view key) {
    const Json* v = find(obj, key);
    if (ok() && v == nullptr) {
      fail(member(path, key), "required field is missing");
    }
    return v;
  }

  void string(const Json& obj, const std::string& path, std::string_view key, std::string& out) {
    if (const Json* v = required(obj, path, key); v != nullptr) {
      if (!v->is_string()) {
        fail(member(path, key), "must be a string, got " + describe(*v));
        return;
      }
      out = v->get<std::string>();
    }
  }

  void requiredNumber(const Json& obj, const std::string& path, std::string_view key, double& out) {
    if (const Json* v = required(obj, path, key); v != nullptr) {
      out = number(*v, member(path, key), Range::kAny).value_or(out);
    }
  }

  // An image side in pixels (640.0 is accepted: it is an integer, only written differently).
  void size(const Json& obj, const std::string& path, std::string_view key, int& out) {
    const Json* v = required(obj, path, key);
    if (v == nullptr) {
      return;
    }
    const std::string at = member(path, key);
    const auto d = number(*v, at, Range::kAny);
    if (!d) {
      return;
    }
    if (*d != std::floor(*d) || *d < kMinImageSidePx || *d > kMaxImageSidePx) {
      fail(at, sizeProblem(*d));
      return;
    }
    out = static_cast<int>(*d);
  }

  template <std::size_t N>
  void array(const Json& obj, const std::string& path, std::string_view key, std::string_view what,
             std::array<double, N>& out) {
    if (const Json* v = required(obj, path, key); v != nullptr) {
      out = numbers<N>(*v, member(path, key), what, Range::kAny).value_or(out);
    }
  }
};

// --- value rules, shared by parseRig() and validateRig() ---

void checkFinite(Reader& r, std::span<const double> values, const std::string& path) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      r.fail(element(path, i), "must be a finite number, got " + formatNumber(values[i]));
    }
  }
}

void checkSize(Reader& r, int v, const std::string& path) {
  if (v < kMinImageSidePx || v > kMaxImageSidePx) {
    r.fail(path, sizeProblem(v));
  }
}

void checkIntrinsics(Reader& r, const std::array<double, 9>& intrinsics, const std::string& path) {
  for (std::size_t i = 0; i < intrinsics.size(); ++i) {
    const double k = intrinsics[i];
    const std::string got = ", got " + formatNumber(k);
    const std::string at = element(path, i);
    if (i == 0 && !(k > 0)) {
      r.fail(at, "fx must be positive" + got);
    } else if (i == 4 && !(k > 0)) {
      r.fail(at, "fy must be positive" + got);
    } else if (i == 1 && k != 0) {
      r.fail(at, "skew must be 0 (" + std::string(kKStructure) + ")" + got);
    } else if ((i == 3 || i == 6 || i == 7) && k != 0) {
      r.fail(at, "must be 0 (" + std::string(kKStructure) + ")" + got);
    } else if (i == 8 && k != 1) {
      r.fail(at, "must be 1 (" + std::string(kKStructure) + ")" + got);
    }
  }
}

// After checkIntrinsics: K has its structure, fx and fy are positive.
void checkIntrinsicsPlausible(Reader& r, const algo::DeviceModel& d, const std::string& path) {
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
      r.fail(element(path, e.index), std::string(e.what) + " must be from " + formatNumber(e.lo) +
                                         " to " + formatNumber(e.hi) + " pixels, got " +
                                         formatNumber(k));
    }
  }
}

void checkWithin(Reader& r, std::span<const double> values, double limit, const std::string& path,
                 const char* what) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::abs(values[i]) > limit) {
      r.fail(element(path, i), std::string(what) + " must be from -" + formatNumber(limit) +
                                   " to " + formatNumber(limit) + ", got " +
                                   formatNumber(values[i]));
    }
  }
}

class IdRegistry {
 public:
  void add(Reader& r, const std::string& id, const std::string& path) {
    if (auto problem = identifierProblem(id)) {
      r.fail(member(path, "id"), std::move(*problem));
      return;
    }
    const auto [it, inserted] = owners_.emplace(id, path);
    if (!inserted) {
      r.fail(member(path, "id"), jsonQuote(id) + " is already the id of " + it->second +
                                     "; ids must be unique across cameras and projectors");
    }
  }

 private:
  std::map<std::string, std::string, std::less<>> owners_;
};

// The rules in file order; only the first failure is kept, so later rules may see values an
// earlier one refused (none of them divides or allocates by a value).
void checkDevice(Reader& r, const algo::DeviceModel& d, const std::string& path, IdRegistry& ids) {
  ids.add(r, d.id, path);
  checkSize(r, d.width, member(path, "width"));
  checkSize(r, d.height, member(path, "height"));
  checkFinite(r, d.K, member(path, "K"));
  checkIntrinsics(r, d.K, member(path, "K"));
  checkIntrinsicsPlausible(r, d, member(path, "K"));
  checkFinite(r, d.dist, member(path, "dist"));
  checkWithin(r, d.dist, kMaxDistortion, member(path, "dist"), "a distortion coefficient");
  checkFinite(r, d.R, member(path, "R"));
  if (auto problem = rotationProblem(d.R)) {
    r.fail(member(path, "R"), std::move(*problem));
  }
  checkFinite(r, d.t, member(path, "t"));
  checkWithin(r, d.t, kMaxTranslationM, member(path, "t"), "a translation (metres)");
}

void checkPattern(Reader& r, const algo::Projector& projector, const std::string& path) {
  const algo::StripePattern& p = projector.pattern;
  const std::array<double, 3> values = {p.angleDeg, p.stripePx, p.offsetPx};
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      r.fail(member(path, kPatternKeys[i]),
             "must be a finite number, got " + formatNumber(values[i]));
    }
  }
  if (!(p.stripePx > 0)) {
    r.fail(member(path, "stripe_px"), "must be positive, got " + formatNumber(p.stripePx));
  } else if (p.stripePx < kMinStripePx) {
    r.fail(member(path, "stripe_px"),
           "must be at least 1 (a stripe narrower than a projector pixel cannot be shown), got " +
               formatNumber(p.stripePx));
  }
  if (std::abs(p.angleDeg) > kMaxAngleDeg) {
    r.fail(member(path, "angle_deg"),
           "must be from -360 to 360 degrees, got " + formatNumber(p.angleDeg));
  }
  if (!r.ok()) {
    return;  // visibleStripes() needs a finite, positive stripe width
  }
  if (const int visible = algo::visibleStripes(projector); visible < algo::stripe::kWindowStripes) {
    r.fail(path, "shows " + std::to_string(visible) + " whole stripes in the " +
                     std::to_string(projector.width) + "x" + std::to_string(projector.height) +
                     " projector image; a stripe is identified by a window of " +
                     std::to_string(algo::stripe::kWindowStripes) +
                     ", so stripe_px or offset_px is wrong");
  }
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

void checkCount(Reader& r, std::size_t n, const DeviceList& list) {
  const std::string path(list.key);
  if (n == 0) {
    r.fail(path, "at least one " + std::string(list.what) + " is required, got none");
  } else if (n > list.most) {
    r.fail(path, "at most " + std::to_string(list.most) + " " + std::string(list.what) + "s" +
                     std::string(list.why) + ", got " + std::to_string(n));
  }
}

// The value rules of one device, in file order: its own, then a projector's pattern.
template <class Device>
void checkAnyDevice(Reader& r, const Device& d, const std::string& path, IdRegistry& ids) {
  checkDevice(r, d, path, ids);
  if constexpr (std::is_same_v<Device, algo::Projector>) {
    if (r.ok()) {
      checkPattern(r, d, member(path, "pattern"));
    }
  }
}

// --- reading: JSON structure -> Rig ---

void readDeviceModel(Reader& r, const Json& obj, const std::string& path, algo::DeviceModel& d) {
  r.string(obj, path, "id", d.id);
  r.size(obj, path, "width", d.width);
  r.size(obj, path, "height", d.height);
  r.array(obj, path, "K", "row-major 3x3 camera matrix", d.K);
  r.array(obj, path, "dist", "k1 k2 p1 p2 k3", d.dist);
  r.array(obj, path, "R", "row-major 3x3 rotation", d.R);
  r.array(obj, path, "t", "translation in metres", d.t);
}

void readPattern(Reader& r, const Json& obj, const std::string& path, algo::StripePattern& p) {
  if (!obj.is_object()) {
    r.fail(path,
           R"(must be an object {"angle_deg", "stripe_px", "offset_px"}, got )" + describe(obj));
    return;
  }
  if (!r.object(obj, path, "", kPatternKeys)) {
    return;
  }
  r.requiredNumber(obj, path, "angle_deg", p.angleDeg);
  r.requiredNumber(obj, path, "stripe_px", p.stripePx);
  r.requiredNumber(obj, path, "offset_px", p.offsetPx);
}

template <class Device>
void readDevice(Reader& r, const Json& obj, const std::string& path, const DeviceList& list,
                IdRegistry& ids, Device& d) {
  constexpr bool kIsProjector = std::is_same_v<Device, algo::Projector>;
  const std::string what = "one " + std::string(list.what);
  if (!(kIsProjector ? r.object(obj, path, what, kProjectorKeys)
                     : r.object(obj, path, what, kCameraKeys,
                                obj.contains("pattern") ? "cameras have no pattern" : ""))) {
    return;
  }
  readDeviceModel(r, obj, path, d);
  if (r.ok()) {
    checkDevice(r, d, path, ids);
  }
  if constexpr (kIsProjector) {
    if (const Json* pattern = r.required(obj, path, "pattern"); pattern != nullptr) {
      readPattern(r, *pattern, member(path, "pattern"), d.pattern);
    }
    if (r.ok()) {
      checkPattern(r, d, member(path, "pattern"));
    }
  }
}

template <class Device>
std::vector<Device> readDevices(Reader& r, const Json& doc, const DeviceList& list,
                                IdRegistry& ids) {
  const std::string path(list.key);
  const Json* devices = r.required(doc, "", list.key);
  if (devices == nullptr) {
    return {};
  }
  if (!devices->is_array()) {
    r.fail(path, "must be an array of " + std::string(list.what) + "s, got " + describe(*devices));
    return {};
  }
  checkCount(r, devices->size(), list);
  std::vector<Device> out(r.ok() ? devices->size() : 0);
  for (std::size_t i = 0; i < out.size() && r.ok(); ++i) {
    readDevice(r, (*devices)[i], element(path, i), list, ids, out[i]);
  }
  return out;
}

void checkTurntable(Reader& r, const algo::TurntableAxis& t) {
  checkFinite(r, t.axis, "turntable.axis");
  checkFinite(r, t.point, "turntable.point");
  checkWithin(r, t.point, kMaxTranslationM, "turntable.point", "a coordinate (metres)");
  const double norm = std::hypot(t.axis[0], t.axis[1], t.axis[2]);
  if (r.ok() && (norm <= 0 || !std::isfinite(norm))) {
    r.fail("turntable.axis", "must be a direction (not the zero vector), e.g. [0, -1, 0]");
  }
}

// The optional turntable axis; its direction is normalised.
void readTurntable(Reader& r, const Json& doc, algo::Rig& rig) {
  const Json* v = r.find(doc, "turntable");
  if (v == nullptr ||
      !r.object(*v, "turntable", "the turntable's axis in the world frame", kTurntableKeys)) {
    return;
  }
  algo::TurntableAxis t;
  r.array(*v, "turntable", "axis", "x, y, z direction of the axis", t.axis);
  r.array(*v, "turntable", "point", "x, y, z of a point on the axis, metres", t.point);
  checkTurntable(r, t);
  if (r.ok()) {
    const double norm = std::hypot(t.axis[0], t.axis[1], t.axis[2]);
    for (double& c : t.axis) {
      c /= norm;
    }
    rig.turntable = t;
  }
}

std::expected<algo::Rig, RigError> parseRigImpl(std::string_view text) {
  auto doc = parseDocument(text, kRigDocument);
  if (!doc) {
    return std::unexpected(
        RigError{{}, std::move(doc.error().field), std::move(doc.error().problem)});
  }
  Reader r;
  IdRegistry ids;
  algo::Rig rig;
  rig.cameras = readDevices<algo::Camera>(r, *doc, kCameraList, ids);
  rig.projectors = readDevices<algo::Projector>(r, *doc, kProjectorList, ids);
  readTurntable(r, *doc, rig);
  if (!r.ok()) {
    return r.error();
  }
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
    return std::unexpected(RigError{{}, {}, std::string("cannot read the rig: ") + e.what()});
  }
}

std::expected<algo::Rig, RigError> loadRig(const std::filesystem::path& path) {
  return loadDocument(path, kRigDocument, [](const std::string& text) { return parseRig(text); });
}

std::expected<void, RigError> validateRig(const algo::Rig& rig) {
  try {
    Reader r;
    IdRegistry ids;
    checkCount(r, rig.cameras.size(), kCameraList);
    for (std::size_t i = 0; i < rig.cameras.size() && r.ok(); ++i) {
      checkAnyDevice(r, rig.cameras[i], element("cameras", i), ids);
    }
    if (r.ok()) {
      checkCount(r, rig.projectors.size(), kProjectorList);
    }
    for (std::size_t i = 0; i < rig.projectors.size() && r.ok(); ++i) {
      checkAnyDevice(r, rig.projectors[i], element("projectors", i), ids);
    }
    if (r.ok() && rig.turntable) {
      checkTurntable(r, *rig.turntable);
    }
    if (!r.ok()) {
      return r.error();
    }
    return {};
  } catch (const std::exception& e) {
    return std::unexpected(RigError{{}, {}, std::string("cannot check the rig: ") + e.what()});
  }
}

std::string toJson(const algo::Rig& rig) {
  std::string out = "{\n  \"format\": " + jsonQuote(kRigFormat) + ",\n";
  writeDevices(out, "cameras", rig.cameras);
  out += ",\n";
  writeDevices(out, "projectors", rig.projectors);
  if (rig.turntable) {
    out += ",\n  \"turntable\": {\"axis\": " + jsonNumbers(rig.turntable->axis) +
           ", \"point\": " + jsonNumbers(rig.turntable->point) + "}";
  }
  out += "\n}\n";
  return out;
}

}  // namespace smx::config
