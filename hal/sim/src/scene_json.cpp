#include "smx/sim/scene_json.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include "smx/sim/mesh_io.hpp"
#include "smx/sim/png_io.hpp"

namespace smx::sim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Keys = std::span<const std::string_view>;

constexpr double kRotationTolerance = 1e-6;  // as rig.json: R printed with 7 digits passes
constexpr int kMaxSupersampling = 8;         // 64 rays per pixel: beyond that, render larger
// A scene.json is a few kB and 7 levels deep (objects[i].albedo.checker.colours[j]). The bounds
// keep a mistaken input (a mesh or an image given as the scene) from costing much.
constexpr std::size_t kMaxSceneBytes = std::size_t{1} << 20U;
constexpr std::size_t kMaxNesting = 16;
constexpr std::size_t kNestingNeeded = 7;

constexpr std::array<std::string_view, 5> kTopKeys = {"format", "supersampling", "lighting",
                                                      "camera_response", "objects"};
constexpr std::array<std::string_view, 5> kLightingKeys = {"ambient", "projector_power",
                                                           "inverse_square", "reference_distance_m",
                                                           "projector_defocus_sigma_px"};
constexpr std::array<std::string_view, 4> kCameraKeys = {"crosstalk", "gain", "noise_sigma",
                                                         "defocus_sigma_px"};
constexpr std::array<std::string_view, 5> kObjectKeys = {"name", "shape", "pose", "motion",
                                                         "albedo"};
constexpr std::array<std::string_view, 4> kPoseKeys = {"t", "rotation_deg", "R", "scale"};
constexpr std::array<std::string_view, 4> kMotionKeys = {"velocity_m_per_frame", "axis",
                                                         "angular_deg_per_frame", "pivot"};
constexpr std::array<std::string_view, 3> kAlbedoKeys = {"rgb", "checker", "texture"};
constexpr std::array<std::string_view, 2> kCheckerKeys = {"square_m", "colours"};
constexpr std::array<std::string_view, 3> kTextureKeys = {"path", "width_m", "height_m"};

constexpr std::array<std::string_view, 3> kPlaneKeys = {"type", "width_m", "height_m"};
constexpr std::array<std::string_view, 2> kBoxKeys = {"type", "size_m"};
constexpr std::array<std::string_view, 2> kSphereKeys = {"type", "radius_m"};
constexpr std::array<std::string_view, 4> kCylinderKeys = {"type", "radius_m", "height_m",
                                                           "capped"};
constexpr std::array<std::string_view, 2> kMeshKeys = {"type", "path"};

struct ShapeType {
  std::string_view name;
  Keys keys;
};
constexpr std::array<ShapeType, 5> kShapeTypes = {{{"plane", kPlaneKeys},
                                                   {"box", kBoxKeys},
                                                   {"sphere", kSphereKeys},
                                                   {"cylinder", kCylinderKeys},
                                                   {"mesh", kMeshKeys}}};
// Words people reach for that are not the type names.
constexpr std::array<std::pair<std::string_view, std::string_view>, 10> kShapeSynonyms = {{
    {"cube", "box"},
    {"cuboid", "box"},
    {"rectangle", "plane"},
    {"quad", "plane"},
    {"wall", "plane"},
    {"ball", "sphere"},
    {"tube", "cylinder"},
    {"ply", "mesh"},
    {"obj", "mesh"},
    {"model", "mesh"},
}};

// --- Generic JSON diagnostics. The approach and wording of firmware/protocol/src/rig_json.cpp
// (paths, "got ...", key suggestions, duplicate keys, overflow, nesting); candidates for a shared
// helper. ---

std::string member(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string element(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Shortest text that reads back to the same double; plain notation where people expect it.
std::string formatNumber(double v) {
  if (!std::isfinite(v)) {
    return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  }
  const double magnitude = std::abs(v);
  const bool plain = magnitude == 0 || (magnitude >= 1e-4 && magnitude < 1e16);
  std::array<char, 64> buf{};
  const auto r =
      plain ? std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed)
            : std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return {buf.data(), r.ptr};
}

// Measured deviations: three significant digits are plenty.
std::string formatDeviation(double v) {
  std::array<char, 32> buf{};
  const auto r =
      std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::general, 3);
  return {buf.data(), r.ptr};
}

std::string jsonQuote(std::string_view s) {
  return Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
}

// "a string ("800")", "an array of 8 elements", ... for "got ..." in wrong-type messages.
std::string describe(const Json& v) {
  constexpr std::size_t kMaxShown = 40;
  switch (v.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return std::string("a boolean (") + (v.get<bool>() ? "true" : "false") + ")";
    case Json::value_t::string: {
      const auto& s = v.get_ref<const std::string&>();
      return "a string (" +
             (s.size() <= kMaxShown ? jsonQuote(s) : jsonQuote(s.substr(0, kMaxShown)) + "...") +
             ")";
    }
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " element" : " elements");
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return "a number (" + formatNumber(v.get<double>()) + ")";
    case Json::value_t::binary:
    case Json::value_t::discarded:
      break;
  }
  return "an unexpected value";
}

