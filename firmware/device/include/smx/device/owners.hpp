#pragma once

#include <expected>
#include <filesystem>
#include <string>

#include "smx/protocol/secure_session.hpp"

// Who owns a device with a state directory (docs/security.md "Key files"): its long-term key
// `STATE/identity.key`, made at the first start, and the hosts it serves, one public key file
// each in `STATE/hosts/` (written by pairing, or dropped there by the owner).
namespace smx::device {

class Owners {
 public:
  // `pairOnStart`: pairing stays open until a host pairs, even when hosts are paired already
  // (stripemuxd --pair). Errors name the file.
  [[nodiscard]] static std::expected<Owners, std::string> open(
      const std::filesystem::path& stateDir, bool pairOnStart);

  [[nodiscard]] const protocol::KeyPair& identity() const { return identity_; }
  // Read from the directory at each call, so that a key the owner adds or removes counts for
  // the next connection without a restart. Files that are not valid keys are ignored.
  [[nodiscard]] bool isPaired(const protocol::Key32& host) const;
  [[nodiscard]] std::size_t pairedHosts() const;
  // Stores a host's key as hosts/host-<fingerprint>.pub; returns the file.
  [[nodiscard]] std::expected<std::filesystem::path, std::string> addHost(
      const protocol::Key32& host);
  // Nobody paired yet, or --pair and no host paired since the start.
  [[nodiscard]] bool pairingOpen() const;

 private:
  Owners(std::filesystem::path hostsDir, protocol::KeyPair identity, bool pairOnStart)
      : hostsDir_(std::move(hostsDir)), identity_(identity), pairOnStart_(pairOnStart) {}

  std::filesystem::path hostsDir_;
  protocol::KeyPair identity_;
  bool pairOnStart_;
  bool pairedSinceStart_ = false;
};

}  // namespace smx::device
