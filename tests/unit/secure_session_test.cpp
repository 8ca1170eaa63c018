// The owner's channel: both sides of the handshake agree on keys (checked against the formula
// computed here with libsodium directly), records carry bytes across any split of the stream,
// and a wrong key, a tampered, replayed or truncated record never yields plaintext.
#include "smx/protocol/secure_session.hpp"

#include <gtest/gtest.h>
#include <sodium.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <vector>

namespace smx::protocol {
namespace {

using Bytes = std::vector<std::byte>;

struct Side {
  KeyPair identity = generateKeyPair();
  KeyPair ephemeral = generateKeyPair();
  [[nodiscard]] SecureHello hello() const { return {ephemeral.publicKey, identity.publicKey}; }
};

Bytes pattern(std::size_t n, unsigned seed) {
  Bytes bytes(n);
  for (std::size_t i = 0; i < n; ++i) {
    bytes[i] = static_cast<std::byte>((i * 131 + seed) & 0xFFU);
  }
  return bytes;
}

// Everything `from` has to send, sealing `plain` in records after the confirmation.
Bytes wireBytes(SecureChannel& from, std::span<const std::byte> plain) {
  Bytes wire;
  const auto drain = [&] {
    const auto pending = from.pending();
    wire.insert(wire.end(), pending.begin(), pending.end());
    from.sent(pending.size());
  };
  drain();
  std::size_t done = 0;
  while (done < plain.size()) {
    done += from.seal(plain.subspan(done));
    drain();
  }
  return wire;
}

// Feeds `wire` to `to` in pieces of `chunk` bytes; what it decrypts, or the error.
ProtocolResult<Bytes> receive(SecureChannel& to, std::span<const std::byte> wire,
                              std::size_t chunk) {
  Bytes plain;
  std::array<std::byte, 1000> out{};
  std::size_t at = 0;
  while (true) {
    const auto got = to.read(out);
    if (!got) {
      return std::unexpected(got.error());
    }
    plain.insert(plain.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(*got));
    if (*got > 0) {
      continue;
    }
    const auto space = to.writable();
    if (space.empty()) {
      continue;  // a unit is complete: read() opens it
    }
    if (at == wire.size()) {
      return plain;
    }
    const std::size_t n = std::min({chunk, space.size(), wire.size() - at});
    std::memcpy(space.data(), wire.data() + at, n);
    to.commit(n);
    at += n;
  }
}

struct Session {
  Side host;
  Side device;
  SecureChannel hostChannel;
  SecureChannel deviceChannel;
  Session() {
    const auto hostKeys =
        deriveSessionKeys(Role::kHost, host.ephemeral, host.identity, device.hello());
    const auto deviceKeys =
        deriveSessionKeys(Role::kDevice, device.ephemeral, device.identity, host.hello());
    EXPECT_TRUE(hostKeys && deviceKeys);
    hostChannel.start(*hostKeys, Role::kHost);
    deviceChannel.start(*deviceKeys, Role::kDevice);
  }
};

TEST(SecureSession, KeysFollowTheDocumentedFormula) {
  const Side host;
  const Side device;
  const auto keys = deriveSessionKeys(Role::kHost, host.ephemeral, host.identity, device.hello());
  ASSERT_TRUE(keys);
  // docs/security.md: transcript = BLAKE2b-256(label ‖ e_h ‖ s_h ‖ e_d ‖ s_d), keys =
  // BLAKE2b-512(DH(e_h, e_d) ‖ DH(s_h, s_d) ‖ transcript), host→device first.
  std::vector<unsigned char> t;
  const std::string label = "stripemux secure session 1";
  t.insert(t.end(), label.begin(), label.end());
  for (const Key32* k : {&host.ephemeral.publicKey, &host.identity.publicKey,
                         &device.ephemeral.publicKey, &device.identity.publicKey}) {
    const auto* p = reinterpret_cast<const unsigned char*>(k->data());
    t.insert(t.end(), p, p + 32);
  }
  std::array<unsigned char, 32> transcript{};
  crypto_generichash(transcript.data(), 32, t.data(), t.size(), nullptr, 0);
  std::array<unsigned char, 96> input{};
  ASSERT_EQ(
      crypto_scalarmult(input.data(),
                        reinterpret_cast<const unsigned char*>(device.ephemeral.secretKey.data()),
                        reinterpret_cast<const unsigned char*>(host.ephemeral.publicKey.data())),
      0);
  ASSERT_EQ(
      crypto_scalarmult(input.data() + 32,
                        reinterpret_cast<const unsigned char*>(device.identity.secretKey.data()),
                        reinterpret_cast<const unsigned char*>(host.identity.publicKey.data())),
      0);
  std::copy(transcript.begin(), transcript.end(), input.begin() + 64);
  std::array<unsigned char, 64> material{};
  crypto_generichash(material.data(), 64, input.data(), input.size(), nullptr, 0);
  EXPECT_EQ(std::memcmp(keys->transcript.data(), transcript.data(), 32), 0);
  EXPECT_EQ(std::memcmp(keys->hostToDevice.data(), material.data(), 32), 0);
  EXPECT_EQ(std::memcmp(keys->deviceToHost.data(), material.data() + 32, 32), 0);
}

TEST(SecureSession, BothDirectionsCarryBytes) {
  Session s;
  const Bytes toDevice = pattern(200'000, 1);
  const Bytes toHost = pattern(3 * kRecordPlainBytes + 5, 2);
  const auto atDevice = receive(s.deviceChannel, wireBytes(s.hostChannel, toDevice), 4096);
  const auto atHost = receive(s.hostChannel, wireBytes(s.deviceChannel, toHost), 70'000);
  ASSERT_TRUE(atDevice) << atDevice.error().message;
  ASSERT_TRUE(atHost) << atHost.error().message;
  EXPECT_EQ(*atDevice, toDevice);
  EXPECT_EQ(*atHost, toHost);
  EXPECT_TRUE(s.deviceChannel.confirmed());
  EXPECT_TRUE(s.hostChannel.confirmed());
}

TEST(SecureSession, EverySplitOfTheStreamGivesTheSameBytes) {
  // Header, confirmation and two records, cut in two at every byte.
  const Bytes plain = pattern(300, 7);
  const Bytes more = pattern(40, 9);
  Bytes expected = plain;
  expected.insert(expected.end(), more.begin(), more.end());
  std::size_t wireSize = 0;
  for (std::size_t split = 1; split == 1 || split < wireSize; ++split) {
    Session s;
    Bytes w = wireBytes(s.hostChannel, plain);
    const Bytes w2 = wireBytes(s.hostChannel, more);
    w.insert(w.end(), w2.begin(), w2.end());
    wireSize = w.size();
    const auto head = receive(s.deviceChannel, std::span(w).first(split), split);
    ASSERT_TRUE(head) << split;
    const auto tail = receive(s.deviceChannel, std::span(w).subspan(split), 1);
    ASSERT_TRUE(tail) << split;
    Bytes all = *head;
    all.insert(all.end(), tail->begin(), tail->end());
    ASSERT_EQ(all, expected) << "split at " << split;
  }
}

TEST(SecureSession, AWrongStaticKeyFailsTheConfirmation) {
  const Side host;
  const Side device;
  const Side impostor;  // has the host's public key but not its secret
  const auto deviceKeys =
      deriveSessionKeys(Role::kDevice, device.ephemeral, device.identity,
                        SecureHello{impostor.ephemeral.publicKey, host.identity.publicKey});
  // It announces the host's public key with a secret of its own.
  const KeyPair claimed{host.identity.publicKey, impostor.identity.secretKey};
  const auto impostorKeys =
      deriveSessionKeys(Role::kHost, impostor.ephemeral, claimed, device.hello());
  SecureChannel atDevice;
  SecureChannel fromImpostor;
  atDevice.start(*deviceKeys, Role::kDevice);
  fromImpostor.start(*impostorKeys, Role::kHost);
  const auto got = receive(atDevice, wireBytes(fromImpostor, pattern(10, 3)), 1000);
  EXPECT_FALSE(got);
  EXPECT_FALSE(atDevice.confirmed());
}

TEST(SecureSession, LowOrderPeerKeysAreRefused) {
  const Side side;
  const SecureHello zero{};
  EXPECT_FALSE(deriveSessionKeys(Role::kHost, side.ephemeral, side.identity, zero));
}

TEST(SecureSession, EveryTamperedByteIsRefused) {
  Session s;
  const Bytes wire = wireBytes(s.hostChannel, pattern(100, 5));
  for (std::size_t i = 0; i < wire.size(); ++i) {
    Session t;
    t.deviceChannel.start(
        *deriveSessionKeys(Role::kDevice, s.device.ephemeral, s.device.identity, s.host.hello()),
        Role::kDevice);
    Bytes bad = wire;
    bad[i] ^= std::byte{0x01};
    const auto got = receive(t.deviceChannel, bad, 64);
    // A flipped length may leave the receiver waiting for more: never plaintext.
    EXPECT_TRUE(!got || got->empty()) << "byte " << i;
  }
}

TEST(SecureSession, ReplayedReorderedAndTruncatedRecordsAreRefused) {
  Session s;
  const Bytes confirm = wireBytes(s.hostChannel, {});
  const Bytes one = wireBytes(s.hostChannel, pattern(50, 1));
  const Bytes two = wireBytes(s.hostChannel, pattern(60, 2));
  const auto fresh = [&] {
    auto channel = std::make_unique<SecureChannel>();
    channel->start(
        *deriveSessionKeys(Role::kDevice, s.device.ephemeral, s.device.identity, s.host.hello()),
        Role::kDevice);
    return channel;
  };
  const auto join = [](std::initializer_list<const Bytes*> parts) {
    Bytes all;
    for (const Bytes* p : parts) {
      all.insert(all.end(), p->begin(), p->end());
    }
    return all;
  };
  auto good = fresh();
  const auto inOrder = receive(*good, join({&confirm, &one, &two}), 17);
  ASSERT_TRUE(inOrder);
  EXPECT_EQ(inOrder->size(), 110U);
  auto replay = fresh();
  const auto replayed = receive(*replay, join({&confirm, &one, &one}), 17);
  EXPECT_FALSE(replayed);
  auto reorder = fresh();
  EXPECT_FALSE(receive(*reorder, join({&confirm, &two, &one}), 17));
  auto skip = fresh();
  EXPECT_FALSE(receive(*skip, join({&one, &two}), 17));  // no confirmation first
  auto truncated = fresh();
  const Bytes cut = join({&confirm, &one});
  const auto part = receive(*truncated, std::span(cut).first(cut.size() - 1), 17);
  ASSERT_TRUE(part);
  EXPECT_TRUE(part->empty());  // a record's plaintext is released only when it is whole
  // Another session's records (a recorded connection replayed) fail under fresh keys.
  Session other;
  EXPECT_FALSE(receive(other.deviceChannel, join({&confirm, &one}), 17));
}

}  // namespace
}  // namespace smx::protocol
