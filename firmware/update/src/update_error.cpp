#include "smx/update/update_error.hpp"

namespace smx::update {

std::string_view reasonName(UpdateReason reason) {
  switch (reason) {
    case UpdateReason::kTruncated:
      return "truncated";
    case UpdateReason::kMalformed:
      return "malformed";
    case UpdateReason::kTooLarge:
      return "too large";
    case UpdateReason::kBadSignature:
      return "bad signature";
    case UpdateReason::kUnknownKey:
      return "unknown key";
    case UpdateReason::kBadName:
      return "bad file name";
    case UpdateReason::kBadHash:
      return "bad hash";
    case UpdateReason::kWrongBoard:
      return "wrong board";
    case UpdateReason::kDowngrade:
      return "downgrade";
    case UpdateReason::kExists:
      return "exists";
    case UpdateReason::kIo:
      return "I/O error";
  }
  return "unknown";
}

}  // namespace smx::update
