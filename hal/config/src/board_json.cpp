#include "smx/config/board_json.hpp"

#include <arpa/inet.h>

#include <array>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/range_image.hpp"
#include "smx/config/field_reader.hpp"
#include "smx/config/identifier.hpp"
#include "smx/config/json_reader.hpp"
#include "smx/config/rig_json.hpp"

namespace smx::config {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr std::array<std::string_view, 13> kTopKeys = {
    "format",  "name", "hal",         "rig",       "depth_unit_m", "cameras",  "triggers",
    "network", "sim",  "description", "turntable", "threads",      "pipelined"};
constexpr std::array<std::string_view, 5> kCameraKeys = {"id", "device", "pixel_format", "fps",
                                                         "buffers"};
constexpr std::array<std::string_view, 2> kTriggerKeys = {"lead_us", "lines"};
constexpr std::array<std::string_view, 4> kLineKeys = {"role", "chip", "line", "active_low"};
constexpr std::array<std::string_view, 3> kNetworkKeys = {"bind", "port", "send_buffer_kib"};
constexpr std::array<std::string_view, 8> kTurntableKeys = {
    "chip",           "step",        "dir",      "enable", "enable_active_low",
    "steps_per_turn", "speed_deg_s", "settle_ms"};
constexpr std::array<std::string_view, 3> kSimKeys = {"scene", "replay", "seed"};
constexpr std::array<std::string_view, 2> kHals = {"sim", "linux"};
constexpr std::array<std::string_view, 3> kPixelFormats = {"RGB24", "BGR24", "YUYV"};

constexpr std::array<FormatHint, 2> kOtherFormats = {
    {{"stripemux-rig/", " (this is a rig.json; a board names its rig in \"rig\")"},
     {"stripemux-scene/", " (this is a scene.json, not a board)"}}};
constexpr DocumentSpec kBoardDocument = {.name = "board.json",
                                         .format = kBoardFormat,
                                         .topKeys = kTopKeys,
                                         .maxBytes = std::size_t{1} << 16U,
                                         .sizeNote = "",
                                         .nestingNeeded = 4,
                                         .maxNesting = 16,
                                         .otherFormats = kOtherFormats};

class Reader : public FieldReader {
 public:
  // One of `allowed` words.
  std::optional<std::string> word(const Json& obj, const std::string& path, std::string_view key,
                                  Keys allowed) {
    auto value = text(obj, path, key, "one of: " + joined(allowed));
    if (value && std::ranges::find(allowed, *value) == allowed.end()) {
      fail(member(path, key), jsonQuote(*value) + " is not one of: " + joined(allowed));
      return std::nullopt;
    }
    return value;
  }

  // A required array of `count` entries, one per rig device (`devices`: "cameras").
  const Json* perDevice(const Json& obj, const std::string& path, std::string_view key,
                        std::size_t count, std::string_view devices) {
    const Json* v = find(obj, key);
    const std::string at = member(path, key);
    if (!ok()) {
      return nullptr;
    }
    if (v == nullptr || !v->is_array()) {
      fail(at, "must be an array, one entry per " + std::string(devices) + " of the rig" +
                   (v == nullptr ? ", but is missing" : ", got " + describe(*v)));
      return nullptr;
    }
    if (v->size() != count) {
      fail(at, "has " + std::to_string(v->size()) + " entries but the rig has " +
                   std::to_string(count) + " " + std::string(devices));
      return nullptr;
    }
    return v;
  }