std::string joined(Keys words) {
  std::string out;
  for (const auto w : words) {
    out += (out.empty() ? "" : ", ") + std::string(w);
  }
  return out;
}

std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) {
    row[j] = j;
  }
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0U : 1U)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

bool equalIgnoringCase(std::string_view a, std::string_view b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) ==
           std::tolower(static_cast<unsigned char>(y));
  });
}

// The allowed word the user probably meant ("color" -> "colours" is too far, "colors" ->
// "colours" is not), or empty when nothing is close enough to be a useful hint.
std::string_view closestWord(std::string_view word, Keys allowed) {
  std::string_view best;
  std::size_t bestDistance = 3;  // within two edits ...
  for (const auto candidate : allowed) {
    if (equalIgnoringCase(word, candidate)) {
      return candidate;
    }
    const bool prefix = std::min(word.size(), candidate.size()) >= 3 &&
                        (word.starts_with(candidate) || candidate.starts_with(word));
    const std::size_t d = prefix ? 1 : editDistance(word, candidate);
    if (d < bestDistance && 2 * d < word.size()) {  // ... and fewer than half the word
      best = candidate;
      bestDistance = d;
    }
  }
  return best;
}

// The first key of `obj` that is not allowed.
std::optional<std::string> unknownKey(const Json& obj, Keys allowed) {
  for (const auto& [key, value] : obj.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      return key;
    }
  }
  return std::nullopt;
}

std::string unknownKeyProblem(std::string_view key, Keys allowed, const std::string& hint = {}) {
  std::string problem = "unknown key " + jsonQuote(key);
  if (!hint.empty()) {
    problem += " (" + hint + ")";
  } else if (const auto guess = closestWord(key, allowed); !guess.empty()) {
    problem += " (did you mean " + jsonQuote(guess) + "?)";
  }
  return problem + "; allowed keys: " + joined(allowed);
}

// Follows the JSON path while nlohmann parses, for what nlohmann does not report by path: a
// duplicated key (nlohmann keeps the last copy silently) and a number too large for a double.
class ParseTracker {
 public:
  bool onEvent(Json::parse_event_t event, const Json& parsed) {
    using E = Json::parse_event_t;
    switch (event) {
      case E::object_start:
      case E::array_start:
        valueStarts();
        stack_.push_back({event == E::array_start, 0, {}, {}});
        break;
      case E::object_end:
      case E::array_end:
        stack_.pop_back();
        break;
      case E::key:
        if (!stack_.empty()) {
          Frame& f = stack_.back();
          f.key = parsed.get<std::string>();
          if (!f.keys.insert(f.key).second && !duplicate_) {
            duplicate_ = SceneError{{},
                                    pathTo(stack_.size() - 1),
                                    "key " + jsonQuote(f.key) + " appears more than once"};
          }
        }
        break;
      case E::value:
        valueStarts();
        break;
    }
    return true;
  }

  [[nodiscard]] const std::optional<SceneError>& duplicate() const { return duplicate_; }

  // The path of the value being read now (the one that made nlohmann stop).
  [[nodiscard]] std::string currentPath() const {
    if (stack_.empty()) {
      return {};
    }
    const Frame& f = stack_.back();
    const std::string parent = pathTo(stack_.size() - 1);
    return f.isArray ? element(parent, f.count) : member(parent, f.key);
  }

 private:
  struct Frame {
    bool isArray;
    std::size_t count;  // elements started so far (arrays)
    std::string key;    // key being read (objects)
    std::set<std::string, std::less<>> keys;
  };

  void valueStarts() {
    if (!stack_.empty() && stack_.back().isArray) {
      ++stack_.back().count;
    }
  }

  // Path of the container held by stack_[depth].
  [[nodiscard]] std::string pathTo(std::size_t depth) const {
    std::string path;
    for (std::size_t i = 0; i < depth; ++i) {
      const Frame& f = stack_[i];
      path = f.isArray ? element(path, f.count - 1) : member(path, f.key);
    }
    return path;
  }

  std::vector<Frame> stack_;
  std::optional<SceneError> duplicate_;
};

std::string parseErrorProblem(std::string_view what) {
  // "[json.exception.parse_error.101] parse error at line 2, column 5: syntax error ..."
  if (const auto close = what.find("] "); close != std::string_view::npos) {
    what.remove_prefix(close + 2);
  }
  constexpr std::string_view kLead = "parse error at ";
  if (what.starts_with(kLead)) {
    what.remove_prefix(kLead.size());
  }
  // The parser quotes the bytes it last read, which may be anything; keep the message printable.
  std::string problem = "not valid JSON: " + std::string(what);
  std::replace_if(
      problem.begin(), problem.end(),
      [](char c) {
        const auto byte = static_cast<unsigned char>(c);
        return byte < 0x20 || byte >= 0x7f;
      },
      '?');
  return problem;
}

