#include "hash.hpp"

#include <sodium.h>

#include <array>

#include "sodium_init.hpp"

namespace smx::update {

std::string blake2bHex(std::span<const std::byte> bytes) {
  initSodium();
  std::array<unsigned char, 32> hash{};
  crypto_generichash(hash.data(), hash.size(), reinterpret_cast<const unsigned char*>(bytes.data()),
                     bytes.size(), nullptr, 0);
  std::array<char, 65> hex{};
  sodium_bin2hex(hex.data(), hex.size(), hash.data(), hash.size());
  return {hex.data(), 64};
}

}  // namespace smx::update
