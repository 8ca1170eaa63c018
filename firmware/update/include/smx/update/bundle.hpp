#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "smx/update/keys.hpp"
#include "smx/update/update_error.hpp"
#include "smx/update/version.hpp"

// The firmware bundle `stripemux-bundle/1` (docs/update.md#bundle): header, manifest JSON, the
// files' bytes, and a trailer holding a signature over everything before it.
namespace smx::update {

inline constexpr std::string_view kBundleFormat = "stripemux-bundle/1";
inline constexpr std::size_t kHeaderSize = 24;
inline constexpr std::size_t kTrailerSize = 12;
inline constexpr std::size_t kMaxManifestSize = std::size_t{64} * 1024;
inline constexpr std::size_t kMaxFiles = 256;
inline constexpr std::uint64_t kMaxPayloadSize = 256ULL * 1024 * 1024;
inline constexpr std::size_t kMaxSignatureSize = 4096;
inline constexpr std::uint64_t kMaxBundleSize =
    kHeaderSize + kMaxManifestSize + kMaxPayloadSize + kMaxSignatureSize + kTrailerSize;

struct BundleFile {
  std::string name;  // "dir/name", components of [A-Za-z0-9._-]
  std::uint64_t size = 0;
  unsigned mode = 0644;  // 0644 or 0755
  std::string blake2bHex;
  std::uint64_t offset = 0;  // in the payload
};

struct BundleInfo {
  Version version;
  std::vector<std::string> boards;
  bool allowDowngrade = false;
  std::vector<BundleFile> files;
  KeyId keyId{};
};

// What the device checks the bundle against. No board: any board (the host's check of a file);
// no installed version: no downgrade check.
struct Expectations {
  std::optional<std::string> board;
  std::optional<Version> installed;
};

// A bundle whose signature, manifest and file hashes were checked; only verifyBundle makes one.
class VerifiedBundle {
 public:
  [[nodiscard]] const BundleInfo& info() const { return info_; }
  [[nodiscard]] std::span<const std::byte> fileBytes(const BundleFile& file) const;

 private:
  friend std::expected<VerifiedBundle, UpdateError> verifyBundle(std::vector<std::byte> bytes,
                                                                 std::span<const PublicKey> trusted,
                                                                 const Expectations& expect);
  VerifiedBundle(std::vector<std::byte> bytes, BundleInfo info, std::size_t payloadOffset);

  std::vector<std::byte> bytes_;
  BundleInfo info_;
  std::size_t payloadOffset_ = 0;
};

// Order: sizes and trailer, then the signature, only then the manifest, then each file's hash,
// then board and version (docs/update.md#verification).
[[nodiscard]] std::expected<VerifiedBundle, UpdateError> verifyBundle(
    std::vector<std::byte> bytes, std::span<const PublicKey> trusted, const Expectations& expect);
// The file's size is checked against kMaxBundleSize before it is read.
[[nodiscard]] std::expected<VerifiedBundle, UpdateError> verifyBundleFile(
    const std::filesystem::path& path, std::span<const PublicKey> trusted,
    const Expectations& expect);

// The cheap check a sender makes before uploading: the size limits and both magics. Nothing is
// verified.
[[nodiscard]] std::expected<void, UpdateError> checkBundleShape(std::span<const std::byte> bytes);

// Writes every file under slotDir, which must not exist: into slotDir.tmp (a stale one from an
// interrupted extraction is removed first), each file and directory fsynced, then renamed to
// slotDir and its parent fsynced. Nothing outside those two paths is touched.
[[nodiscard]] std::expected<void, UpdateError> extractBundle(const VerifiedBundle& bundle,
                                                             const std::filesystem::path& slotDir);

struct BundleInput {
  std::string name;
  unsigned mode = 0644;
  std::vector<std::byte> bytes;
};

struct BundleSpec {
  Version version;
  std::vector<std::string> boards;
  bool allowDowngrade = false;
  std::vector<BundleInput> files;
};

// The manifest is checked as verifyBundle checks it (names, modes, limits) before signing.
[[nodiscard]] std::expected<std::vector<std::byte>, UpdateError> makeBundle(const SecretKey& key,
                                                                            const BundleSpec& spec);
// The bundle around a given manifest text and payload, unchecked: for tests of hostile
// manifests signed by a trusted key, and for the fuzzer's seeds.
[[nodiscard]] std::vector<std::byte> sealBundle(const SecretKey& key, std::string_view manifest,
                                                std::span<const std::byte> payload);

}  // namespace smx::update