// "[json.exception.out_of_range.406] number overflow parsing '1e999'" -> "1e999"
std::string overflowedLiteral(std::string_view what) {
  const auto open = what.find('\'');
  const auto close = what.rfind('\'');
  if (open == std::string_view::npos || close <= open) {
    return "the number";
  }
  return std::string(what.substr(open + 1, close - open - 1));
}

// Deepest [ / { nesting outside strings; checked before nlohmann builds anything.
std::size_t nestingDepth(std::string_view text) {
  std::size_t depth = 0;
  std::size_t deepest = 0;
  bool inString = false;
  bool escaped = false;
  for (const char c : text) {
    if (inString) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        inString = false;
      }
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// --- Reading scene values ---

enum class Range : std::uint8_t { kAny, kPositive, kNonNegative, kFraction };

// Reads values into a scene whose members already hold the defaults, and keeps the first
// problem: once one is found the remaining reads do nothing, so the reading code stays a plain
// sequence and the report is the first problem in reading order.
class Reader {
 public:
  [[nodiscard]] bool ok() const { return !error_.has_value(); }
  [[nodiscard]] std::unexpected<SceneError> error() const {
    return std::unexpected(error_.value_or(SceneError{}));
  }

  void fail(std::string field, std::string problem) {
    if (!error_) {
      error_ = SceneError{{}, std::move(field), std::move(problem)};
    }
  }

  // `v` must be an object (`what`, for the message) holding only `allowed` keys.
  bool object(const Json& v, const std::string& path, std::string_view what, Keys allowed) {
    if (!ok()) {
      return false;
    }
    if (!v.is_object()) {
      fail(path, "must be an object (" + std::string(what) + "), got " + describe(v));
      return false;
    }
    if (const auto key = unknownKey(v, allowed)) {
      fail(path, unknownKeyProblem(*key, allowed));
      return false;
    }
    return true;
  }

  // The value of an optional key, or nullptr when it is absent (or reading has failed).
  [[nodiscard]] const Json* find(const Json& obj, std::string_view key) const {
    if (!ok()) {
      return nullptr;
    }
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  std::optional<double> number(const Json& v, const std::string& path, Range range) {
    if (!ok()) {
      return std::nullopt;
    }
    if (!v.is_number()) {
      fail(path, "must be a number, got " + describe(v));
      return std::nullopt;
    }
    const double d = v.get<double>();
    const std::string got = ", got " + formatNumber(d);
    if (!std::isfinite(d)) {
      fail(path, "must be a finite number" + got);
    } else if (range == Range::kPositive && !(d > 0)) {
      fail(path, "must be positive" + got);
    } else if (range == Range::kNonNegative && d < 0) {
      fail(path, "must not be negative" + got);
    } else if (range == Range::kFraction && (d < 0 || d > 1)) {
      fail(path, "must be between 0 and 1" + got);
    } else {
      return d;
    }
    return std::nullopt;
  }

  void number(const Json& obj, const std::string& path, std::string_view key, Range range,
              double& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      out = number(*v, member(path, key), range).value_or(out);
    }
  }

  // An integer lo ... hi (2.0 is accepted as 2: it is an integer, only written differently).
  void integer(const Json& obj, const std::string& path, std::string_view key, int lo, int hi,
               std::string_view what, int& out) {
    const Json* v = find(obj, key);
    if (v == nullptr) {
      return;
    }
    const std::string at = member(path, key);
    const auto d = number(*v, at, Range::kAny);
    if (!d) {
      return;
    }
    if (*d != std::floor(*d) || *d < lo || *d > hi) {
      fail(at, "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi) +
                   " (" + std::string(what) + "), got " + formatNumber(*d));
      return;
    }
    out = static_cast<int>(*d);
  }

  void boolean(const Json& obj, const std::string& path, std::string_view key, bool& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      if (!v->is_boolean()) {
        fail(member(path, key), "must be true or false, got " + describe(*v));
        return;
      }
      out = v->get<bool>();
    }
  }

  // A required, non-empty string.
  std::optional<std::string> text(const Json& obj, const std::string& path, std::string_view key,
                                  std::string_view missingHint) {
    if (!ok()) {
      return std::nullopt;
    }
    const std::string at = member(path, key);
    const Json* v = find(obj, key);
    if (v == nullptr) {
      fail(at, "required field is missing; " + std::string(missingHint));
    } else if (!v->is_string()) {
      fail(at, "must be a string, got " + describe(*v));
    } else if (v->get_ref<const std::string&>().empty()) {
      fail(at, "must not be empty");
    } else {
      return v->get<std::string>();
    }
    return std::nullopt;
  }

  // An array of N numbers (`what` says what they are, for the message).
  template <std::size_t N>
  std::optional<std::array<double, N>> numbers(const Json& v, const std::string& path,
                                               std::string_view what, Range range) {
    if (!ok()) {
      return std::nullopt;
    }
    if (!v.is_array() || v.size() != N) {
      fail(path, "must be an array of " + std::to_string(N) + " numbers (" + std::string(what) +
                     "), got " + describe(v));
      return std::nullopt;
    }
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      const auto d = number(v[i], element(path, i), range);
      if (!d) {
        return std::nullopt;
      }
      out[i] = *d;
    }
    return out;
  }

  void vec3(const Json& obj, const std::string& path, std::string_view key, std::string_view what,
            Range range, Vec3& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      if (const auto a = numbers<3>(*v, member(path, key), what, range)) {
        out = Vec3((*a)[0], (*a)[1], (*a)[2]);
      }
    }
  }

  void mat3(const Json& obj, const std::string& path, std::string_view key, std::string_view what,
            Mat3& out) {
    if (const Json* v = find(obj, key); v != nullptr) {
      if (const auto a = numbers<9>(*v, member(path, key), what, Range::kAny)) {
        out = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a->data());
      }
    }
  }

 private:
  std::optional<SceneError> error_;
};

