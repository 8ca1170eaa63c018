#include "smx/protocol/rig_json.hpp"

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
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

namespace smx::protocol {
namespace {

using Json = nlohmann::json;
using Status = std::expected<void, RigError>;

// Larger images are certainly a typo, and a bound keeps width * height far from int overflow.
constexpr int kMaxImageSidePx = 65535;
constexpr double kRotationTolerance = 1e-6;
// A rig.json is a few kB and 4 levels deep. The bounds keep a hostile or mistaken input (a
// video file, /dev/zero, "[[[[...") from costing the board more than a few MB.
constexpr std::size_t kMaxRigBytes = std::size_t{1} << 20U;
constexpr std::size_t kMaxNesting = 16;
constexpr std::string_view kKStructure = "K is [fx 0 cx; 0 fy cy; 0 0 1]";

constexpr std::array<std::string_view, 3> kTopKeys = {"format", "cameras", "projectors"};
constexpr std::array<std::string_view, 7> kCameraKeys = {"id",   "width", "height", "K",
                                                         "dist", "R",     "t"};
constexpr std::array<std::string_view, 8> kProjectorKeys = {"id",   "width", "height", "K",
                                                            "dist", "R",     "t",      "pattern"};
constexpr std::array<std::string_view, 3> kPatternKeys = {"angle_deg", "stripe_px", "offset_px"};

std::unexpected<RigError> fail(std::string field, std::string problem) {
  return std::unexpected(RigError{{}, std::move(field), std::move(problem)});
}

std::string member(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string element(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Shortest text that reads back to the same double (what toJson() writes, and what users see).
std::string formatNumber(double v) {
  if (!std::isfinite(v)) {
    return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  }
  if (v == 0.0 && std::signbit(v)) {
    return "-0.0";  // "-0" would read back as the integer 0
  }
  // Plain notation where people expect it (100000, 0.0125), exponent notation for the extremes;
  // either way the shortest digits that read back to the same double.
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

std::string joined(std::span<const std::string_view> words) {
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
      const std::size_t replace = diagonal + (a[i - 1] == b[j - 1] ? 0U : 1U);
      row[j] = std::min({above + 1, row[j - 1] + 1, replace});
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

// The allowed key the user probably meant ("k" -> "K", "angle" -> "angle_deg", "strip_px" ->
// "stripe_px"), or empty when nothing is close enough to be a useful hint.
std::string_view closestKey(std::string_view key, std::span<const std::string_view> allowed) {
  std::string_view best;
  std::size_t bestDistance = 3;  // only suggest within two edits ...
  for (const auto candidate : allowed) {
    if (equalIgnoringCase(key, candidate)) {
      return candidate;
    }
    const bool prefix = std::min(key.size(), candidate.size()) >= 3 &&
                        (key.starts_with(candidate) || candidate.starts_with(key));
    const std::size_t d = prefix ? 1 : editDistance(key, candidate);
    if (d < bestDistance &&
        2 * d < key.size()) {  // ... and fewer than half the key: not "fx"->"id"
      best = candidate;
      bestDistance = d;
    }
  }
  return best;
}

// Unknown keys are errors, not ignored: a misspelt optional key would otherwise fall back to a
// default without a word. The closest allowed key is suggested.
Status checkKeys(const Json& obj, const std::string& path,
                 std::span<const std::string_view> allowed, std::string_view hint = {}) {
  for (const auto& [key, value] : obj.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) {
      continue;
    }
    std::string problem = "unknown key " + jsonQuote(key);
    if (!hint.empty()) {
      problem += " (" + std::string(hint) + ")";
    } else if (const auto guess = closestKey(key, allowed); !guess.empty()) {
      problem += " (did you mean " + jsonQuote(guess) + "?)";
    }
    return fail(path, problem + "; allowed keys: " + joined(allowed));
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
  return v > kMaxImageSidePx ? "must be at most " + std::to_string(kMaxImageSidePx) +
                                   " pixels, got " + formatNumber(v)
                             : "must be a positive integer (pixels), got " + formatNumber(v);
}

std::expected<int, RigError> readSize(const Json& v, const std::string& path) {
  auto d = readNumber(v, path);
  if (!d) {
    return std::unexpected(d.error());
  }
  // 640.0 is accepted: it is an integer, only written differently.
  if (*d != std::floor(*d) || *d < 1 || *d > kMaxImageSidePx) {
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
  if (v < 1 || v > kMaxImageSidePx) {
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

Status checkRotation(const std::array<double, 9>& r, const std::string& path) {
  double deviation = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      double rrt = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        rrt += r[3 * i + k] * r[3 * j + k];
      }
      deviation = std::max(deviation, std::abs(rrt - (i == j ? 1.0 : 0.0)));
    }
  }
  if (!(deviation <= kRotationTolerance)) {
    return fail(path, "not a rotation: max |R*R^T - I| is " + formatDeviation(deviation) +
                          " (must be at most " + formatDeviation(kRotationTolerance) + ")");
  }
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  if (!(std::abs(det - 1) <= kRotationTolerance)) {
    return fail(path, "not a rotation: det R is " + formatDeviation(det) + " (must be 1 within " +
                          formatDeviation(kRotationTolerance) +
                          (det < 0 ? "; det -1 is a reflection)" : ")"));
  }
  return {};
}

class IdRegistry {
 public:
  Status add(const std::string& id, const std::string& path) {
    if (id.empty()) {
      return fail(member(path, "id"), "must not be empty");
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
  if (auto s = checkFinite(d.dist, member(path, "dist")); !s) {
    return s;
  }
  if (auto s = checkFinite(d.R, member(path, "R")); !s) {
    return s;
  }
  if (auto s = checkRotation(d.R, member(path, "R")); !s) {
    return s;
  }
  return checkFinite(d.t, member(path, "t"));
}

Status checkPattern(const algo::StripePattern& p, const std::string& path) {
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
  return {};
}

Status checkCount(std::size_t n, const std::string& path, std::string_view what) {
  if (n == 0) {
    return fail(path, "at least one " + std::string(what) + " is required, got none");
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
    return checkPattern(d.pattern, at);
  }
  return {};
}

template <class Device>
std::expected<std::vector<Device>, RigError> readDevices(const Json& doc, std::string_view key,
                                                         std::string_view what, IdRegistry& ids) {
  const std::string path(key);
  const auto it = doc.find(key);
  if (it == doc.end()) {
    return fail(path, "required field is missing");
  }
  if (!it->is_array()) {
    return fail(path, "must be an array of " + std::string(what) + "s, got " + describe(*it));
  }
  if (auto s = checkCount(it->size(), path, what); !s) {
    return std::unexpected(s.error());
  }
  std::vector<Device> devices(it->size());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const Json& obj = (*it)[i];
    const std::string at = element(path, i);
    if (!obj.is_object()) {
      return fail(at, "must be an object (one " + std::string(what) + "), got " + describe(obj));
    }
    if (auto s = readDevice(obj, at, ids, devices[i]); !s) {
      return std::unexpected(s.error());
    }
  }
  return devices;
}

Status checkFormat(const Json& doc) {
  const std::string supported = "supported: " + jsonQuote(kRigFormat);
  const auto it = doc.find("format");
  if (it == doc.end()) {
    return fail("format", "required field is missing; a rig.json starts with \"format\": " +
                              jsonQuote(kRigFormat));
  }
  if (!it->is_string()) {
    return fail("format",
                "must be a string such as " + jsonQuote(kRigFormat) + ", got " + describe(*it));
  }
  const auto& format = it->get_ref<const std::string&>();
  if (format == kRigFormat) {
    return {};
  }
  if (format.starts_with("stripemux-rig/")) {
    return fail("format", "unsupported version " + jsonQuote(format) + "; " + supported);
  }
  return fail("format", "unknown format " + jsonQuote(format) + "; " + supported);
}

// Follows the JSON path while nlohmann parses, for two things nlohmann does not report by path:
// a duplicated key (nlohmann keeps the last one without a word; a second "t" is a mistake) and a
// number too large for a double (nlohmann stops with "number overflow").
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
            duplicate_ = RigError{{},
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

  [[nodiscard]] const std::optional<RigError>& duplicate() const { return duplicate_; }

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
  // One path component per frame; whole paths are built only for an error, so deep nesting
  // costs linear memory, not quadratic.
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
  std::optional<RigError> duplicate_;
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

std::expected<algo::Rig, RigError> parseRigImpl(std::string_view text) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    return fail("",
                "not valid JSON: the text is empty; a rig.json is a JSON object {\"format\": ...}");
  }
  if (text.size() > kMaxRigBytes) {
    return fail("", "the text is " + std::to_string(text.size()) +
                        " bytes; a rig.json is at most " + std::to_string(kMaxRigBytes) + " bytes");
  }
  if (const auto depth = nestingDepth(text); depth > kMaxNesting) {
    return fail("", "nested " + std::to_string(depth) +
                        " levels deep; a rig.json needs 4 and at most " +
                        std::to_string(kMaxNesting) + " are accepted");
  }
  ParseTracker tracker;
  Json doc;
  try {
    doc = Json::parse(text, [&](int, Json::parse_event_t event, Json& parsed) {
      return tracker.onEvent(event, parsed);
    });
  } catch (const Json::parse_error& e) {
    return fail("", parseErrorProblem(e.what()));
  } catch (const Json::out_of_range& e) {
    // JSON has no NaN or infinity; the only non-finite number is one that overflows a double.
    if (e.id == 406) {
      return fail(tracker.currentPath(), "must be a finite number; " + overflowedLiteral(e.what()) +
                                             " is too large for a double");
    }
    throw;
  }
  if (!doc.is_object()) {
    return fail("", "the top level must be a JSON object {\"format\": ...}, got " + describe(doc));
  }
  if (auto format = checkFormat(doc); !format) {
    return std::unexpected(format.error());
  }
  if (const auto& duplicate = tracker.duplicate(); duplicate.has_value()) {
    return std::unexpected(*duplicate);
  }
  if (auto keys = checkKeys(doc, "", kTopKeys); !keys) {
    return std::unexpected(keys.error());
  }
  IdRegistry ids;
  algo::Rig rig;
  auto cameras = readDevices<algo::Camera>(doc, "cameras", "camera", ids);
  if (!cameras) {
    return std::unexpected(cameras.error());
  }
  rig.cameras = std::move(*cameras);
  auto projectors = readDevices<algo::Projector>(doc, "projectors", "projector", ids);
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
  std::string out;
  for (const auto* part : {&file, &field, &problem}) {
    if (!part->empty()) {
      out += (out.empty() ? "" : ": ") + *part;
    }
  }
  return out;
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
  const auto withFile = [&](RigError e) {
    e.file = path.string();
    return std::unexpected(std::move(e));
  };
  try {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
      return withFile(
          {{}, {}, "cannot read the file: " + (ec ? ec.message() : std::string("no such file"))});
    }
    if (std::filesystem::is_directory(status)) {
      return withFile({{}, {}, "cannot read the file: it is a directory"});
    }
    std::ifstream in(path, std::ios::binary);
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
      if (text.size() > kMaxRigBytes) {
        return withFile({{},
                         {},
                         "file is larger than " + std::to_string(kMaxRigBytes) +
                             " bytes; a rig.json is a few kB"});
      }
    }
    if (in.bad()) {
      return withFile({{}, {}, "cannot read the file: read error"});
    }
    auto rig = parseRig(text);
    if (!rig) {
      return withFile(std::move(rig.error()));
    }
    return rig;
  } catch (const std::exception& e) {
    return withFile({{}, {}, std::string("cannot read the file: ") + e.what()});
  }
}

std::expected<void, RigError> validateRig(const algo::Rig& rig) {
  try {
    IdRegistry ids;
    if (auto s = checkCount(rig.cameras.size(), "cameras", "camera"); !s) {
      return s;
    }
    for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
      if (auto s = checkDevice(rig.cameras[i], element("cameras", i), ids); !s) {
        return s;
      }
    }
    if (auto s = checkCount(rig.projectors.size(), "projectors", "projector"); !s) {
      return s;
    }
    for (std::size_t i = 0; i < rig.projectors.size(); ++i) {
      const std::string at = element("projectors", i);
      if (auto s = checkDevice(rig.projectors[i], at, ids); !s) {
        return s;
      }
      if (auto s = checkPattern(rig.projectors[i].pattern, member(at, "pattern")); !s) {
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

}  // namespace smx::protocol
