#include "sodium_init.hpp"

#include <sodium.h>

#include <cstdlib>

namespace smx::update {

void initSodium() {
  // Thread-safe once; fails only when the system has no random source, which no key can do
  // without.
  static const bool kReady = sodium_init() >= 0;
  if (!kReady) {
    std::abort();
  }
}

}  // namespace smx::update