  // The required `key` naming the rig's device `index` (`expected`), listed in the rig's order.
  std::string rigId(const Json& obj, const std::string& path, std::string_view key,
                    const std::string& expected, std::size_t index, std::string_view device) {
    auto id = text(obj, path, key, "the rig's " + std::string(device) + " id").value_or("");
    if (ok() && id != expected) {
      fail(member(path, key), jsonQuote(id) + " is not the rig's " + std::string(device) + " " +
                                  std::to_string(index) + " (" + jsonQuote(expected) +
                                  "); list them in the rig's order");
    }
    return id;
  }
};

hal::PixelFormat pixelFormat(std::string_view name) {
  if (name == "BGR24") {
    return hal::PixelFormat::kBgr24;
  }
  return name == "YUYV" ? hal::PixelFormat::kYuyv : hal::PixelFormat::kRgb24;
}

void readCameras(Reader& r, const Json& doc, const algo::Rig& rig, hal::BoardConfig& board) {
  const Json* cameras = r.perDevice(doc, "", "cameras", rig.cameras.size(), "cameras");
  if (cameras == nullptr) {
    return;
  }
  for (std::size_t i = 0; i < cameras->size() && r.ok(); ++i) {
    const std::string at = element("cameras", i);
    const Json& v = (*cameras)[i];
    if (!r.object(v, at, "a camera", kCameraKeys)) {
      return;
    }
    hal::CameraConfig camera;
    camera.id = r.rigId(v, at, "id", rig.cameras[i].id, i, "camera");
    camera.device = r.text(v, at, "device", R"(e.g. "/dev/video0" or "sim")").value_or("");
    camera.format.pixelFormat =
        pixelFormat(r.word(v, at, "pixel_format", kPixelFormats).value_or(""));
    camera.format.width = rig.cameras[i].width;
    camera.format.height = rig.cameras[i].height;
    r.integer(v, at, "fps", 1, 240, "frames per second", camera.format.fps);
    r.integer(v, at, "buffers", 2, 32, "streaming buffers", camera.buffers);
    board.cameras.push_back(std::move(camera));
  }
}

void readTriggers(Reader& r, const Json& doc, const algo::Rig& rig, hal::BoardConfig& board) {
  const Json* triggers = r.find(doc, "triggers");
  if (!r.ok()) {
    return;
  }
  if (triggers == nullptr) {
    r.fail("triggers", "required field is missing; one trigger line per projector of the rig");
    return;
  }
  if (!r.object(*triggers, "triggers", "trigger lines", kTriggerKeys)) {
    return;
  }
  int leadUs = 0;
  r.integer(*triggers, "triggers", "lead_us", 0, 100'000, "microseconds", leadUs);
  board.trigger.leadNs = std::int64_t{leadUs} * 1000;
  const Json* lines =
      r.perDevice(*triggers, "triggers", "lines", rig.projectors.size(), "projectors");
  if (lines == nullptr) {
    return;
  }
  for (std::size_t i = 0; i < lines->size() && r.ok(); ++i) {
    const std::string at = element("triggers.lines", i);
    const Json& v = (*lines)[i];
    if (!r.object(v, at, "a trigger line", kLineKeys)) {
      return;
    }
    hal::TriggerLineConfig line;
    line.role = r.rigId(v, at, "role", rig.projectors[i].id, i, "projector");
    line.chip = r.text(v, at, "chip", "the GPIO chip, e.g. \"gpiochip0\"").value_or("");
    int offset = -1;
    r.integer(v, at, "line", 0, 511, "the line offset on the chip", offset);
    if (r.ok() && offset < 0) {
      r.fail(member(at, "line"), "required field is missing; the line offset on the chip");
    }
    line.offset = static_cast<unsigned>(offset < 0 ? 0 : offset);
    r.boolean(v, at, "active_low", line.activeLow);
    for (const auto& other : board.trigger.lines) {
      if (r.ok() && other.chip == line.chip && other.offset == line.offset) {
        r.fail(member(at, "line"), "line " + std::to_string(line.offset) + " of " + line.chip +
                                       " is already the line of " + jsonQuote(other.role));
      }
    }
    board.trigger.lines.push_back(std::move(line));
  }
}

// A GPIO line of the turntable: required (`required`) or optional, on no trigger line of its chip.
std::optional<unsigned> turntableLine(Reader& r, const Json& table, std::string_view key,
                                      bool required, const hal::BoardConfig& board,
                                      const std::string& chip) {
  const std::string at = member("turntable", key);
  int offset = -1;
  r.integer(table, "turntable", key, 0, 511, "the line offset on the chip", offset);
  if (r.ok() && offset < 0) {
    if (required) {
      r.fail(at, "required field is missing; the line offset on the chip");
    }
    return std::nullopt;
  }
  const auto line = static_cast<unsigned>(offset);
  for (const auto& trigger : board.trigger.lines) {
    if (r.ok() && trigger.chip == chip && trigger.offset == line) {
      r.fail(at, "line " + std::to_string(line) + " of " + trigger.chip +
                     " is already the trigger line of " + jsonQuote(trigger.role));
    }
  }
  return r.ok() ? std::optional<unsigned>(line) : std::nullopt;
}

void readTurntable(Reader& r, const Json& doc, hal::BoardConfig& board) {
  const Json* table = r.find(doc, "turntable");
  if (table == nullptr ||
      !r.object(*table, "turntable", "the stepper turntable's lines and motion", kTurntableKeys)) {
    return;
  }
  hal::TurntableConfig& t = board.turntable.emplace();
  t.chip = r.text(*table, "turntable", "chip", "the GPIO chip, e.g. \"gpiochip0\"").value_or("");
  t.stepLine = turntableLine(r, *table, "step", true, board, t.chip).value_or(0);
  t.dirLine = turntableLine(r, *table, "dir", true, board, t.chip).value_or(0);
  t.enableLine = turntableLine(r, *table, "enable", false, board, t.chip);
  if (r.ok() && t.dirLine == t.stepLine) {
    r.fail("turntable.dir", "line " + std::to_string(t.dirLine) + " is already the STEP line");
  }
  if (r.ok() && t.enableLine && (*t.enableLine == t.stepLine || *t.enableLine == t.dirLine)) {
    r.fail("turntable.enable", "line " + std::to_string(*t.enableLine) + " is already the " +
                                   (*t.enableLine == t.stepLine ? "STEP" : "DIR") + " line");
  }
  r.boolean(*table, "turntable", "enable_active_low", t.enableActiveLow);
  int stepsPerTurn = 0;
  r.integer(*table, "turntable", "steps_per_turn", 1, 1'000'000, "steps of one full turn",
            stepsPerTurn);
  if (r.ok() && stepsPerTurn == 0) {
    r.fail("turntable.steps_per_turn", "required field is missing; steps of one full turn");
  }
  t.stepsPerTurn = stepsPerTurn;
  r.number(*table, "turntable", "speed_deg_s", Range::kPositive, t.speedDegS);
  if (r.ok() && (t.speedDegS < 1.0 || t.speedDegS > 360.0)) {
    r.fail("turntable.speed_deg_s",
           "must be from 1 to 360 degrees per second, got " + formatNumber(t.speedDegS));
  }
  r.integer(*table, "turntable", "settle_ms", 0, 10'000, "milliseconds", t.settleMs);
}

void readNetwork(Reader& r, const Json& doc, hal::BoardConfig& board) {
  const Json* network = r.find(doc, "network");
  if (network == nullptr || !r.object(*network, "network", "the network", kNetworkKeys)) {
    return;
  }
  if (r.find(*network, "bind") != nullptr) {
    board.network.bindAddress = r.text(*network, "network", "bind", "").value_or("");
    in_addr parsed{};
    if (r.ok() && ::inet_pton(AF_INET, board.network.bindAddress.c_str(), &parsed) != 1) {
      r.fail("network.bind", jsonQuote(board.network.bindAddress) +
                                 " is not an IPv4 address (\"0.0.0.0\": every interface)");
    }
  }
  int port = board.network.port;
  r.integer(*network, "network", "port", 0, 65535, "TCP port; 0: any free one", port);
  board.network.port = static_cast<std::uint16_t>(port);
  int sendBufferKib = 0;
  r.integer(*network, "network", "send_buffer_kib", 0, 65536, "KiB; 0: the system's default",
            sendBufferKib);
  board.network.sendBufferBytes = sendBufferKib * 1024;
}

void readSim(Reader& r, const Json& doc, const fs::path& dir, hal::BoardConfig& board) {
  const Json* sim = r.find(doc, "sim");
  if (!r.ok()) {
    return;
  }
  if (board.backend != "sim") {
    if (sim != nullptr) {
      r.fail("sim", R"(only a board with "hal": "sim" has a sim section)");
    }
    return;
  }
  if (sim == nullptr) {
    r.fail("sim",
           "required field is missing; the simulated board needs a scene or a replay "
           "folder");
    return;
  }
  if (!r.object(*sim, "sim", "what the simulated cameras see", kSimKeys)) {
    return;
  }
  if (r.find(*sim, "scene") != nullptr) {
    board.sim.scene = r.text(*sim, "sim", "scene", "").value_or("");
  }
  if (r.find(*sim, "replay") != nullptr) {
    board.sim.replayDir = dir / r.text(*sim, "sim", "replay", "").value_or("");
  }
  if (r.ok() && board.sim.scene.empty() == board.sim.replayDir.empty()) {
    r.fail("sim",
           "give exactly one of \"scene\" (render live) and \"replay\" (a folder of "
           "frames)");
  }
  double seed = 1;
  r.number(*sim, "sim", "seed", Range::kNonNegative, seed);
  board.sim.seed = static_cast<std::uint64_t>(seed);
}

std::expected<Board, BoardError> parseBoardImpl(std::string_view text, const fs::path& dir) {
  auto parsed = parseDocument(text, kBoardDocument);
  if (!parsed) {
    return std::unexpected(BoardError{{}, parsed.error().field, parsed.error().problem});
  }
  const Json& doc = *parsed;
  Reader r;
  Board out;
  hal::BoardConfig& board = out.config;
  board.directory = dir;
  board.name = r.text(doc, "", "name", "the board's name, e.g. \"rpi4\"").value_or("");
  // The name goes on the wire to every host and onto their terminals: an id, not free text.
  if (auto problem = r.ok() ? identifierProblem(board.name) : std::nullopt) {
    r.fail("name", std::move(*problem));
  }
  board.backend = r.word(doc, "", "hal", kHals).value_or("");
  const auto rigFile = r.text(doc, "", "rig", "the rig.json file, relative to the board folder");
  if (rigFile) {
    board.rigPath = dir / *rigFile;
    auto rig = loadRig(board.rigPath);
    if (!rig) {
      r.fail("rig", "cannot use the rig: " + rig.error().message());
    } else {
      out.rig = std::move(*rig);
    }
    // The device streams every camera at the size its capabilities announce.
    for (const auto& camera : out.rig.cameras) {
      const auto& first = out.rig.cameras.front();
      if (r.ok() && (camera.width != first.width || camera.height != first.height)) {
        r.fail("rig", "the cameras of a board share one image size; " + camera.id + " is " +
                          std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                          ", " + first.id + " " + std::to_string(first.width) + "x" +
                          std::to_string(first.height));
      }
    }
  }
  r.number(doc, "", "depth_unit_m", Range::kPositive, board.depthUnitM);
  if (r.ok() && (board.depthUnitM < 1e-6 || board.depthUnitM > 1e-2)) {
    r.fail("depth_unit_m",
           "must be from 1e-06 (1 um) to 0.01 (1 cm), got " + formatNumber(board.depthUnitM));
  }
  if (r.ok() && board.depthUnitM < algo::minDepthUnitM(algo::kDefaultNominalDepthM)) {
    r.fail("depth_unit_m", formatNumber(board.depthUnitM) + " m per unit stores depths up to " +
                               formatNumber(algo::maxStoredDepthM(board.depthUnitM)) +
                               " m in 16 bits; the board decodes for " +
                               formatNumber(algo::kDefaultNominalDepthM) +
                               " m, and every depth beyond the limit would be lost; use at least " +
                               formatNumber(algo::minDepthUnitM(algo::kDefaultNominalDepthM)));
  }
  r.integer(doc, "", "threads", 1, 64, "decoding threads (the board's cores)", board.threads);
  r.boolean(doc, "", "pipelined", board.pipelined);
  if (r.ok()) {
    readCameras(r, doc, out.rig, board);
    readTriggers(r, doc, out.rig, board);
    readTurntable(r, doc, board);
    readNetwork(r, doc, board);
    readSim(r, doc, dir, board);
  }
  if (!r.ok()) {
    const auto e = r.firstError().value_or(FieldError{});
    return std::unexpected(BoardError{{}, e.field, e.problem});
  }
  return out;
}

}  // namespace

std::string BoardError::message() const {
  return errorMessage(file, field, problem);
}

std::expected<Board, BoardError> parseBoard(std::string_view text, const fs::path& dir) {
  try {
    return parseBoardImpl(text, dir);
  } catch (const std::exception& e) {
    return std::unexpected(BoardError{{}, {}, std::string("cannot read the board: ") + e.what()});
  }
}

std::expected<Board, BoardError> loadBoard(const fs::path& path) {
  std::error_code ec;
  const fs::path file = fs::is_directory(path, ec) ? path / "board.json" : path;
  return loadDocument(file, kBoardDocument, [&](const std::string& text) {
    return parseBoard(text, file.parent_path());
  });
}

}  // namespace smx::config
