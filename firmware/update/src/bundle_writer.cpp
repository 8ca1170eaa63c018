#include <string>

#include "bundle_layout.hpp"
#include "hash.hpp"
#include "manifest.hpp"
#include "smx/update/bundle.hpp"
#include "smx/update/signature.hpp"

namespace smx::update {
namespace {

void store(std::vector<std::byte>& out, std::uint64_t value, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) {
    out.push_back(static_cast<std::byte>((value >> (8 * i)) & 0xffU));
  }
}

void append(std::vector<std::byte>& out, std::span<const char> text) {
  const auto bytes = std::as_bytes(text);
  out.insert(out.end(), bytes.begin(), bytes.end());
}

}  // namespace

std::vector<std::byte> sealBundle(const SecretKey& key, std::string_view manifest,
                                  std::span<const std::byte> payload) {
  std::vector<std::byte> out;
  out.reserve(kHeaderSize + manifest.size() + payload.size() + 512);
  append(out, layout::kMagic);
  store(out, manifest.size(), 4);
  store(out, 0, 4);
  store(out, payload.size(), 8);
  append(out, manifest);
  out.insert(out.end(), payload.begin(), payload.end());
  const std::string signature = sign(key, out, layout::kTrustedComment);
  append(out, signature);
  store(out, signature.size(), 4);
  append(out, layout::kEndMagic);
  return out;
}

std::expected<std::vector<std::byte>, UpdateError> makeBundle(const SecretKey& key,
                                                              const BundleSpec& spec) {
  Manifest manifest{spec.version, spec.boards, spec.allowDowngrade, {}};
  std::vector<std::byte> payload;
  for (const auto& input : spec.files) {
    manifest.files.push_back(
        {input.name, input.bytes.size(), input.mode, blake2bHex(input.bytes), payload.size()});
    if (payload.size() + input.bytes.size() > kMaxPayloadSize) {
      return std::unexpected(UpdateError{
          UpdateReason::kTooLarge,
          "bundle: the files are more than " + std::to_string(kMaxPayloadSize) + " bytes in all"});
    }
    payload.insert(payload.end(), input.bytes.begin(), input.bytes.end());
  }
  const std::string text = manifestJson(manifest);
  if (text.size() > kMaxManifestSize) {
    return std::unexpected(UpdateError{
        UpdateReason::kTooLarge, "bundle: the manifest is " + std::to_string(text.size()) +
                                     " bytes, more than " + std::to_string(kMaxManifestSize)});
  }
  // The reader's own check, so that no bundle is made that a device would refuse as malformed.
  if (auto checked = parseManifest(text); !checked) {
    return std::unexpected(checked.error());
  }
  return sealBundle(key, text, payload);
}

}  // namespace smx::update
