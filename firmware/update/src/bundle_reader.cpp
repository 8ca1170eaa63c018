#include <algorithm>
#include <cstring>
#include <string>

#include "bundle_layout.hpp"
#include "hash.hpp"
#include "manifest.hpp"
#include "smx/update/bundle.hpp"
#include "smx/update/file_io.hpp"
#include "smx/update/signature.hpp"

namespace smx::update {
namespace {

std::unexpected<UpdateError> fail(UpdateReason reason, const std::string& what) {
  return std::unexpected(UpdateError{reason, "bundle: " + what});
}

bool matches(std::span<const std::byte> bytes, std::size_t at, std::span<const char> magic) {
  // The first bytes of a cut file are compared with as much of the magic as there is, which may
  // be none: an empty span may have no data pointer, which memcmp must never see.
  return bytes.size() >= at + magic.size() &&
         (magic.empty() || std::memcmp(bytes.data() + at, magic.data(), magic.size()) == 0);
}

struct Sections {
  std::size_t manifestSize = 0;
  std::size_t payloadSize = 0;
  std::size_t signatureSize = 0;
  [[nodiscard]] std::size_t signedSize() const { return kHeaderSize + manifestSize + payloadSize; }
};

// Every size in the header and trailer, against the limits and the bytes there are; nothing is
// read beyond what they allow.
std::expected<Sections, UpdateError> readSections(std::span<const std::byte> bytes) {
  const std::size_t size = bytes.size();
  if (!matches(bytes, 0, std::span(layout::kMagic).first(std::min(size, layout::kMagic.size())))) {
    return fail(UpdateReason::kMalformed, "no stripemux bundle magic at the start");
  }
  if (size < kHeaderSize + kTrailerSize) {
    return fail(UpdateReason::kTruncated, std::to_string(size) + " bytes, less than the " +
                                              std::to_string(kHeaderSize + kTrailerSize) +
                                              " of header and trailer");
  }
  if (layout::load(bytes, layout::kReservedAt, 4) != 0) {
    return fail(UpdateReason::kMalformed, "header: reserved bytes 12..15 are not zero");
  }
  Sections s;
  const auto manifestSize = layout::load(bytes, layout::kManifestSizeAt, 4);
  const auto payloadSize = layout::load(bytes, layout::kPayloadSizeAt, 8);
  if (manifestSize == 0 || manifestSize > kMaxManifestSize) {
    return fail(UpdateReason::kTooLarge, "header: manifest size " + std::to_string(manifestSize) +
                                             " is not 1.." + std::to_string(kMaxManifestSize));
  }
  if (payloadSize > kMaxPayloadSize) {
    return fail(UpdateReason::kTooLarge, "header: payload size " + std::to_string(payloadSize) +
                                             " is more than " + std::to_string(kMaxPayloadSize));
  }
  s.manifestSize = manifestSize;
  s.payloadSize = payloadSize;
  if (size < s.signedSize() + kTrailerSize) {
    return fail(UpdateReason::kTruncated, std::to_string(size) + " bytes, less than the header's " +
                                              std::to_string(s.signedSize()) +
                                              " before the signature and trailer");
  }
  if (!matches(bytes, size - layout::kEndMagic.size(), layout::kEndMagic)) {
    return fail(UpdateReason::kTruncated, "no trailer at the end (cut short or not a bundle)");
  }
  const auto signatureSize = layout::load(bytes, size - kTrailerSize, 4);
  if (signatureSize == 0 || signatureSize > kMaxSignatureSize) {
    return fail(UpdateReason::kTooLarge, "trailer: signature size " +
                                             std::to_string(signatureSize) + " is not 1.." +
                                             std::to_string(kMaxSignatureSize));
  }
  s.signatureSize = signatureSize;
  const std::size_t total = s.signedSize() + s.signatureSize + kTrailerSize;
  if (size < total) {
    return fail(UpdateReason::kTruncated, std::to_string(size) + " bytes, less than the " +
                                              std::to_string(total) + " its sizes add up to");
  }
  if (size > total) {
    return fail(UpdateReason::kMalformed, std::to_string(size) + " bytes, more than the " +
                                              std::to_string(total) + " its sizes add up to");
  }
  return s;
}

}  // namespace

VerifiedBundle::VerifiedBundle(std::vector<std::byte> bytes, BundleInfo info,
                               std::size_t payloadOffset)
    : bytes_(std::move(bytes)), info_(std::move(info)), payloadOffset_(payloadOffset) {}

std::span<const std::byte> VerifiedBundle::fileBytes(const BundleFile& file) const {
  return std::span(bytes_).subspan(payloadOffset_ + file.offset, file.size);
}

std::expected<VerifiedBundle, UpdateError> verifyBundle(std::vector<std::byte> bytes,
                                                        std::span<const PublicKey> trusted,
                                                        const Expectations& expect) {
  const auto sections = readSections(bytes);
  if (!sections) {
    return std::unexpected(sections.error());
  }
  const auto all = std::span<const std::byte>(bytes);
  const auto signedBytes = all.first(sections->signedSize());
  const auto signature = all.subspan(sections->signedSize(), sections->signatureSize);
  // The signature first: nothing of the manifest is read before its bytes are authenticated.
  const auto keyId = verify(
      signedBytes,
      std::string_view(reinterpret_cast<const char*>(signature.data()), signature.size()), trusted);
  if (!keyId) {
    return fail(keyId.error().reason, keyId.error().message);
  }
  const auto manifestBytes = all.subspan(kHeaderSize, sections->manifestSize);
  auto manifest = parseManifest(
      std::string_view(reinterpret_cast<const char*>(manifestBytes.data()), manifestBytes.size()));
  if (!manifest) {
    return fail(manifest.error().reason, manifest.error().message);
  }
  const std::uint64_t listed =
      manifest->files.empty() ? 0 : manifest->files.back().offset + manifest->files.back().size;
  if (listed != sections->payloadSize) {
    return fail(UpdateReason::kMalformed, "manifest: files add up to " + std::to_string(listed) +
                                              " bytes, the payload is " +
                                              std::to_string(sections->payloadSize));
  }
  const std::size_t payloadOffset = kHeaderSize + sections->manifestSize;
  for (const auto& f : manifest->files) {
    if (blake2bHex(all.subspan(payloadOffset + f.offset, f.size)) != f.blake2bHex) {
      return fail(UpdateReason::kBadHash, f.name + ": its " + std::to_string(f.size) +
                                              " bytes do not match the manifest's blake2b");
    }
  }
  if (expect.board && std::find(manifest->boards.begin(), manifest->boards.end(), *expect.board) ==
                          manifest->boards.end()) {
    std::string listedBoards;
    for (const auto& b : manifest->boards) {
      listedBoards += (listedBoards.empty() ? "" : ", ") + b;
    }
    return fail(UpdateReason::kWrongBoard,
                "made for " + listedBoards + ", not for board " + *expect.board);
  }
  if (expect.installed && manifest->version < *expect.installed && !manifest->allowDowngrade) {
    return fail(UpdateReason::kDowngrade,
                "version " + toString(manifest->version) + " is older than the installed " +
                    toString(*expect.installed) + " and the bundle does not allow a downgrade");
  }
  BundleInfo info{manifest->version, std::move(manifest->boards), manifest->allowDowngrade,
                  std::move(manifest->files), *keyId};
  return VerifiedBundle(std::move(bytes), std::move(info), payloadOffset);
}

std::expected<VerifiedBundle, UpdateError> verifyBundleFile(const std::filesystem::path& path,
                                                            std::span<const PublicKey> trusted,
                                                            const Expectations& expect) {
  auto bytes = readFile(path, kMaxBundleSize);
  if (!bytes) {
    return std::unexpected(bytes.error());
  }
  auto verified = verifyBundle(std::move(*bytes), trusted, expect);
  if (!verified) {
    return std::unexpected(
        UpdateError{verified.error().reason, path.string() + ": " + verified.error().message});
  }
  return verified;
}

}  // namespace smx::update
