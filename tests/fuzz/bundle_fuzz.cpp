// libFuzzer target for firmware bundles (smx::update::verifyBundle, docs/update.md): any bytes
// are a verified bundle or an UpdateError, never a crash or a sanitizer report. Random bytes
// rarely carry a valid signature, so an input that does not start with the bundle magic is
// taken as "MANIFEST\0PAYLOAD", sealed with the trusted test key and verified: the manifest
// parser, which only ever reads signed text, is fuzzed too.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "smx/update/bundle.hpp"

namespace {

// The key tests/fuzz/make_seeds.py signs the seed bundles with: the seed is 32 bytes of 1.
const smx::update::KeyPair& testKey() {
  static const smx::update::KeyPair key = [] {
    std::array<std::uint8_t, 32> seed{};
    seed.fill(1);
    return smx::update::keyPairFromSeed(seed);
  }();
  return key;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* begin = reinterpret_cast<const std::byte*>(data);
  std::vector<std::byte> bytes(begin, begin + size);
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (!text.starts_with("SMXBNDL1")) {
    const auto nul = text.rfind('\0');
    const auto manifest = text.substr(0, nul);
    if (manifest.size() > smx::update::kMaxManifestSize) {
      return 0;
    }
    const auto payload = nul == std::string_view::npos ? std::span<const std::byte>{}
                                                       : std::span(bytes).subspan(nul + 1);
    bytes = smx::update::sealBundle(testKey().secret, manifest, payload);
  }
  const std::array<smx::update::PublicKey, 1> trusted = {testKey().pub};
  const auto bundle = smx::update::verifyBundle(std::move(bytes), trusted, {"sim", {{1, 0, 0}}});
  if (!bundle) {
    return 0;
  }
  // A verified bundle's files lie inside it, with the sizes the manifest gives.
  for (const auto& file : bundle->info().files) {
    if (bundle->fileBytes(file).size() != file.size) {
      std::abort();
    }
  }
  return 0;
}
