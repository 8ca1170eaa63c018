#include "smx/device/owners.hpp"

#include <algorithm>
#include <system_error>

#include "smx/protocol/secure_keys.hpp"
#include "smx/update/file_io.hpp"

namespace smx::device {

namespace fs = std::filesystem;

std::expected<Owners, std::string> Owners::open(const fs::path& stateDir, bool pairOnStart) {
  std::error_code error;
  const fs::path hosts = stateDir / "hosts";
  fs::create_directories(hosts, error);
  if (error) {
    return std::unexpected(hosts.string() + ": " + error.message());
  }
  auto identity = protocol::loadOrCreateIdentity(stateDir / "identity.key");
  if (!identity) {
    return std::unexpected(identity.error());
  }
  return Owners(hosts, *identity, pairOnStart);
}

bool Owners::isPaired(const protocol::Key32& host) const {
  std::error_code error;
  return std::ranges::any_of(fs::directory_iterator(hostsDir_, error), [&](const auto& entry) {
    if (entry.path().extension() != ".pub") {
      return false;
    }
    const auto key = protocol::readPublicKeyFile(entry.path());
    return key && *key == host;
  });
}

std::size_t Owners::pairedHosts() const {
  std::size_t count = 0;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(hostsDir_, error)) {
    if (entry.path().extension() == ".pub" && protocol::readPublicKeyFile(entry.path())) {
      ++count;
    }
  }
  return count;
}

std::expected<fs::path, std::string> Owners::addHost(const protocol::Key32& host) {
  const fs::path file = hostsDir_ / ("host-" + protocol::fingerprint(host) + ".pub");
  const std::string text = protocol::formatPublicKey(host, "paired");
  auto written =
      update::writeFileAtomic(file, update::asBytes(text), 0644, update::Replace::kAllow);
  if (!written) {
    return std::unexpected(written.error().message);
  }
  pairedSinceStart_ = true;
  return file;
}

bool Owners::pairingOpen() const {
  return pairOnStart_ ? !pairedSinceStart_ : pairedHosts() == 0;
}

}  // namespace smx::device
