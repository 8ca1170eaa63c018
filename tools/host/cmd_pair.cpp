// stripemux pair --device HOST [--code CODE] | pair --show-key | unpair --device HOST
// Pairing with a device that has an owner (docs/security.md "Pairing"): the device prints a
// one-time code on its console; the code proves to both sides that they talk to each other, and
// each stores the other's long-term key. --show-key prints this host's public key, for an owner
// who adds it to the device's STATE/hosts by hand.
#include <iostream>
#include <memory>
#include <string>

#include "command_failure.hpp"
#include "commands.hpp"
#include "device_option.hpp"
#include "device_socket.hpp"
#include "pairing_store.hpp"
#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_keys.hpp"
#include "smx/protocol/secure_messages.hpp"
#include "smx/protocol/secure_pairing.hpp"

namespace smx::host {
namespace {

using protocol::MessageType;

using Fail = std::unexpected<CommandFailure>;

struct PairOptions {
  std::string device;
  std::string code;
  bool showKey = false;
};

std::expected<void, CommandFailure> send(
    net::TcpClient& socket, const protocol::ProtocolResult<std::span<const std::byte>>& m) {
  if (!m) {
    return Fail(CommandFailure{kExitDeviceOrIo, m.error().message});
  }
  if (auto sent = socket.sendAll(*m, kDeviceConnectTimeout); !sent) {
    return Fail(CommandFailure{kExitDeviceOrIo, sent.error()});
  }
  return {};
}

// The device's answer of `expected` type; its error (code 5: a refusal of the pairing) otherwise.
std::expected<std::vector<std::byte>, CommandFailure> expect(net::TcpClient& socket,
                                                             MessageType expected) {
  auto answer = readClearMessage(socket, kDeviceConnectTimeout);
  if (!answer) {
    return Fail(CommandFailure{kExitDeviceOrIo, answer.error()});
  }
  auto& [type, payload] = *answer;
  if (type == MessageType::kError) {
    const auto error = protocol::decodeError(payload);
    if (!error) {
      return Fail(CommandFailure{kExitDeviceOrIo, "the device refused (unreadable)"});
    }
    const bool refused = error->code == protocol::ErrorCode::kNotPaired;
    return Fail(CommandFailure{refused ? kExitBadInput : kExitDeviceOrIo,
                               "the device refused: " + std::string(error->text)});
  }
  if (type != expected) {
    return Fail(CommandFailure{
        kExitDeviceOrIo, std::string("expected ") + protocol::toString(expected) + ", got " +
                             protocol::toString(type) + " (does this firmware know pairing?)"});
  }
  return std::move(payload);
}

std::expected<net::TcpClient, CommandFailure> open(const net::DeviceAddress& address) {
  auto socket = net::TcpClient::connect(address, kDeviceConnectTimeout);
  if (!socket) {
    return Fail(CommandFailure{kExitDeviceOrIo, socket.error()});
  }
  return std::move(*socket);
}

// Asks the device to open a code (it prints it) and says how long it is valid.
std::expected<protocol::PairReady, CommandFailure> beginPairing(const net::DeviceAddress& address) {
  auto socket = open(address);
  if (!socket) {
    return Fail(socket.error());
  }
  std::array<std::byte, 64> out{};
  if (auto sent = send(*socket, protocol::encodeEmpty(MessageType::kPairBegin, out)); !sent) {
    return Fail(sent.error());
  }
  const auto payload = expect(*socket, MessageType::kPairReady);
  if (!payload) {
    return Fail(payload.error());
  }
  const auto ready = protocol::decodePairReady(*payload);
  if (!ready) {
    return Fail(
        CommandFailure{kExitDeviceOrIo, std::string("bad pair-ready: ") + ready.error().message});
  }
  return *ready;
}

// The exchange proper; returns the device's key.
std::expected<protocol::Key32, CommandFailure> provePairing(const net::DeviceAddress& address,
                                                            const protocol::KeyPair& identity,
                                                            const std::string& code) {
  auto socket = open(address);
  if (!socket) {
    return Fail(socket.error());
  }
  const protocol::PakeShare share = protocol::pakeStart(code);
  const protocol::PairRequest request{share.element, identity.publicKey};
  std::array<std::byte, 256> out{};
  if (auto sent = send(*socket, protocol::encode(request, out)); !sent) {
    return Fail(sent.error());
  }
  const auto payload = expect(*socket, MessageType::kPairChallenge);
  if (!payload) {
    return Fail(payload.error());
  }
  const auto challenge = protocol::decodePairChallenge(*payload);
  if (!challenge) {
    return Fail(CommandFailure{kExitDeviceOrIo,
                               std::string("bad pair-challenge: ") + challenge.error().message});
  }
  const auto keys = protocol::pakeFinish(share, challenge->element, request, challenge->element,
                                         challenge->identity);
  if (!keys) {
    return Fail(CommandFailure{kExitDeviceOrIo, "pair-challenge: an invalid element"});
  }
  const bool deviceKnowsCode = protocol::sameProof(challenge->proof, keys->deviceProof);
  // Sent either way, so that the device counts a wrong code at once and says what is left.
  if (auto sent = send(*socket, protocol::encode(protocol::PairProof{keys->hostProof}, out));
      !sent) {
    return Fail(sent.error());
  }
  auto done = expect(*socket, MessageType::kPairDone);
  if (!done) {
    return Fail(done.error());
  }
  if (!deviceKnowsCode) {
    return Fail(CommandFailure{kExitBadInput, "the device did not prove the code: not paired"});
  }
  return challenge->identity;
}

std::expected<std::string, CommandFailure> runPair(const PairOptions& opts) {
  auto identity = hostIdentity();
  if (!identity) {
    return Fail(CommandFailure{kExitDeviceOrIo, identity.error()});
  }
  if (opts.showKey) {
    return protocol::formatPublicKey(identity->publicKey, "stripemux-host");
  }
  if (opts.device.empty()) {
    return Fail(CommandFailure{kExitUsage, "--device HOST or --show-key is required"});
  }
  const auto address = net::parseDeviceAddress(opts.device, protocol::kDefaultPort);
  if (!address) {
    return Fail(CommandFailure{kExitUsage, "--device: " + address.error()});
  }
  const auto ready = beginPairing(*address);
  if (!ready) {
    return Fail(ready.error());
  }
  std::string code = opts.code;
  if (code.empty()) {
    std::cout << "the device printed a " << int{ready->digits} << "-digit pairing code on its "
              << "console (" << int{ready->attemptsLeft} << " attempts, " << ready->secondsLeft
              << " s left); code: " << std::flush;
    std::getline(std::cin, code);
  }
  if (code.size() < 6 || code.size() > 8 ||
      code.find_first_not_of("0123456789") != std::string::npos) {
    return Fail(CommandFailure{kExitUsage, "the pairing code is 6 to 8 digits"});
  }
  const auto deviceKey = provePairing(*address, *identity, code);
  if (!deviceKey) {
    return Fail(deviceKey.error());
  }
  const auto stored = storePairedDevice(*address, *deviceKey);
  if (!stored) {
    return Fail(CommandFailure{kExitDeviceOrIo, stored.error()});
  }
  return "paired with " + net::toString(*address) + ": device key " +
         protocol::fingerprint(*deviceKey) + ", this host's key " +
         protocol::fingerprint(identity->publicKey) + " (" + stored->string() + ")\n";
}

std::expected<std::string, CommandFailure> runUnpair(const std::string& device) {
  const auto address = net::parseDeviceAddress(device, protocol::kDefaultPort);
  if (!address) {
    return Fail(CommandFailure{kExitUsage, "--device: " + address.error()});
  }
  const auto forgot = forgetPairedDevice(*address);
  if (!forgot) {
    return Fail(CommandFailure{kExitDeviceOrIo, forgot.error()});
  }
  if (!*forgot) {
    return Fail(
        CommandFailure{kExitBadInput, "this host has not paired with " + net::toString(*address)});
  }
  return "forgot " + net::toString(*address) +
         "; the device keeps this host's key until its owner removes it from STATE/hosts\n";
}

int report(const std::expected<std::string, CommandFailure>& result, const CliStreams& io,
           const char* command) {
  if (!result) {
    io.err << "stripemux " << command << ": " << result.error().message << "\n";
    return result.error().code;
  }
  io.out << *result;
  return kExitOk;
}

}  // namespace

void addPairCommand(CLI::App& app, const CliStreams& io, int& exitCode) {
  auto opts = std::make_shared<PairOptions>();
  auto* cmd = app.add_subcommand("pair", "Pair this host with a device that has an owner");
  cmd->add_option("--device", opts->device, "the device (HOST[:PORT])")
      ->check(deviceAddressValidator());
  cmd->add_option("--code", opts->code, "the code the device printed (asked for when absent)");
  cmd->add_flag("--show-key", opts->showKey, "print this host's public key and exit");
  cmd->callback([opts, &io, &exitCode] { exitCode = report(runPair(*opts), io, "pair"); });

  auto device = std::make_shared<std::string>();
  auto* unpair = app.add_subcommand("unpair", "Forget a device this host paired with");
  unpair->add_option("--device", *device, "the device (HOST[:PORT]) as given to pair")
      ->required()
      ->check(deviceAddressValidator());
  unpair->callback(
      [device, &io, &exitCode] { exitCode = report(runUnpair(*device), io, "unpair"); });
}

}  // namespace smx::host