// sin and cos of an angle in degrees; exact at multiples of 90° so that quarter turns give
// rotation matrices of exact zeros and ones.
std::pair<double, double> sinCosDeg(double deg) {
  const double reduced = std::remainder(deg, 360.0);  // exact, in [-180, 180]
  const double quarters = reduced / 90.0;
  if (quarters == std::round(quarters)) {
    switch (static_cast<int>(quarters)) {
      case 0:
        return {0.0, 1.0};
      case 1:
        return {1.0, 0.0};
      case -1:
        return {-1.0, 0.0};
      default:
        return {0.0, -1.0};  // ±180°
    }
  }
  const double rad = reduced * std::numbers::pi / 180.0;
  return {std::sin(rad), std::cos(rad)};
}

// R = Rz(rz) · Ry(ry) · Rx(rx): rotate about x first, then y, then z (fixed axes), right-handed.
Mat3 rotationFromDegrees(const Vec3& deg) {
  const auto [sx, cx] = sinCosDeg(deg.x());
  const auto [sy, cy] = sinCosDeg(deg.y());
  const auto [sz, cz] = sinCosDeg(deg.z());
  Mat3 rx;
  rx << 1, 0, 0, 0, cx, -sx, 0, sx, cx;
  Mat3 ry;
  ry << cy, 0, sy, 0, 1, 0, -sy, 0, cy;
  Mat3 rz;
  rz << cz, -sz, 0, sz, cz, 0, 0, 0, 1;
  return rz * ry * rx;
}

void checkRotation(Reader& r, const Mat3& rotation, const std::string& path) {
  const double deviation =
      (rotation * rotation.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(deviation <= kRotationTolerance)) {
    r.fail(path, "not a rotation: max |R*R^T - I| is " + formatDeviation(deviation) +
                     " (must be at most " + formatDeviation(kRotationTolerance) + ")");
    return;
  }
  const double det = rotation.determinant();
  if (!(std::abs(det - 1) <= kRotationTolerance)) {
    r.fail(path, "not a rotation: det R is " + formatDeviation(det) + " (must be 1 within " +
                     formatDeviation(kRotationTolerance) +
                     (det < 0 ? "; det -1 is a reflection)" : ")"));
  }
}

void readLighting(Reader& r, const Json& doc, Lighting& out) {
  const std::string path = "lighting";
  const Json* v = r.find(doc, path);
  if (v == nullptr || !r.object(*v, path, "the lighting settings", kLightingKeys)) {
    return;
  }
  r.vec3(*v, path, "ambient", "r, g, b, each 0 to 1", Range::kFraction, out.ambient);
  r.number(*v, path, "projector_power", Range::kPositive, out.projectorPower);
  r.boolean(*v, path, "inverse_square", out.inverseSquare);
  r.number(*v, path, "reference_distance_m", Range::kPositive, out.referenceDistanceM);
  r.number(*v, path, "projector_defocus_sigma_px", Range::kNonNegative,
           out.projectorDefocusSigmaPx);
}

void readCameraResponse(Reader& r, const Json& doc, CameraResponse& out) {
  const std::string path = "camera_response";
  const Json* v = r.find(doc, path);
  if (v == nullptr || !r.object(*v, path, "the camera response settings", kCameraKeys)) {
    return;
  }
  r.mat3(*v, path, "crosstalk", "row-major 3x3 matrix, camera RGB = crosstalk * scene RGB",
         out.crosstalk);
  r.number(*v, path, "gain", Range::kPositive, out.gain);
  r.vec3(*v, path, "noise_sigma", "r, g, b in grey levels", Range::kNonNegative, out.noiseSigma);
  r.number(*v, path, "defocus_sigma_px", Range::kNonNegative, out.defocusSigmaPx);
}

std::string shapeTypeNames() {
  std::string out;
  for (const auto& t : kShapeTypes) {
    out += (out.empty() ? "" : ", ") + std::string(t.name);
  }
  return out;
}

