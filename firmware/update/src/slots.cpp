#include "smx/update/slots.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <nlohmann/json.hpp>
#include <system_error>

#include "smx/update/version.hpp"

namespace smx::update {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr std::size_t kMaxRecordSize = std::size_t{64} * 1024;

std::unexpected<UpdateError> malformed(const std::string& where, const std::string& what) {
  return std::unexpected(UpdateError{UpdateReason::kMalformed, where + ": " + what});
}

std::unexpected<UpdateError> ioFail(const fs::path& path, const char* what) {
  return std::unexpected(
      UpdateError{UpdateReason::kIo,
                  path.string() + ": " + what + ": " + std::generic_category().message(errno)});
}

std::expected<Json, UpdateError> readJson(const fs::path& file) {
  auto bytes = readFile(file, kMaxRecordSize);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  const std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
  Json json = Json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object()) {
    return malformed(file.string(), "not a JSON object");
  }
  return json;
}

std::expected<std::string, UpdateError> slotField(const Json& json, const char* key) {
  const auto it = json.find(key);
  if (it == json.end() || !it->is_string()) {
    return malformed(std::string("boot.json: ") + key, "must be a string");
  }
  const auto value = it->get<std::string>();
  if (!value.empty() && !isSlotId(value)) {
    return malformed(std::string("boot.json: ") + key, R"(must be "", "a" or "b")");
  }
  return value;
}

std::expected<std::string, UpdateError> textField(const Json& json, const char* key) {
  const auto it = json.find(key);
  if (it == json.end() || !it->is_string() || it->get_ref<const std::string&>().size() > 1024) {
    return malformed(std::string("boot.json: ") + key, "must be a string of at most 1024 bytes");
  }
  return it->get<std::string>();
}

}  // namespace

const char* toString(UpdateOutcome outcome) {
  switch (outcome) {
    case UpdateOutcome::kInstalled:
      return "installed";
    case UpdateOutcome::kRolledBack:
      return "rolled back";
    case UpdateOutcome::kNone:
      break;
  }
  return "none";
}

bool isSlotId(std::string_view id) {
  return std::ranges::any_of(kSlotIds, [&](const char* slot) { return id == slot; });
}

std::string inactiveSlot(const std::optional<std::string>& active) {
  return active == std::string(kSlotIds[0]) ? kSlotIds[1] : kSlotIds[0];
}

std::string bootRecordJson(const BootRecord& record) {
  const Json json = {{"format", "stripemux-boot/1"},     {"previous", record.previous},
                     {"pending", record.pending},        {"tries", record.tries},
                     {"marked_good", record.markedGood}, {"outcome", toString(record.outcome)},
                     {"reason", record.reason},          {"version", record.version}};
  return json.dump(2) + "\n";
}

std::expected<BootRecord, UpdateError> parseBootRecord(std::string_view text) {
  const Json json = Json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object()) {
    return malformed("boot.json", "not a JSON object");
  }
  if (json.value("format", "") != "stripemux-boot/1") {
    return malformed("boot.json: format", R"(must be "stripemux-boot/1")");
  }
  BootRecord record;
  auto previous = slotField(json, "previous");
  auto pending = slotField(json, "pending");
  auto reason = textField(json, "reason");
  auto version = textField(json, "version");
  auto outcome = textField(json, "outcome");
  for (const auto* field : {&previous, &pending, &reason, &version, &outcome}) {
    if (!*field) {
      return std::unexpected(field->error());
    }
  }
  const auto tries = json.find("tries");
  if (tries == json.end() || !tries->is_number_unsigned() || tries->get<std::uint64_t>() > 100) {
    return malformed("boot.json: tries", "must be an integer from 0 to 100");
  }
  const auto good = json.find("marked_good");
  if (good == json.end() || !good->is_boolean()) {
    return malformed("boot.json: marked_good", "must be true or false");
  }
  record.previous = *previous;
  record.pending = *pending;
  record.reason = *reason;
  record.version = *version;
  record.tries = static_cast<int>(tries->get<std::uint64_t>());
  record.markedGood = good->get<bool>();
  if (*outcome == "installed") {
    record.outcome = UpdateOutcome::kInstalled;
  } else if (*outcome == "rolled back") {
    record.outcome = UpdateOutcome::kRolledBack;
  } else if (*outcome != "none") {
    return malformed("boot.json: outcome", R"(must be "none", "installed" or "rolled back")");
  }
  return record;
}

std::expected<BootRecord, UpdateError> readBootRecord(const fs::path& dir) {
  const fs::path file = dir / "boot.json";
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(file, ec))) {
    return BootRecord{};
  }
  auto bytes = readFile(file, kMaxRecordSize);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  return parseBootRecord(
      std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
}

std::expected<void, UpdateError> writeBootRecord(const fs::path& dir, const BootRecord& record,
                                                 const StepHook& onStep) {
  return writeFileAtomic(dir / "boot.json", asBytes(bootRecordJson(record)), 0644, Replace::kAllow,
                         onStep);
}

