// libFuzzer target for the owner's channel (docs/security.md): the parsers of messages 21–28 and
// the encrypted record reader. The input is [type u8, length u16, payload] records sealed into
// messages with correct headers (so the decoders, not the CRC, see the bytes); each that decodes
// must re-encode to the same payload. The same bytes then go to a started SecureChannel as
// ciphertext, which must refuse them (nothing decrypts without the key) without a crash.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "smx/protocol/messages.hpp"
#include "smx/protocol/secure_messages.hpp"
#include "smx/protocol/secure_session.hpp"
#include "smx/protocol/stream_parser.hpp"

namespace {

using namespace smx::protocol;

[[noreturn]] void broken() {
  std::abort();
}

template <class T>
void sameAs(const ProtocolResult<std::span<const std::byte>>& again,
            std::span<const std::byte> payload, const ProtocolResult<T>& decoded) {
  if (!decoded) {
    return;
  }
  if (!again || again->size() != kHeaderBytes + payload.size() ||
      std::memcmp(again->data() + kHeaderBytes, payload.data(), payload.size()) != 0) {
    broken();
  }
}

void check(const Message& m) {
  std::array<std::byte, 512> out{};
  switch (m.type) {
    case MessageType::kSecureHello:
    case MessageType::kSecureAccept: {
      const auto d = decodeSecureHello(m.payload);
      sameAs(d ? encodeSecureHello(m.type, *d, out) : encodeEmpty(m.type, out), m.payload, d);
      return;
    }
    case MessageType::kPairRequest: {
      const auto d = decodePairRequest(m.payload);
      sameAs(d ? encode(*d, out) : encodeEmpty(m.type, out), m.payload, d);
      return;
    }
    case MessageType::kPairChallenge: {
      const auto d = decodePairChallenge(m.payload);
      sameAs(d ? encode(*d, out) : encodeEmpty(m.type, out), m.payload, d);
      return;
    }
    case MessageType::kPairProof: {
      const auto d = decodePairProof(m.payload);
      sameAs(d ? encode(*d, out) : encodeEmpty(m.type, out), m.payload, d);
      return;
    }
    case MessageType::kPairReady: {
      const auto d = decodePairReady(m.payload);
      sameAs(d ? encode(*d, out) : encodeEmpty(m.type, out), m.payload, d);
      return;
    }
    default:
      (void)decodeEmpty(m.payload);
      return;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span input(reinterpret_cast<const std::byte*>(data), size);
  std::vector<std::byte> stream;
  for (std::size_t at = 0; at + 3 <= input.size();) {
    const auto type = static_cast<MessageType>(input[at]);
    const std::size_t length =
        std::min<std::size_t>(std::to_integer<std::size_t>(input[at + 1]) |
                                  (std::to_integer<std::size_t>(input[at + 2]) << 8U),
                              input.size() - at - 3);
    std::vector<std::byte> message(kHeaderBytes + length);
    std::memcpy(message.data() + kHeaderBytes, input.data() + at + 3, length);
    if (const auto sealed = sealMessage(message, type, length)) {
      stream.insert(stream.end(), sealed->begin(), sealed->end());
    }
    at += 3 + length;
  }
  StreamParser parser(4096);
  for (std::size_t fed = 0; fed < stream.size();) {
    fed += parser.feed(std::span(stream).subspan(fed));
    while (true) {
      const auto next = parser.next();
      if (next && !next->has_value()) {
        break;
      }
      if (next) {
        check(**next);
      }
    }
  }

  static SecureChannel channel;
  SessionKeys keys;
  keys.deviceToHost.fill(std::byte{7});
  channel.start(keys, Role::kHost);
  std::array<std::byte, 256> plain{};
  for (std::size_t at = 0; at < input.size();) {
    const auto space = channel.writable();
    const std::size_t n = std::min(space.size(), input.size() - at);
    std::memcpy(space.data(), input.data() + at, n);
    channel.commit(n);
    at += n;
    const auto got = channel.read(plain);
    if (!got) {
      break;
    }
    if (*got > 0) {
      broken();  // decrypted without the key
    }
  }
  return 0;
}