// "radius_m is for sphere and cylinder shapes" when another shape type has the key.
std::string otherShapeHint(std::string_view key, std::string_view type) {
  std::vector<std::string_view> owners;
  for (const auto& t : kShapeTypes) {
    if (std::find(t.keys.begin(), t.keys.end(), key) != t.keys.end()) {
      owners.push_back(t.name);
    }
  }
  if (owners.empty()) {
    return {};
  }
  std::string list;
  for (std::size_t i = 0; i < owners.size(); ++i) {
    list += (i == 0 ? "" : (i + 1 == owners.size() ? " and " : ", ")) + std::string(owners[i]);
  }
  return std::string(key) + " is for " + list + " shapes, not for a " + std::string(type);
}

const ShapeType* readShapeType(Reader& r, const Json& shape, const std::string& path) {
  const std::string at = member(path, "type");
  const auto it = shape.find("type");
  if (it == shape.end()) {
    r.fail(at, "required field is missing; one of " + shapeTypeNames());
    return nullptr;
  }
  if (!it->is_string()) {
    r.fail(at, "must be a string, one of " + shapeTypeNames() + "; got " + describe(*it));
    return nullptr;
  }
  const auto& name = it->get_ref<const std::string&>();
  for (const auto& t : kShapeTypes) {
    if (t.name == name) {
      return &t;
    }
  }
  std::string_view guess;
  for (const auto& [word, type] : kShapeSynonyms) {
    if (equalIgnoringCase(word, name)) {
      guess = type;
    }
  }
  if (guess.empty()) {
    std::array<std::string_view, kShapeTypes.size()> names{};
    std::transform(kShapeTypes.begin(), kShapeTypes.end(), names.begin(),
                   [](const ShapeType& t) { return t.name; });
    guess = closestWord(name, names);
  }
  r.fail(at, "unknown shape type " + jsonQuote(name) +
                 (guess.empty() ? "" : " (did you mean " + jsonQuote(guess) + "?)") +
                 "; types: " + shapeTypeNames());
  return nullptr;
}

// Shape parameters; a mesh keeps the path as written until the object's files are loaded.
void readShape(Reader& r, const Json& obj, const std::string& objectPath, Shape& out) {
  const std::string path = member(objectPath, "shape");
  const Json* v = r.find(obj, "shape");
  if (v == nullptr) {
    r.fail(path, R"(required field is missing; e.g. "shape": {"type": "sphere", "radius_m": 0.1})");
    return;
  }
  if (!v->is_object()) {
    r.fail(path, "must be an object {\"type\": ...}, got " + describe(*v));
    return;
  }
  const ShapeType* type = readShapeType(r, *v, path);
  if (type == nullptr) {
    return;
  }
  if (const auto key = unknownKey(*v, type->keys)) {
    r.fail(path, unknownKeyProblem(*key, type->keys, otherShapeHint(*key, type->name)));
    return;
  }
  if (type->name == "plane") {
    Plane plane;
    r.number(*v, path, "width_m", Range::kPositive, plane.widthM);
    r.number(*v, path, "height_m", Range::kPositive, plane.heightM);
    out = plane;
  } else if (type->name == "box") {
    Box box;
    r.vec3(*v, path, "size_m", "x, y, z edge lengths in metres, each positive", Range::kPositive,
           box.sizeM);
    out = box;
  } else if (type->name == "sphere") {
    Sphere sphere;
    r.number(*v, path, "radius_m", Range::kPositive, sphere.radiusM);
    out = sphere;
  } else if (type->name == "cylinder") {
    Cylinder cylinder;
    r.number(*v, path, "radius_m", Range::kPositive, cylinder.radiusM);
    r.number(*v, path, "height_m", Range::kPositive, cylinder.heightM);
    r.boolean(*v, path, "capped", cylinder.capped);
    out = cylinder;
  } else {
    Mesh mesh;
    mesh.path = r.text(*v, path, "path", "the PLY or OBJ file, e.g. \"meshes/bun_zipper.ply\"")
                    .value_or(std::string());
    out = std::move(mesh);
  }
}

void readPose(Reader& r, const Json& obj, const std::string& objectPath, Pose& out) {
  const std::string path = member(objectPath, "pose");
  const Json* v = r.find(obj, "pose");
  if (v == nullptr || !r.object(*v, path, "the object's pose", kPoseKeys)) {
    return;
  }
  r.vec3(*v, path, "t", "x, y, z in metres", Range::kAny, out.t);
  if (v->contains("R") && v->contains("rotation_deg")) {
    r.fail(path, R"(give the rotation as "R" or as "rotation_deg", not both)");
    return;
  }
  if (v->contains("rotation_deg")) {
    Vec3 degrees = Vec3::Zero();
    r.vec3(*v, path, "rotation_deg", "rx, ry, rz in degrees, R = Rz * Ry * Rx", Range::kAny,
           degrees);
    out.R = rotationFromDegrees(degrees);
  } else if (v->contains("R")) {
    r.mat3(*v, path, "R", "row-major 3x3 rotation, object to world", out.R);
    if (r.ok()) {
      checkRotation(r, out.R, member(path, "R"));
    }
  }
  r.number(*v, path, "scale", Range::kPositive, out.scale);
}