std::expected<std::optional<std::string>, UpdateError> activeSlot(const fs::path& dir) {
  const fs::path link = dir / "active";
  std::error_code ec;
  const fs::path target = fs::read_symlink(link, ec);
  if (ec) {
    if (!fs::exists(fs::symlink_status(link, ec))) {
      return std::optional<std::string>{};
    }
    return malformed(link.string(), "not a symbolic link");
  }
  const std::string text = target.string();
  const std::string prefix = "slots/";
  if (!text.starts_with(prefix) || !isSlotId(text.substr(prefix.size()))) {
    return malformed(link.string(), "points to " + text + ", not slots/a or slots/b");
  }
  return std::optional<std::string>{text.substr(prefix.size())};
}

std::expected<void, UpdateError> switchActive(const fs::path& dir,
                                              const std::optional<std::string>& id) {
  const fs::path link = dir / "active";
  if (!id) {
    if (::unlink(link.c_str()) != 0 && errno != ENOENT) {
      return ioFail(link, "unlink");
    }
    return syncDirectory(dir);
  }
  if (!isSlotId(*id)) {
    return malformed("slot", "\"" + *id + "\" is not a slot id");
  }
  const fs::path temp = dir / "active.tmp";
  ::unlink(temp.c_str());
  const std::string target = "slots/" + *id;
  if (::symlink(target.c_str(), temp.c_str()) != 0) {
    return ioFail(temp, "symlink");
  }
  if (::rename(temp.c_str(), link.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    errno = error;
    return ioFail(link, "rename");
  }
  return syncDirectory(dir);
}

std::expected<BundleInfo, UpdateError> readSlotManifest(const fs::path& dir,
                                                        const std::string& id) {
  const fs::path file = dir / "slots" / id / kSlotManifest;
  auto json = readJson(file);
  if (!json) {
    return std::unexpected(json.error());
  }
  const auto version = json->find("version");
  const auto boards = json->find("boards");
  if (version == json->end() || !version->is_string()) {
    return malformed(file.string() + ": version", "must be a string");
  }
  auto parsed = parseVersion(version->get<std::string>(), "version");
  if (!parsed) {
    return std::unexpected(parsed.error());
  }
  BundleInfo info;
  info.version = *parsed;
  if (boards == json->end() || !boards->is_array()) {
    return malformed(file.string() + ": boards", "must be an array of strings");
  }
  for (const auto& board : *boards) {
    if (!board.is_string()) {
      return malformed(file.string() + ": boards", "must be an array of strings");
    }
    info.boards.push_back(board.get<std::string>());
  }
  return info;
}

std::expected<void, UpdateError> writeSlot(const fs::path& dir, const std::string& id,
                                           const VerifiedBundle& bundle) {
  if (!isSlotId(id)) {
    return malformed("slot", "\"" + id + "\" is not a slot id");
  }
  const auto& files = bundle.info().files;
  if (std::ranges::any_of(files, [](const BundleFile& f) { return f.name == kSlotManifest; })) {
    return std::unexpected(UpdateError{
        UpdateReason::kBadName, std::string("the bundle holds a file named ") + kSlotManifest +
                                    ", the name the device keeps its manifest under"});
  }
  const fs::path slots = dir / "slots";
  const fs::path slot = slots / id;
  std::error_code ec;
  fs::create_directories(slots, ec);
  fs::remove_all(slot, ec);  // the slot being replaced is neither active nor the fallback
  if (ec) {
    return std::unexpected(UpdateError{UpdateReason::kIo, slot.string() + ": " + ec.message()});
  }
  if (auto synced = syncDirectory(slots); !synced) {
    return synced;
  }
  if (auto extracted = extractBundle(bundle, slot); !extracted) {
    return extracted;
  }
  Json boards = Json::array();
  for (const auto& board : bundle.info().boards) {
    boards.push_back(board);
  }
  Json list = Json::array();
  for (const auto& file : files) {
    list.push_back({{"name", file.name}, {"size", file.size}, {"blake2b", file.blake2bHex}});
  }
  const Json manifest = {{"version", toString(bundle.info().version)},
                         {"boards", boards},
                         {"key_id", keyIdHex(bundle.info().keyId)},
                         {"files", list}};
  return writeFileAtomic(slot / kSlotManifest, asBytes(manifest.dump(2) + "\n"), 0644,
                         Replace::kRefuse);
}

std::expected<std::vector<PublicKey>, UpdateError> readTrustedKeys(const fs::path& dir) {
  std::vector<PublicKey> keys;
  std::error_code ec;
  const fs::path keyDir = dir / "keys";
  if (!fs::is_directory(keyDir, ec)) {
    return keys;
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(keyDir, ec)) {
    if (entry.path().extension() == ".pub") {
      files.push_back(entry.path());
    }
  }
  std::ranges::sort(files);
  for (const auto& file : files) {
    auto key = readPublicKeyFile(file);
    if (!key) {
      return std::unexpected(key.error());
    }
    keys.push_back(*key);
  }
  return keys;
}

}  // namespace smx::update
