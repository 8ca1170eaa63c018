#include "manifest.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>

namespace smx::update {
namespace {

using Json = nlohmann::json;

constexpr std::size_t kMaxBoards = 64;
constexpr std::size_t kMaxBoardName = 64;
constexpr std::size_t kMaxComponent = 255;
constexpr std::size_t kMaxName = 1024;
constexpr std::size_t kHashHexSize = 64;  // BLAKE2b-256

std::unexpected<UpdateError> bad(const std::string& field, const std::string& what,
                                 UpdateReason reason = UpdateReason::kMalformed) {
  return std::unexpected(UpdateError{reason, "manifest: " + field + ": " + what});
}

bool nameChar(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
         c == '_' || c == '-';
}

bool onlyKeys(const Json& object, std::initializer_list<std::string_view> keys,
              std::string& unknown) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      unknown = key;
      return false;
    }
  }
  return true;
}

std::expected<void, UpdateError> checkKeys(const Json& object, const std::string& where,
                                           std::initializer_list<std::string_view> keys) {
  if (!object.is_object()) {
    return bad(where, "not an object");
  }
  std::string unknown;
  if (!onlyKeys(object, keys, unknown)) {
    return bad(where + "." + unknown, "unknown key");
  }
  for (const auto key : keys) {
    if (!object.contains(key)) {
      return bad(where + "." + std::string(key), "missing");
    }
  }
  return {};
}

std::expected<BundleFile, UpdateError> parseFile(const Json& entry, const std::string& where) {
  if (auto keys = checkKeys(entry, where, {"name", "size", "mode", "blake2b"}); !keys) {
    return std::unexpected(keys.error());
  }
  BundleFile file;
  const Json& name = entry["name"];
  if (!name.is_string()) {
    return bad(where + ".name", "not a string");
  }
  file.name = name.get<std::string>();
  if (const auto problem = nameProblem(file.name)) {
    return bad(where + ".name", "\"" + file.name + "\" " + *problem, UpdateReason::kBadName);
  }
  const Json& size = entry["size"];
  if (!size.is_number_unsigned() || size.get<std::uint64_t>() > kMaxPayloadSize) {
    return bad(where + ".size", "not a size in 0.." + std::to_string(kMaxPayloadSize));
  }
  file.size = size.get<std::uint64_t>();
  const Json& mode = entry["mode"];
  if (!mode.is_string() || (mode != "0644" && mode != "0755")) {
    return bad(where + ".mode", R"(not "0644" or "0755")");
  }
  file.mode = mode == "0755" ? 0755 : 0644;
  const Json& hash = entry["blake2b"];
  if (!hash.is_string() || hash.get_ref<const std::string&>().size() != kHashHexSize ||
      !std::all_of(hash.get_ref<const std::string&>().begin(),
                   hash.get_ref<const std::string&>().end(),
                   [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); })) {
    return bad(where + ".blake2b", "not 64 lower-case hex digits (BLAKE2b-256)");
  }
  file.blake2bHex = hash.get<std::string>();
  return file;
}

// No name may also be a directory of another ("bin" and "bin/stripemuxd"), nor appear twice.
std::expected<void, UpdateError> checkNamesDistinct(const std::vector<BundleFile>& files) {
  std::set<std::string_view> names;
  for (const auto& f : files) {
    if (!names.insert(f.name).second) {
      return bad("files", "\"" + f.name + "\" appears twice", UpdateReason::kBadName);
    }
  }
  for (const auto& f : files) {
    const std::string_view name = f.name;
    for (auto slash = name.find('/'); slash != std::string_view::npos;
         slash = name.find('/', slash + 1)) {
      if (names.contains(name.substr(0, slash))) {
        return bad("files", "\"" + f.name.substr(0, slash) + "\" is a file and a directory",
                   UpdateReason::kBadName);
      }
    }
  }
  return {};
}

}  // namespace