void readMotion(Reader& r, const Json& obj, const std::string& objectPath, Motion& out) {
  const std::string path = member(objectPath, "motion");
  const Json* v = r.find(obj, "motion");
  if (v == nullptr || !r.object(*v, path, "the object's motion per frame", kMotionKeys)) {
    return;
  }
  r.vec3(*v, path, "velocity_m_per_frame", "x, y, z in metres per frame", Range::kAny,
         out.velocityMPerFrame);
  r.vec3(*v, path, "axis", "x, y, z direction of the rotation axis", Range::kAny, out.axis);
  if (r.ok()) {
    // stableNorm: [1e300, 0, 0] is a fine direction even though its squared norm overflows.
    const double norm = out.axis.stableNorm();
    if (!(norm > 0)) {
      r.fail(member(path, "axis"),
             "must not be the zero vector; it is the direction of the rotation axis, e.g. [0, 1, "
             "0]");
      return;
    }
    out.axis /= norm;
  }
  r.number(*v, path, "angular_deg_per_frame", Range::kAny, out.angularDegPerFrame);
  r.vec3(*v, path, "pivot", "x, y, z of a point on the axis, metres", Range::kAny, out.pivot);
}

void readChecker(Reader& r, const Json& v, const std::string& path, CheckerTexture& out) {
  if (!r.object(v, path, R"(a checkerboard {"square_m", "colours"})", kCheckerKeys)) {
    return;
  }
  r.number(v, path, "square_m", Range::kPositive, out.squareM);
  const Json* colours = r.find(v, "colours");
  if (colours == nullptr) {
    return;
  }
  const std::string at = member(path, "colours");
  if (!colours->is_array() || colours->empty()) {
    r.fail(at, "must be an array of at least one [r, g, b] colour, got " + describe(*colours));
    return;
  }
  out.colours.clear();
  for (std::size_t i = 0; i < colours->size(); ++i) {
    const auto rgb =
        r.numbers<3>((*colours)[i], element(at, i), "r, g, b, each 0 to 1", Range::kFraction);
    if (!rgb) {
      return;
    }
    out.colours.emplace_back((*rgb)[0], (*rgb)[1], (*rgb)[2]);
  }
}

void readTexture(Reader& r, const Json& v, const std::string& path, ImageTexture& out) {
  if (!r.object(v, path, R"(an image texture {"path", "width_m", "height_m"})", kTextureKeys)) {
    return;
  }
  out.path =
      r.text(v, path, "path", "the PNG file, e.g. \"textures/poster.png\"").value_or(std::string());
  r.number(v, path, "width_m", Range::kPositive, out.widthM);
  r.number(v, path, "height_m", Range::kPositive, out.heightM);
}

void readAlbedo(Reader& r, const Json& obj, const std::string& objectPath, Albedo& out) {
  const std::string path = member(objectPath, "albedo");
  const Json* v = r.find(obj, "albedo");
  if (v == nullptr || !r.object(*v, path, "the object's albedo", kAlbedoKeys)) {
    return;
  }
  std::vector<std::string_view> given;
  for (const auto key : kAlbedoKeys) {
    if (v->contains(key)) {
      given.push_back(key);
    }
  }
  if (given.size() != 1) {
    std::string got;
    for (std::size_t i = 0; i < given.size(); ++i) {
      got += (i == 0 ? ", got " : (i + 1 == given.size() ? " and " : ", ")) + jsonQuote(given[i]);
    }
    r.fail(path, R"(needs exactly one of "rgb", "checker" or "texture")" + got);
    return;
  }
  if (given[0] == "rgb") {
    r.vec3(*v, path, "rgb", "r, g, b, each 0 to 1", Range::kFraction, out.rgb);
  } else if (given[0] == "checker") {
    CheckerTexture checker;
    readChecker(r, v->at("checker"), member(path, "checker"), checker);
    out.texture = std::move(checker);
  } else {
    ImageTexture texture;
    readTexture(r, v->at("texture"), member(path, "texture"), texture);
    out.texture = std::move(texture);
  }
}

// Object names are unique; an unnamed object is "object<N>" after its index.
class NameRegistry {
 public:
  void add(Reader& r, const std::string& name, const std::string& path, bool given) {
    const auto [it, inserted] = owners_.emplace(name, Owner{path, given});
    if (inserted) {
      return;
    }
    const std::string owner =
        it->second.given ? it->second.path : "the unnamed " + it->second.path + " (its default)";
    if (given) {
      r.fail(member(path, "name"), jsonQuote(name) + " is already the name of " + owner +
                                       "; object names must be unique");
    } else {
      r.fail(path, "has no name, and its default name " + jsonQuote(name) +
                       " is already the name of " + owner + "; give one of them another name");
    }
  }

