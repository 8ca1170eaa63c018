#pragma once

#include <expected>
#include <filesystem>
#include <optional>
#include <string>

#include "smx/net/tcp_client.hpp"
#include "smx/protocol/secure_session.hpp"

// The host's side of ownership (docs/security.md "Key files"): its key pair in
// `$XDG_CONFIG_HOME/stripemux/host.key` (~/.config when unset) and, per device it paired with,
// the device's public key in `devices/<name>.pub`, the name made from the address the user gave
// (host and port; characters other than letters, digits, '.' and '-' as _xx), never a path.
namespace smx::host {

[[nodiscard]] std::expected<std::filesystem::path, std::string> stripemuxConfigDir();
// "127.0.0.1-5555", "_3a_3a1-5555" for [::1]:5555.
[[nodiscard]] std::string deviceRecordName(const net::DeviceAddress& address);

// This host's key pair, made on first use.
[[nodiscard]] std::expected<protocol::KeyPair, std::string> hostIdentity();
// The key of the device this host paired with at `address`, if it did.
[[nodiscard]] std::expected<std::optional<protocol::Key32>, std::string> pairedDeviceKey(
    const net::DeviceAddress& address);
[[nodiscard]] std::expected<std::filesystem::path, std::string> storePairedDevice(
    const net::DeviceAddress& address, const protocol::Key32& key);
// Forgets the device at `address`; false if this host had not paired with it.
[[nodiscard]] std::expected<bool, std::string> forgetPairedDevice(
    const net::DeviceAddress& address);

}  // namespace smx::host