std::optional<std::string> nameProblem(std::string_view name) {
  if (name.empty() || name.size() > kMaxName) {
    return "is empty or longer than " + std::to_string(kMaxName);
  }
  std::size_t start = 0;
  while (true) {
    const auto end = name.find('/', start);
    const auto part = name.substr(start, end == std::string_view::npos ? end : end - start);
    if (part.empty()) {
      return std::string("has an empty component (a leading, trailing or double '/')");
    }
    if (part == "." || part == "..") {
      return std::string("has a '.' or '..' component");
    }
    if (part.size() > kMaxComponent || !std::all_of(part.begin(), part.end(), nameChar)) {
      return std::string("has a component that is not 1..255 of [A-Za-z0-9._-]");
    }
    if (end == std::string_view::npos) {
      return std::nullopt;
    }
    start = end + 1;
  }
}

std::expected<Manifest, UpdateError> parseManifest(std::string_view text) {
  const Json json = Json::parse(text, nullptr, false);
  if (json.is_discarded()) {
    return bad("(text)", "not JSON");
  }
  if (auto keys =
          checkKeys(json, "(top)", {"format", "version", "boards", "allow_downgrade", "files"});
      !keys) {
    return std::unexpected(keys.error());
  }
  if (json["format"] != kBundleFormat) {
    return bad("format", "not \"" + std::string(kBundleFormat) + "\"");
  }
  Manifest manifest;
  if (!json["version"].is_string()) {
    return bad("version", "not a string");
  }
  const auto version = parseVersion(json["version"].get<std::string>(), "manifest: version");
  if (!version) {
    return std::unexpected(version.error());
  }
  manifest.version = *version;
  const Json& boards = json["boards"];
  if (!boards.is_array() || boards.empty() || boards.size() > kMaxBoards) {
    return bad("boards", "not an array of 1.." + std::to_string(kMaxBoards) + " names");
  }
  for (std::size_t i = 0; i < boards.size(); ++i) {
    const Json& b = boards[i];
    const auto where = "boards[" + std::to_string(i) + "]";
    if (!b.is_string() || b.get_ref<const std::string&>().empty() ||
        b.get_ref<const std::string&>().size() > kMaxBoardName ||
        !std::all_of(b.get_ref<const std::string&>().begin(), b.get_ref<const std::string&>().end(),
                     nameChar)) {
      return bad(where, "not a board name (1..64 of [A-Za-z0-9._-])");
    }
    manifest.boards.push_back(b.get<std::string>());
  }
  if (!json["allow_downgrade"].is_boolean()) {
    return bad("allow_downgrade", "not true or false");
  }
  manifest.allowDowngrade = json["allow_downgrade"].get<bool>();
  const Json& files = json["files"];
  if (!files.is_array() || files.size() > kMaxFiles) {
    return bad("files", "not an array of at most " + std::to_string(kMaxFiles) + " files",
               UpdateReason::kTooLarge);
  }
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    auto file = parseFile(files[i], "files[" + std::to_string(i) + "]");
    if (!file) {
      return std::unexpected(file.error());
    }
    file->offset = offset;
    offset += file->size;
    if (offset > kMaxPayloadSize) {
      return bad("files", "more than " + std::to_string(kMaxPayloadSize) + " bytes in all",
                 UpdateReason::kTooLarge);
    }
    manifest.files.push_back(std::move(*file));
  }
  if (auto distinct = checkNamesDistinct(manifest.files); !distinct) {
    return std::unexpected(distinct.error());
  }
  return manifest;
}

std::string manifestJson(const Manifest& manifest) {
  nlohmann::ordered_json files = nlohmann::ordered_json::array();
  for (const auto& f : manifest.files) {
    files.push_back({{"name", f.name},
                     {"size", f.size},
                     {"mode", f.mode == 0755 ? "0755" : "0644"},
                     {"blake2b", f.blake2bHex}});
  }
  const nlohmann::ordered_json json = {{"format", kBundleFormat},
                                       {"version", toString(manifest.version)},
                                       {"boards", manifest.boards},
                                       {"allow_downgrade", manifest.allowDowngrade},
                                       {"files", files}};
  return json.dump(1);
}

}  // namespace smx::update