 private:
  struct Owner {
    std::string path;
    bool given;
  };
  std::map<std::string, Owner, std::less<>> owners_;
};

// Loads what the object's shape and albedo name; the same mesh file is read once per scene.
class FileLoader {
 public:
  explicit FileLoader(fs::path baseDir) : baseDir_(std::move(baseDir)) {}

  void load(Reader& r, const std::string& objectPath, Object& object) {
    if (auto* mesh = std::get_if<Mesh>(&object.shape); mesh != nullptr && r.ok()) {
      loadMeshFile(r, member(member(objectPath, "shape"), "path"), *mesh);
    }
    if (auto* texture = std::get_if<ImageTexture>(&object.albedo.texture);
        texture != nullptr && r.ok()) {
      loadTexture(r, member(member(member(objectPath, "albedo"), "texture"), "path"), *texture);
    }
  }

 private:
  [[nodiscard]] fs::path resolve(const std::string& path) const {
    return (baseDir_ / path).lexically_normal();
  }

  void loadMeshFile(Reader& r, const std::string& field, Mesh& mesh) {
    const fs::path file = resolve(mesh.path);
    auto it = meshes_.find(file);
    if (it == meshes_.end()) {
      auto loaded = loadMesh(file);
      if (!loaded) {
        r.fail(field, "cannot load mesh " + loaded.error().message());
        return;
      }
      it = meshes_.emplace(file, std::move(*loaded)).first;
    }
    mesh = it->second;
  }

  void loadTexture(Reader& r, const std::string& field, ImageTexture& texture) const {
    const fs::path file = resolve(texture.path);
    texture.path = file.string();
    std::error_code ec;
    if (!fs::exists(fs::status(file, ec))) {
      r.fail(field, "cannot load texture " + file.string() + ": cannot read the file: " +
                        (ec ? ec.message() : std::string("no such file")));
      return;
    }
    const auto image = readPngRgb8(file);
    if (!image) {
      r.fail(field, "cannot load texture " + image.error());
      return;
    }
    texture.width = image->width;
    texture.height = image->height;
    texture.texels.resize(image->pixels.size());
    // 8-bit values taken as linear albedo (no sRGB curve): the scene's textures are synthetic
    // charts whose values are meant as reflectances. Divided, not multiplied by 1/255, so that
    // 255 is exactly 1 and 51 exactly 0.2F.
    std::transform(image->pixels.begin(), image->pixels.end(), texture.texels.begin(),
                   [](const algo::Rgb8& p) {
                     return std::array<float, 3>{static_cast<float>(p.r) / 255.0F,
                                                 static_cast<float>(p.g) / 255.0F,
                                                 static_cast<float>(p.b) / 255.0F};
                   });
  }

  fs::path baseDir_;
  std::map<fs::path, Mesh> meshes_;
};

void readObject(Reader& r, const Json& v, std::size_t index, NameRegistry& names, FileLoader& files,
                Scene& scene) {
  const std::string path = element("objects", index);
  if (!r.object(v, path, "one scene object {\"shape\": ...}", kObjectKeys)) {
    return;
  }
  Object object;
  if (r.find(v, "name") != nullptr) {
    object.name = r.text(v, path, "name", "").value_or(std::string());
    if (r.ok()) {
      names.add(r, object.name, path, true);
    }
  } else {
    object.name = "object" + std::to_string(index);
    names.add(r, object.name, path, false);
  }
  readShape(r, v, path, object.shape);
  readPose(r, v, path, object.pose);
  readMotion(r, v, path, object.motion);
  readAlbedo(r, v, path, object.albedo);
  files.load(r, path, object);
  scene.objects.push_back(std::move(object));
}

void readObjects(Reader& r, const Json& doc, const fs::path& baseDir, Scene& scene) {
  const auto it = doc.find("objects");
  if (it == doc.end()) {
    r.fail("objects",
           "required field is missing; a scene needs at least one object, e.g. \"objects\": "
           "[{\"shape\": {\"type\": \"plane\"}}]");
    return;
  }
  if (!it->is_array()) {
    r.fail("objects", "must be an array of objects, got " + describe(*it));
    return;
  }
  if (it->empty()) {
    r.fail("objects", "at least one object is required, got none");
    return;
  }
  NameRegistry names;
  FileLoader files(baseDir);
  for (std::size_t i = 0; i < it->size() && r.ok(); ++i) {
    readObject(r, (*it)[i], i, names, files, scene);
  }
}

std::optional<SceneError> checkFormat(const Json& doc) {
  const std::string supported = "supported: " + jsonQuote(kSceneFormat);
  const auto it = doc.find("format");
  if (it == doc.end()) {
    return SceneError{{},
                      "format",
                      "required field is missing; a scene.json starts with \"format\": " +
                          jsonQuote(kSceneFormat)};
  }
  if (!it->is_string()) {
    return SceneError{
        {},
        "format",
        "must be a string such as " + jsonQuote(kSceneFormat) + ", got " + describe(*it)};
  }
  const auto& format = it->get_ref<const std::string&>();
  if (format == kSceneFormat) {
    return std::nullopt;
  }
  if (format.starts_with("stripemux-scene/")) {
    return SceneError{{}, "format", "unsupported version " + jsonQuote(format) + "; " + supported};
  }
  const std::string hint =
      format.starts_with("stripemux-rig/") ? " (this is a rig.json, not a scene)" : "";
  return SceneError{{}, "format", "unknown format " + jsonQuote(format) + hint + "; " + supported};
}

