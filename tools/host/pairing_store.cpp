#include "pairing_store.hpp"

#include <cstdlib>
#include <system_error>

#include "smx/protocol/secure_keys.hpp"
#include "smx/update/file_io.hpp"

namespace smx::host {

namespace fs = std::filesystem;

namespace {

std::expected<fs::path, std::string> devicesDir(bool create) {
  auto dir = stripemuxConfigDir();
  if (!dir) {
    return dir;
  }
  const fs::path devices = *dir / "devices";
  std::error_code error;
  if (create) {
    fs::create_directories(devices, error);
    if (error) {
      return std::unexpected(devices.string() + ": " + error.message());
    }
  }
  return devices;
}

}  // namespace

std::expected<fs::path, std::string> stripemuxConfigDir() {
  // NOLINTNEXTLINE(concurrency-mt-unsafe): the tool never sets its environment
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  if (xdg != nullptr && *xdg == '/') {
    return fs::path(xdg) / "stripemux";
  }
  const char* home = std::getenv("HOME");  // NOLINT(concurrency-mt-unsafe): as above
  if (home == nullptr || *home != '/') {
    return std::unexpected(std::string("neither XDG_CONFIG_HOME nor HOME names a directory"));
  }
  return fs::path(home) / ".config" / "stripemux";
}

std::string deviceRecordName(const net::DeviceAddress& address) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string name;
  for (const char c : address.host) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '-';
    if (plain) {
      name += c;
    } else {
      const auto byte = static_cast<unsigned char>(c);
      name += '_';
      name += kHex[byte >> 4U];
      name += kHex[byte & 0xFU];
    }
  }
  // The port has no '-': the name maps back to one address. "." and ".." cannot come out.
  return name + "-" + std::to_string(address.port);
}

std::expected<protocol::KeyPair, std::string> hostIdentity() {
  auto dir = stripemuxConfigDir();
  if (!dir) {
    return std::unexpected(dir.error());
  }
  std::error_code error;
  fs::create_directories(*dir, error);
  if (error) {
    return std::unexpected(dir->string() + ": " + error.message());
  }
  return protocol::loadOrCreateIdentity(*dir / "host.key");
}

std::expected<std::optional<protocol::Key32>, std::string> pairedDeviceKey(
    const net::DeviceAddress& address) {
  auto dir = devicesDir(false);
  if (!dir) {
    return std::unexpected(dir.error());
  }
  const fs::path file = *dir / (deviceRecordName(address) + ".pub");
  std::error_code error;
  if (!fs::exists(file, error)) {
    return std::nullopt;
  }
  auto key = protocol::readPublicKeyFile(file);
  if (!key) {
    return std::unexpected(key.error());
  }
  return *key;
}

std::expected<fs::path, std::string> storePairedDevice(const net::DeviceAddress& address,
                                                       const protocol::Key32& key) {
  auto dir = devicesDir(true);
  if (!dir) {
    return dir;
  }
  const fs::path file = *dir / (deviceRecordName(address) + ".pub");
  const std::string text = protocol::formatPublicKey(key, net::toString(address));
  if (auto written =
          update::writeFileAtomic(file, update::asBytes(text), 0644, update::Replace::kAllow);
      !written) {
    return std::unexpected(written.error().message);
  }
  return file;
}

std::expected<bool, std::string> forgetPairedDevice(const net::DeviceAddress& address) {
  auto dir = devicesDir(false);
  if (!dir) {
    return std::unexpected(dir.error());
  }
  const fs::path file = *dir / (deviceRecordName(address) + ".pub");
  std::error_code error;
  const bool removed = fs::remove(file, error);
  if (error) {
    return std::unexpected(file.string() + ": " + error.message());
  }
  return removed;
}

}  // namespace smx::host
