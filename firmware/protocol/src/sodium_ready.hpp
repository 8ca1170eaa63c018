#pragma once

namespace smx::protocol {

// Every entry point of smx_secure that uses libsodium calls this first (sodium_init() once).
void sodiumReady();

}  // namespace smx::protocol
