#include "smx/config/json_errors.hpp"

#include <algorithm>
#include <initializer_list>
#include <string>
#include <string_view>

namespace smx::config {
namespace {

// "[json.exception.out_of_range.406] number overflow parsing '1e999'" -> "1e999"
std::string overflowedLiteral(std::string_view what) {
  const auto open = what.find('\'');
  const auto close = what.rfind('\'');
  if (open == std::string_view::npos || close <= open) {
    return "the number";
  }
  return std::string(what.substr(open + 1, close - open - 1));
}

}  // namespace

std::string errorMessage(std::string_view file, std::string_view field, std::string_view problem) {
  std::string out;
  for (const auto part : {file, field, problem}) {
    if (!part.empty()) {
      out += (out.empty() ? "" : ": ") + std::string(part);
    }
  }
  return out;
}

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

std::string overflowProblem(std::string_view what) {
  return "must be a finite number; " + overflowedLiteral(what) + " is too large for a double";
}

}  // namespace smx::config
