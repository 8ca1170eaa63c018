#pragma once

#include <string>
#include <string_view>

// What a configuration reader reports, and the wording of the failures nlohmann reports as
// exceptions (syntax errors, numbers too large for a double), turned into messages for end users.
namespace smx::config {

// One problem in a document. Each reader wraps it in its own error type (RigError, SceneError),
// which adds the file.
struct FieldError {
  std::string field;    // JSON path, e.g. "cameras[0].K[4]"; empty = the document as a whole
  std::string problem;  // what is wrong, e.g. "must be a number, got a string ("800")"
};

// "file: field: problem", leaving out the empty parts: what RigError::message() and
// SceneError::message() print.
[[nodiscard]] std::string errorMessage(std::string_view file, std::string_view field,
                                       std::string_view problem);

// "not valid JSON: line 2, column 5: syntax error ..." from the what() of a
// nlohmann::json::parse_error; bytes that are not printable ASCII become '?'.
[[nodiscard]] std::string parseErrorProblem(std::string_view what);

// "must be a finite number; 1e999 is too large for a double" from the what() of nlohmann's
// "number overflow" (out_of_range.406).
[[nodiscard]] std::string overflowProblem(std::string_view what);

}  // namespace smx::config
