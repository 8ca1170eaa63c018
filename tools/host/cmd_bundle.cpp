// stripemux bundle --key SECRET --firmware DIR --out FILE [--version V] [--board NAME]...
//                  [--allow-downgrade]
// stripemux verify-bundle --pub KEY.pub [--board NAME] [--installed V] FILE
// A signed firmware bundle of an installed firmware tree, and the device's check of one
// (docs/update.md, docs/cli.md).
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "smx/update/bundle.hpp"
#include "smx/update/file_io.hpp"
#include "smx/update/signature.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

struct BundleOptions {
  fs::path key;
  fs::path firmware;
  fs::path out;
  std::string version = SMX_VERSION;
  std::vector<std::string> boards;
  bool allowDowngrade = false;
};

struct VerifyOptions {
  fs::path pub;
  fs::path bundle;
  std::optional<std::string> board;
  std::optional<std::string> installed;
};

int report(const CliStreams& io, const char* command, const update::UpdateError& error) {
  io.err << "stripemux " << command << ": " << update::reasonName(error.reason) << ": "
         << error.message << "\n";
  return error.reason == update::UpdateReason::kIo ? kExitDeviceOrIo : kExitBadInput;
}

// Every regular file below dir, by name relative to it, sorted; anything else is refused.
std::expected<std::vector<update::BundleInput>, update::UpdateError> readTree(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) {
    return std::unexpected(
        update::UpdateError{update::UpdateReason::kMalformed, dir.string() + ": not a folder"});
  }
  std::vector<fs::path> paths;
  std::uint64_t total = 0;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const auto status = it->symlink_status(ec);
    if (ec) {
      break;
    }
    if (fs::is_directory(status)) {
      continue;
    }
    if (!fs::is_regular_file(status)) {
      return std::unexpected(update::UpdateError{
          update::UpdateReason::kMalformed,
          it->path().string() + ": " + (fs::is_symlink(status) ? "a symlink" : "a special file") +
              "; a bundle holds regular files only"});
    }
    total += it->file_size(ec);
    if (total > update::kMaxPayloadSize) {
      return std::unexpected(update::UpdateError{
          update::UpdateReason::kTooLarge,
          dir.string() + ": more than " + std::to_string(update::kMaxPayloadSize) + " bytes"});
    }
    paths.push_back(it->path());
  }
  if (ec) {
    return std::unexpected(
        update::UpdateError{update::UpdateReason::kIo, dir.string() + ": " + ec.message()});
  }
  std::sort(paths.begin(), paths.end());
  std::vector<update::BundleInput> files;
  for (const auto& path : paths) {
    auto bytes = update::readFile(path, update::kMaxPayloadSize);
    if (!bytes) {
      return std::unexpected(bytes.error());
    }
    const auto perms = fs::status(path, ec).permissions();
    const bool executable = (perms & fs::perms::owner_exec) != fs::perms::none;
    files.push_back({path.lexically_relative(dir).generic_string(), executable ? 0755U : 0644U,
                     std::move(*bytes)});
  }
  return files;
}

// The board folders under DIR/boards.
std::vector<std::string> boardsIn(const fs::path& dir) {
  std::vector<std::string> boards;
  std::error_code ec;
  for (auto it = fs::directory_iterator(dir / "boards", ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (it->is_directory(ec)) {
      boards.push_back(it->path().filename().string());
    }
  }
  std::sort(boards.begin(), boards.end());
  return boards;
}

int runBundle(const BundleOptions& opts, const CliStreams& io) {
  const auto key = update::readSecretKeyFile(opts.key);
  if (!key) {
    return report(io, "bundle", key.error());
  }
  const auto version = update::parseVersion(opts.version, "--version");
  if (!version) {
    return report(io, "bundle", version.error());
  }
  update::BundleSpec spec{*version, opts.boards, opts.allowDowngrade, {}};
  if (spec.boards.empty()) {
    spec.boards = boardsIn(opts.firmware);
    if (spec.boards.empty()) {
      io.err << "stripemux bundle: " << opts.firmware.string()
             << ": no boards/<name> folders; name the boards with --board\n";
      return kExitUsage;
    }
  }
  auto files = readTree(opts.firmware);
  if (!files) {
    return report(io, "bundle", files.error());
  }
  spec.files = std::move(*files);
  const auto bundle = update::makeBundle(*key, spec);
  if (!bundle) {
    return report(io, "bundle", bundle.error());
  }
  if (auto written = update::writeFileAtomic(opts.out, *bundle, 0644, update::Replace::kAllow);
      !written) {
    return report(io, "bundle", written.error());
  }
  std::string boards;
  for (const auto& b : spec.boards) {
    boards += (boards.empty() ? "" : ", ") + b;
  }
  io.out << opts.out.string() << ": " << bundle->size() << " bytes, " << spec.files.size()
         << " files, version " << update::toString(spec.version) << ", boards " << boards
         << ", key id " << update::keyIdHex(key->id) << "\n";
  return kExitOk;
}

int runVerify(const VerifyOptions& opts, const CliStreams& io) {
  const auto pub = update::readPublicKeyFile(opts.pub);
  if (!pub) {
    return report(io, "verify-bundle", pub.error());
  }
  update::Expectations expect{opts.board, std::nullopt};
  if (opts.installed) {
    const auto installed = update::parseVersion(*opts.installed, "--installed");
    if (!installed) {
      return report(io, "verify-bundle", installed.error());
    }
    expect.installed = *installed;
  }
  const auto bundle = update::verifyBundleFile(opts.bundle, std::span(&*pub, 1), expect);
  if (!bundle) {
    return report(io, "verify-bundle", bundle.error());
  }
  const auto& info = bundle->info();
  std::string boards;
  for (const auto& b : info.boards) {
    boards += (boards.empty() ? "" : ", ") + b;
  }
  io.out << opts.bundle.string() << ": valid, version " << update::toString(info.version)
         << ", boards " << boards << ", " << info.files.size() << " files, key id "
         << update::keyIdHex(info.keyId) << (info.allowDowngrade ? ", may downgrade" : "") << "\n";
  return kExitOk;
}

}  // namespace

void addBundleCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<BundleOptions>();
  auto* cmd = app.add_subcommand("bundle", "Make a signed firmware bundle of an installed tree");
  cmd->add_option("--key", opts->key, "Secret key (stripemux keygen)")->required();
  cmd->add_option("--firmware", opts->firmware, "Installed firmware folder (bin/, boards/...)")
      ->required();
  cmd->add_option("--out", opts->out, "Bundle file to write")->required();
  cmd->add_option("--version", opts->version, "MAJOR.MINOR.PATCH (default: this tool's)");
  cmd->add_option("--board", opts->boards, "A board it is for (default: DIR/boards/*)");
  cmd->add_flag("--allow-downgrade", opts->allowDowngrade,
                "Let devices with a newer version install it");
  cmd->callback([opts, &io, &exitCode] { exitCode = runBundle(*opts, io); });
}

void addVerifyBundleCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<VerifyOptions>();
  auto* cmd = app.add_subcommand("verify-bundle", "Check a firmware bundle as a device does");
  cmd->add_option("--pub", opts->pub, "Trusted public key (stripemux keygen, minisign)")
      ->required();
  cmd->add_option("--board", opts->board, "The device's board");
  cmd->add_option("--installed", opts->installed, "The device's installed version");
  cmd->add_option("FILE", opts->bundle, "Bundle file")->required();
  cmd->callback([opts, &io, &exitCode] { exitCode = runVerify(*opts, io); });
}

}  // namespace smx::host
