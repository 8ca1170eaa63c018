#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "smx/update/bundle.hpp"
#include "smx/update/keys.hpp"

// Fixed test keys and a small bundle for the update tests and the fuzzer's seeds.
namespace smx::test {

inline update::KeyPair testKey(std::uint8_t fill) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(fill);
  return update::keyPairFromSeed(seed);
}

inline std::vector<std::byte> bytesOf(const std::string& text) {
  const auto* data = reinterpret_cast<const std::byte*>(text.data());
  return {data, data + text.size()};
}

// Two boards, an executable, a nested data file and an empty one.
inline update::BundleSpec smallSpec() {
  update::BundleSpec spec;
  spec.version = {1, 4, 2};
  spec.boards = {"rpi4", "sim"};
  spec.files = {{"bin/stripemuxd", 0755, bytesOf("#!/bin/sh\necho firmware\n")},
                {"boards/sim/board.json", 0644, bytesOf("{\"format\": \"stripemux-board/1\"}\n")},
                {"boards/sim/empty", 0644, {}}};
  return spec;
}

}  // namespace smx::test
