// stripemux keygen --out PREFIX
// An Ed25519 key pair for signing firmware bundles (docs/update.md#keys): PREFIX.key, the secret
// key (0600, minisign's unencrypted format), and PREFIX.pub, minisign's public key. Neither file
// is ever replaced.
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "smx/update/keys.hpp"

namespace smx::host {
namespace {

int exitFor(const update::UpdateError& error) {
  return error.reason == update::UpdateReason::kIo ? kExitDeviceOrIo : kExitBadInput;
}

int runKeygen(const std::string& prefix, const CliStreams& io) {
  const std::filesystem::path secretPath = prefix + ".key";
  const std::filesystem::path publicPath = prefix + ".pub";
  // Both checked first, so that a refusal leaves no half of a pair behind.
  for (const auto& path : {secretPath, publicPath}) {
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::symlink_status(path, ec))) {
      io.err << "stripemux keygen: " << path.string() << ": exists already; not replaced\n";
      return kExitBadInput;
    }
  }
  const update::KeyPair pair = update::generateKeyPair();
  if (auto written = update::writeSecretKeyFile(secretPath, pair.secret); !written) {
    io.err << "stripemux keygen: " << written.error().message << "\n";
    return exitFor(written.error());
  }
  if (auto written = update::writePublicKeyFile(publicPath, pair.pub); !written) {
    io.err << "stripemux keygen: " << written.error().message << "\n";
    return exitFor(written.error());
  }
  io.out << "key id " << update::keyIdHex(pair.pub.id) << "\n"
         << "public key " << update::publicKeyLine(pair.pub) << "\n"
         << "secret key " << secretPath.string() << " (keep it off the devices)\n"
         << "public key " << publicPath.string() << "\n";
  return kExitOk;
}

}  // namespace

void addKeygenCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto prefix = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("keygen", "Make a key pair for signing firmware bundles");
  cmd->add_option("--out", *prefix, "Writes PREFIX.key (secret) and PREFIX.pub")->required();
  cmd->callback([prefix, &io, &exitCode] { exitCode = runKeygen(*prefix, io); });
}

}  // namespace smx::host
