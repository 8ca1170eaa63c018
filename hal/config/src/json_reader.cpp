#include "smx/config/json_reader.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstddef>
#include <exception>
#include <expected>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "parse_tracker.hpp"
#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"
#include "smx/config/json_text.hpp"

namespace smx::config {
namespace {

using Json = nlohmann::json;

std::unexpected<FieldError> fail(std::string field, std::string problem) {
  return std::unexpected(FieldError{std::move(field), std::move(problem)});
}

std::optional<FieldError> formatProblem(const Json& doc, const DocumentSpec& spec) {
  const std::string supported = "supported: " + jsonQuote(spec.format);
  const auto it = doc.find("format");
  if (it == doc.end()) {
    return FieldError{"format", "required field is missing; a " + std::string(spec.name) +
                                    " starts with \"format\": " + jsonQuote(spec.format)};
  }
  if (!it->is_string()) {
    return FieldError{
        "format", "must be a string such as " + jsonQuote(spec.format) + ", got " + describe(*it)};
  }
  const auto& format = it->get_ref<const std::string&>();
  if (format == spec.format) {
    return std::nullopt;
  }
  const std::string_view family = spec.format.substr(0, spec.format.rfind('/') + 1);
  if (format.starts_with(family)) {
    return FieldError{"format", "unsupported version " + jsonQuote(format) + "; " + supported};
  }
  std::string_view note;
  for (const auto& other : spec.otherFormats) {
    if (format.starts_with(other.prefix)) {
      note = other.note;
      break;
    }
  }
  return FieldError{"format",
                    "unknown format " + jsonQuote(format) + std::string(note) + "; " + supported};
}

}  // namespace

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

std::expected<Json, FieldError> parseDocument(std::string_view text, const DocumentSpec& spec) {
  const std::string name(spec.name);
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    return fail(
        "", "not valid JSON: the text is empty; a " + name + " is a JSON object {\"format\": ...}");
  }
  if (text.size() > spec.maxBytes) {
    return fail("", "the text is " + std::to_string(text.size()) + " bytes; a " + name +
                        " is at most " + std::to_string(spec.maxBytes) + " bytes" +
                        std::string(spec.sizeNote));
  }
  if (const auto depth = nestingDepth(text); depth > spec.maxNesting) {
    return fail("", "nested " + std::to_string(depth) + " levels deep; a " + name + " needs " +
                        std::to_string(spec.nestingNeeded) + " and at most " +
                        std::to_string(spec.maxNesting) + " are accepted");
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
      return fail(tracker.currentPath(), overflowProblem(e.what()));
    }
    throw;
  }
  if (!doc.is_object()) {
    return fail("", "the top level must be a JSON object {\"format\": ...}, got " + describe(doc));
  }
  if (auto format = formatProblem(doc, spec)) {
    return std::unexpected(std::move(*format));
  }
  if (const auto& duplicate = tracker.duplicate(); duplicate.has_value()) {
    return std::unexpected(*duplicate);
  }
  if (const auto key = unknownKey(doc, spec.topKeys)) {
    return fail("", unknownKeyProblem(*key, spec.topKeys));
  }
  return doc;
}

std::expected<std::string, FieldError> readDocumentFile(const std::filesystem::path& file,
                                                        const DocumentSpec& spec) {
  try {
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (ec || !std::filesystem::exists(status)) {
      return fail({}, "cannot read the file: " + (ec ? ec.message() : std::string("no such file")));
    }
    if (std::filesystem::is_directory(status)) {
      return fail({}, "cannot read the file: it is a directory");
    }
    // A FIFO or socket would block the reader until something writes to it, maybe forever.
    if (!std::filesystem::is_regular_file(status)) {
      return fail({}, "cannot read the file: it is not a regular file (a pipe, socket or device)");
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      return fail(
          {}, "cannot read the file: " + std::generic_category().message(errno != 0 ? errno : EIO));
    }
    std::string text;
    std::array<char, 4096> chunk{};
    while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0) {
      text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
      if (text.size() > spec.maxBytes) {
        return fail({}, "file is larger than " + std::to_string(spec.maxBytes) + " bytes; a " +
                            std::string(spec.name) + " is a few kB");
      }
    }
    if (in.bad()) {
      return fail({}, "cannot read the file: read error");
    }
    return text;
  } catch (const std::exception& e) {
    return fail({}, std::string("cannot read the file: ") + e.what());
  }
}

}  // namespace smx::config
