#include "sodium_ready.hpp"

#include <sodium.h>

#include <cstdlib>

namespace smx::protocol {

void sodiumReady() {
  // Fails only without a random source, which no key or session can do without.
  static const bool kReady = sodium_init() >= 0;
  if (!kReady) {
    std::abort();
  }
}

}  // namespace smx::protocol
