#pragma once

#include <cstddef>
#include <exception>
#include <expected>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "smx/config/json_errors.hpp"
#include "smx/config/json_keys.hpp"

// The checks every configuration reader makes before its own: reading the file, size and nesting
// bounds, JSON syntax, the "format" version, duplicate keys and the top-level keys. A reader
// describes its document in a DocumentSpec and reads its own fields from the parsed document.
namespace smx::config {

// A format this document is often confused with, and what to say when it is given instead.
struct FormatHint {
  std::string_view prefix;  // the other format's "format" value up to its version, e.g.
                            // "stripemux-rig/"
  std::string_view note;    // e.g. " (this is a rig.json, not a scene)"
};

// One kind of configuration document (rig.json, scene.json, ...).
struct DocumentSpec {
  std::string_view name;    // as messages call it: "rig.json"
  std::string_view format;  // the "format" value this build reads, e.g. "stripemux-rig/1"; the
                            // text up to its last '/' names the format in any version
  Keys topKeys;             // the keys allowed at the top level
  // Bounds that keep a hostile or mistaken input (a video file, /dev/zero, "[[[[...") from
  // costing more than a few MB.
  std::size_t maxBytes = 0;
  std::string_view sizeNote;      // added to the too-large message, e.g. " (meshes go elsewhere)"
  std::size_t nestingNeeded = 0;  // how deep a real document nests, for the too-deep message
  std::size_t maxNesting = 0;
  std::span<const FormatHint> otherFormats;  // recognised in an unknown "format"
};

// Deepest [ / { nesting outside strings; checked before nlohmann builds anything.
[[nodiscard]] std::size_t nestingDepth(std::string_view text);

// Parses `text` as a `spec` document and makes the common checks, in this order: not empty, size,
// nesting, JSON syntax (and numbers too large for a double, by path), a top-level object, the
// "format" value, duplicate keys, unknown top-level keys. Returns the document for the reader's
// own fields, or the first problem. Throws only what nlohmann or the allocator throw beyond that
// (out of memory); readers that promise not to throw catch std::exception around it.
[[nodiscard]] std::expected<nlohmann::json, FieldError> parseDocument(std::string_view text,
                                                                      const DocumentSpec& spec);

// The whole of `file` as text, or why not ("cannot read the file: No such file or directory",
// "... it is a directory", "file is larger than ..."). The error has no field; the caller names
// the file. An exception while reading (out of memory) is reported as "cannot read the file: ...".
[[nodiscard]] std::expected<std::string, FieldError> readDocumentFile(
    const std::filesystem::path& file, const DocumentSpec& spec);

// Reads `file` and parses its text with `parse`, which returns std::expected<T, Error> for a
// reader's error aggregate {file, field, problem} (RigError, SceneError). Every error names
// `file`; an exception (out of memory) becomes "cannot read the file: ...", so none leaves.
template <class Parse>
auto loadDocument(const std::filesystem::path& file, const DocumentSpec& spec, Parse parse)
    -> std::invoke_result_t<Parse&, const std::string&> {
  using Error = typename std::invoke_result_t<Parse&, const std::string&>::error_type;
  const auto withFile = [&](Error e) {
    e.file = file.string();
    return std::unexpected(std::move(e));
  };
  try {
    auto text = readDocumentFile(file, spec);
    if (!text) {
      return withFile(Error{{}, std::move(text.error().field), std::move(text.error().problem)});
    }
    auto parsed = parse(*text);
    if (!parsed) {
      return withFile(std::move(parsed.error()));
    }
    return parsed;
  } catch (const std::exception& e) {
    return withFile(Error{{}, {}, std::string("cannot read the file: ") + e.what()});
  }
}

}  // namespace smx::config
