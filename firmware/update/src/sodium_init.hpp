#pragma once

namespace smx::update {

// Every entry point that uses libsodium calls this first; it runs sodium_init() once.
void initSodium();

}  // namespace smx::update
