#pragma once

#include <string>
#include <string_view>

// Why a key, signature or bundle was refused (docs/update.md#errors). The message names the
// file, the field and the sizes involved.
namespace smx::update {

enum class UpdateReason {
  kTruncated,     // shorter than its header or trailer says
  kMalformed,     // not the format: magic, sizes, text, JSON, a field out of range
  kTooLarge,      // a limit (manifest, file count, total size) exceeded
  kBadSignature,  // signed by a trusted key, but the signature does not match the bytes
  kUnknownKey,    // signed by a key that is not trusted
  kBadName,       // a file name in the manifest is not a plain relative name
  kBadHash,       // a file's bytes do not match the manifest's hash
  kWrongBoard,    // the bundle does not list this board
  kDowngrade,     // older than the installed version and not allowed to downgrade
  kExists,        // the output exists already
  kIo,            // a system call failed
};

struct UpdateError {
  UpdateReason reason;
  std::string message;
};

[[nodiscard]] std::string_view reasonName(UpdateReason reason);

}  // namespace smx::update