std::unexpected<SceneError> failDocument(std::string problem) {
  return std::unexpected(SceneError{{}, {}, std::move(problem)});
}

std::expected<Scene, SceneError> parseSceneImpl(std::string_view text, const fs::path& baseDir) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    return failDocument(
        "not valid JSON: the text is empty; a scene.json is a JSON object {\"format\": ...}");
  }
  if (text.size() > kMaxSceneBytes) {
    return failDocument("the text is " + std::to_string(text.size()) +
                        " bytes; a scene.json is at most " + std::to_string(kMaxSceneBytes) +
                        " bytes (meshes and textures go in their own files)");
  }
  if (const auto depth = nestingDepth(text); depth > kMaxNesting) {
    return failDocument("nested " + std::to_string(depth) + " levels deep; a scene.json needs " +
                        std::to_string(kNestingNeeded) + " and at most " +
                        std::to_string(kMaxNesting) + " are accepted");
  }
  ParseTracker tracker;
  Json doc;
  try {
    doc = Json::parse(text, [&](int, Json::parse_event_t event, Json& parsed) {
      return tracker.onEvent(event, parsed);
    });
  } catch (const Json::parse_error& e) {
    return failDocument(parseErrorProblem(e.what()));
  } catch (const Json::out_of_range& e) {
    // JSON has no NaN or infinity; the only non-finite number is one that overflows a double.
    if (e.id == 406) {
      return std::unexpected(SceneError{{},
                                        tracker.currentPath(),
                                        "must be a finite number; " + overflowedLiteral(e.what()) +
                                            " is too large for a double"});
    }
    throw;
  }
  if (!doc.is_object()) {
    return failDocument("the top level must be a JSON object {\"format\": ...}, got " +
                        describe(doc));
  }
  if (auto format = checkFormat(doc)) {
    return std::unexpected(std::move(*format));
  }
  if (const auto& duplicate = tracker.duplicate(); duplicate.has_value()) {
    return std::unexpected(*duplicate);
  }
  Reader r;
  Scene scene;
  r.object(doc, "", "", kTopKeys);
  r.integer(doc, "", "supersampling", 1, kMaxSupersampling, "samples per pixel side",
            scene.supersampling);
  readLighting(r, doc, scene.lighting);
  readCameraResponse(r, doc, scene.camera);
  readObjects(r, doc, baseDir, scene);
  if (!r.ok()) {
    return r.error();
  }
  return scene;
}

}  // namespace

std::string SceneError::message() const {
  std::string out;
  for (const auto* part : {&file, &field, &problem}) {
    if (!part->empty()) {
      out += (out.empty() ? "" : ": ") + *part;
    }
  }
  return out;
}

std::expected<Scene, SceneError> parseScene(std::string_view jsonText,
                                            const std::filesystem::path& baseDir) {
  try {
    return parseSceneImpl(jsonText, baseDir);
  } catch (const std::exception& e) {
    // Out of memory or a library surprise: still an error value, never an exception.
    return failDocument(std::string("cannot read the scene: ") + e.what());
  }
}

std::expected<Scene, SceneError> loadScene(const std::filesystem::path& file) {
  const auto withFile = [&](SceneError e) {
    e.file = file.string();
    return std::unexpected(std::move(e));
  };
  try {
    std::error_code ec;
    const auto status = fs::status(file, ec);
    if (ec || !fs::exists(status)) {
      return withFile(
          {{}, {}, "cannot read the file: " + (ec ? ec.message() : std::string("no such file"))});
    }
    if (fs::is_directory(status)) {
      return withFile({{}, {}, "cannot read the file: it is a directory"});
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      return withFile(
          {{},
           {},
           "cannot read the file: " + std::generic_category().message(errno != 0 ? errno : EIO)});
    }
    std::string text;
    std::array<char, 4096> chunk{};
    while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0) {
      text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
      if (text.size() > kMaxSceneBytes) {
        return withFile({{},
                         {},
                         "file is larger than " + std::to_string(kMaxSceneBytes) +
                             " bytes; a scene.json is a few kB"});
      }
    }
    if (in.bad()) {
      return withFile({{}, {}, "cannot read the file: read error"});
    }
    auto scene = parseScene(text, file.parent_path());
    if (!scene) {
      return withFile(std::move(scene.error()));
    }
    return scene;
  } catch (const std::exception& e) {
    return withFile({{}, {}, std::string("cannot read the file: ") + e.what()});
  }
}

}  // namespace smx::sim
