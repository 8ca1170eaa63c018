#include "smx/config/device_config.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <nlohmann/json.hpp>
#include <utility>

#include "smx/algo/range_image.hpp"
#include "smx/config/field_reader.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/rig_json.hpp"

namespace smx::config {
namespace {

using Json = nlohmann::json;

constexpr std::array<std::string_view, 10> kSettingKeys = {
    "fps",         "exposure_us", "gain",        "projectors",     "projector_power",
    "compression", "depth_min_m", "depth_max_m", "confidence_min", "rig"};
constexpr std::array<std::string_view, 11> kTopKeys = {
    "format",      "fps",         "exposure_us", "gain",           "projectors", "projector_power",
    "compression", "depth_min_m", "depth_max_m", "confidence_min", "rig"};
// exposure_us and gain: the camera's own setting (stored as 0).
constexpr std::string_view kCameraOwn = "camera";
constexpr int kMaxExposureUs = 1'000'000;
constexpr double kMaxGain = 64.0;
constexpr std::array<std::string_view, 3> kCompressions = {"any", "rvl", "none"};

constexpr std::array<FormatHint, 2> kOtherFormats = {
    {{"stripemux-rig/", " (this is a rig.json; a configuration holds it under \"rig\")"},
     {"stripemux-board/", " (this is a board.json, which the device's owner does not change)"}}};
constexpr DocumentSpec kConfigDocument = {.name = "config.json",
                                          .format = kDeviceConfigFormat,
                                          .topKeys = kTopKeys,
                                          .maxBytes = kDeviceConfigMaxBytes,
                                          .sizeNote = "",
                                          .nestingNeeded = 5,
                                          .maxNesting = 16,
                                          .otherFormats = kOtherFormats};

// The rig must describe the board's devices: the device decodes the cameras it has with the
// projectors its trigger lines switch.
void checkRigFitsBoard(FieldReader& r, const algo::Rig& rig, const algo::Rig& board) {
  if (rig.cameras.size() != board.cameras.size() ||
      rig.projectors.size() != board.projectors.size()) {
    r.fail("rig", "has " + std::to_string(rig.cameras.size()) + " cameras and " +
                      std::to_string(rig.projectors.size()) + " projectors; the board has " +
                      std::to_string(board.cameras.size()) + " and " +
                      std::to_string(board.projectors.size()));
    return;
  }
  for (std::size_t i = 0; i < rig.cameras.size() && r.ok(); ++i) {
    const auto& a = rig.cameras[i];
    const auto& b = board.cameras[i];
    const std::string at = element("rig.cameras", i);
    if (a.id != b.id) {
      r.fail(member(at, "id"), jsonQuote(a.id) + " is not the board's camera " + jsonQuote(b.id));
    } else if (a.width != b.width || a.height != b.height) {
      r.fail(at, "is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                     "; the board's camera is " + std::to_string(b.width) + "x" +
                     std::to_string(b.height));
    }
  }
  for (std::size_t i = 0; i < rig.projectors.size() && r.ok(); ++i) {
    if (rig.projectors[i].id != board.projectors[i].id) {
      r.fail(member(element("rig.projectors", i), "id"), jsonQuote(rig.projectors[i].id) +
                                                             " is not the board's projector " +
                                                             jsonQuote(board.projectors[i].id));
    }
  }
}

void readRig(FieldReader& r, const Json& doc, const Board& board, DeviceConfig& out) {
  const Json* v = r.find(doc, "rig");
  if (v == nullptr) {
    return;
  }
  if (!v->is_object()) {
    r.fail("rig", "must be an object (a stripemux-rig/1 document), got " + describe(*v));
    return;
  }
  auto rig = parseRig(v->dump());
  if (!rig) {
    r.fail(rig.error().field.empty() ? "rig" : "rig." + rig.error().field, rig.error().problem);
    return;
  }
  checkRigFitsBoard(r, *rig, board.rig);
  out.rig = std::move(*rig);
}

void readDepthWindow(FieldReader& r, const Json& doc, const Board& board,
                     const DeviceConfig& stored, DeviceConfig& out) {
  for (const auto& [key, value] :
       {std::pair{"depth_min_m", &out.depthMinM}, std::pair{"depth_max_m", &out.depthMaxM}}) {
    if (const Json* v = r.find(doc, key); v != nullptr) {
      *value = r.number(*v, key, Range::kNonNegative);
    }
  }
  if (!r.ok()) {
    return;
  }
  const double farthest = algo::maxStoredDepthM(board.config.depthUnitM);
  const double lo = out.depthMinM.value_or(stored.depthMinM.value_or(0.0));
  const double hi = out.depthMaxM.value_or(stored.depthMaxM.value_or(farthest));
  if (!(lo < hi)) {
    r.fail(out.depthMaxM ? "depth_max_m" : "depth_min_m",
           "the depth window would be empty: depth_min_m " + formatNumber(lo) +
               " must be less than depth_max_m " + formatNumber(hi));
  } else if (lo >= farthest) {
    r.fail("depth_min_m", "must be less than " + formatNumber(farthest) +
                              " m, the farthest depth the board's depth unit stores");
  }
}

void readCameraControls(FieldReader& r, const Json& doc, DeviceConfig& out) {
  if (const Json* v = r.find(doc, "exposure_us"); v != nullptr) {
    if (v->is_string() && v->get_ref<const std::string&>() == kCameraOwn) {
      out.exposureUs = 0;
    } else {
      int exposure = 0;
      r.integer(doc, "", "exposure_us", 1, kMaxExposureUs,
                "microseconds, or \"camera\" for the camera's own", exposure);
      out.exposureUs = exposure;
    }
  }
  if (const Json* v = r.find(doc, "gain"); v != nullptr) {
    if (v->is_string() && v->get_ref<const std::string&>() == kCameraOwn) {
      out.gain = 0.0;
    } else if (const auto gain = r.number(*v, "gain", Range::kPositive); gain) {
      if (*gain < 1.0 || *gain > kMaxGain) {
        r.fail("gain", "must be from 1 to " + formatNumber(kMaxGain) +
                           " (sensor gain), or \"camera\" for the camera's own, got " +
                           formatNumber(*gain));
      }
      out.gain = *gain;
    }
  }
}

// A set of the board's projectors, kept in the rig's order whatever order the document lists.
void readProjectors(FieldReader& r, const Json& doc, const Board& board, DeviceConfig& out) {
  if (const Json* v = r.find(doc, "projectors"); v != nullptr) {
    if (!v->is_array() || v->empty()) {
      r.fail("projectors",
             "must be a non-empty list of the board's projector ids, got " + describe(*v));
      return;
    }
    std::vector<bool> chosen(board.rig.projectors.size(), false);
    for (std::size_t i = 0; i < v->size() && r.ok(); ++i) {
      const Json& id = (*v)[i];
      const auto at = std::ranges::find_if(board.rig.projectors, [&](const algo::Projector& p) {
        return id.is_string() && p.id == id.get_ref<const std::string&>();
      });
      if (at == board.rig.projectors.end()) {
        std::vector<std::string_view> ids(board.rig.projectors.size());
        std::ranges::transform(board.rig.projectors, ids.begin(),
                               [](const algo::Projector& p) -> std::string_view { return p.id; });
        r.fail(element("projectors", i),
               describe(id) + " is not a projector of the board (" + joined(ids) + ")");
      } else if (chosen[static_cast<std::size_t>(at - board.rig.projectors.begin())]) {
        r.fail(element("projectors", i), describe(id) + " is listed twice");
      } else {
        chosen[static_cast<std::size_t>(at - board.rig.projectors.begin())] = true;
      }
    }
    std::vector<std::string> ids;
    for (std::size_t p = 0; p < chosen.size(); ++p) {
      if (chosen[p]) {
        ids.push_back(board.rig.projectors[p].id);
      }
    }
    out.projectors = std::move(ids);
  }
  if (r.find(doc, "projector_power") != nullptr) {
    int power = 0;
    r.integer(doc, "", "projector_power", 1, 100, "percent of full", power);
    out.projectorPower = power;
  }
}

std::expected<DeviceConfig, FieldError> parseImpl(std::string_view text, const Board& board,
                                                  const DeviceConfig& stored) {
  auto parsed = parseDocument(text, kConfigDocument);
  if (!parsed) {
    return std::unexpected(parsed.error());
  }
  const Json& doc = *parsed;
  FieldReader r;
  DeviceConfig out;
  if (r.find(doc, "fps") != nullptr) {
    int fps = 0;
    r.integer(doc, "", "fps", 1, 120, "frames per second", fps);
    out.fps = fps;
  }
  readCameraControls(r, doc, out);
  readProjectors(r, doc, board, out);
  if (const Json* v = r.find(doc, "compression"); v != nullptr) {
    if (!v->is_string() ||
        std::ranges::find(kCompressions, v->get_ref<const std::string&>()) == kCompressions.end()) {
      r.fail("compression", "must be one of: " + joined(kCompressions) + ", got " + describe(*v));
    } else {
      const auto* const at = std::ranges::find(kCompressions, v->get_ref<const std::string&>());
      out.compression = static_cast<Compression>(at - kCompressions.begin());
    }
  }
  readDepthWindow(r, doc, board, stored, out);
  if (r.find(doc, "confidence_min") != nullptr) {
    int confidence = 0;
    r.integer(doc, "", "confidence_min", 1, 255, "the least confidence kept", confidence);
    out.confidenceMin = confidence;
  }
  readRig(r, doc, board, out);
  if (!r.ok()) {
    return std::unexpected(r.firstError().value_or(FieldError{}));
  }
  return out;
}

Json settingsJson(const DeviceConfig& c) {
  Json doc = Json::object();
  doc["format"] = kDeviceConfigFormat;
  if (c.fps) {
    doc["fps"] = *c.fps;
  }
  if (c.exposureUs) {
    doc["exposure_us"] = *c.exposureUs == 0 ? Json(kCameraOwn) : Json(*c.exposureUs);
  }
  if (c.gain) {
    doc["gain"] = *c.gain == 0.0 ? Json(kCameraOwn) : Json(*c.gain);
  }
  if (c.projectors) {
    doc["projectors"] = *c.projectors;
  }
  if (c.projectorPower) {
    doc["projector_power"] = *c.projectorPower;
  }
  if (c.compression) {
    doc["compression"] = kCompressions.at(static_cast<std::size_t>(*c.compression));
  }
  if (c.depthMinM) {
    doc["depth_min_m"] = *c.depthMinM;
  }
  if (c.depthMaxM) {
    doc["depth_max_m"] = *c.depthMaxM;
  }
  if (c.confidenceMin) {
    doc["confidence_min"] = *c.confidenceMin;
  }
  if (c.rig) {
    doc["rig"] = Json::parse(toJson(*c.rig));
  }
  return doc;
}

}  // namespace

std::span<const std::string_view> deviceConfigKeys() {
  return kSettingKeys;
}

std::expected<DeviceConfig, FieldError> parseDeviceConfig(std::string_view text, const Board& board,
                                                          const DeviceConfig& stored) {
  try {
    return parseImpl(text, board, stored);
  } catch (const std::exception& e) {
    return std::unexpected(
        FieldError{{}, std::string("cannot read the configuration: ") + e.what()});
  }
}

std::expected<std::string, FieldError> readDeviceConfigText(const std::filesystem::path& file) {
  return readDocumentFile(file, kConfigDocument);
}

std::vector<std::string_view> setKeys(const DeviceConfig& config) {
  const Json doc = settingsJson(config);
  std::vector<std::string_view> keys;
  for (const std::string_view key : kSettingKeys) {
    if (doc.contains(key)) {
      keys.push_back(key);
    }
  }
  return keys;
}

std::expected<DeviceConfig, FieldError> loadDeviceConfig(const std::filesystem::path& file,
                                                         const Board& board) {
  try {
    auto text = readDeviceConfigText(file);
    if (!text) {
      return std::unexpected(text.error());
    }
    return parseDeviceConfig(*text, board);
  } catch (const std::exception& e) {
    return std::unexpected(
        FieldError{{}, std::string("cannot read the configuration: ") + e.what()});
  }
}

DeviceConfig merged(DeviceConfig stored, const DeviceConfig& change) {
  const auto take = [](auto& into, const auto& from) {
    if (from) {
      into = from;
    }
  };
  take(stored.fps, change.fps);
  take(stored.exposureUs, change.exposureUs);
  take(stored.gain, change.gain);
  take(stored.projectors, change.projectors);
  take(stored.projectorPower, change.projectorPower);
  take(stored.compression, change.compression);
  take(stored.depthMinM, change.depthMinM);
  take(stored.depthMaxM, change.depthMaxM);
  take(stored.confidenceMin, change.confidenceMin);
  take(stored.rig, change.rig);
  return stored;
}

std::string toJson(const DeviceConfig& config) {
  return settingsJson(config).dump(2) + "\n";
}

std::string effectiveJson(const DeviceConfig& config, const Board& board) {
  DeviceConfig all = config;
  all.fps = config.fps.value_or(board.config.cameras.front().format.fps);
  all.exposureUs = config.exposureUs.value_or(0);
  all.gain = config.gain.value_or(0.0);
  if (!all.projectors) {
    all.projectors.emplace();
    for (const auto& p : board.rig.projectors) {
      all.projectors->push_back(p.id);
    }
  }
  all.projectorPower = config.projectorPower.value_or(100);
  all.compression = config.compression.value_or(Compression::kAny);
  all.depthMinM = config.depthMinM.value_or(0.0);
  // To the micrometre: 65535 units of 0.1 mm are 6.5535 m, not 6.5535000000000005.
  all.depthMaxM = config.depthMaxM.value_or(
      std::round(algo::maxStoredDepthM(board.config.depthUnitM) * 1e6) / 1e6);
  all.confidenceMin = config.confidenceMin.value_or(1);
  all.rig = config.rig.value_or(board.rig);
  return toJson(all);
}

Board appliedTo(const DeviceConfig& config, Board board) {
  if (config.fps) {
    for (auto& camera : board.config.cameras) {
      camera.format.fps = *config.fps;
    }
  }
  for (auto& camera : board.config.cameras) {
    if (config.exposureUs) {
      camera.controls.exposureUs =
          *config.exposureUs == 0 ? std::nullopt : std::optional(*config.exposureUs);
    }
    if (config.gain) {
      camera.controls.gain = *config.gain == 0.0 ? std::nullopt : std::optional(*config.gain);
    }
  }
  if (config.projectors) {
    board.config.trigger.rangeMask = 0;
    for (std::size_t p = 0; p < board.rig.projectors.size(); ++p) {
      if (std::ranges::find(*config.projectors, board.rig.projectors[p].id) !=
          config.projectors->end()) {
        board.config.trigger.rangeMask |= 1U << p;
      }
    }
  }
  board.config.trigger.powerPercent = config.projectorPower.value_or(100);
  if (config.rig) {
    board.rig = *config.rig;
  }
  return board;
}

std::uint32_t rangeProjectorsMask(const Board& board) {
  const auto all =
      static_cast<std::uint32_t>((std::uint64_t{1} << board.rig.projectors.size()) - 1U);
  const std::uint32_t chosen = board.config.trigger.rangeMask;
  return chosen == 0 ? all : chosen & all;
}

algo::Rig rangeRig(const Board& board) {
  const std::uint32_t mask = rangeProjectorsMask(board);
  algo::Rig rig = board.rig;
  rig.projectors.clear();
  for (std::size_t p = 0; p < board.rig.projectors.size(); ++p) {
    if (((mask >> p) & 1U) != 0) {
      rig.projectors.push_back(board.rig.projectors[p]);
    }
  }
  return rig;
}

}  // namespace smx::config
