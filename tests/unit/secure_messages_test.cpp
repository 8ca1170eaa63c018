// The clear-text messages of the owner's channel: each round-trips, and a payload a byte short,
// a byte long or with a value out of range is refused.
#include "smx/protocol/secure_messages.hpp"

#include <gtest/gtest.h>

#include "smx/protocol/stream_parser.hpp"

namespace smx::protocol {
namespace {

Key32 key(std::uint8_t fill) {
  Key32 k{};
  k.fill(std::byte{fill});
  return k;
}

// The one message in `wire`, through the parser as a receiver sees it.
std::pair<MessageType, std::vector<std::byte>> parse(std::span<const std::byte> wire) {
  StreamParser parser(4096);
  EXPECT_EQ(parser.feed(wire), wire.size());
  const auto next = parser.next();
  EXPECT_TRUE(next && next->has_value());
  const Message& m = **next;
  return {m.type, {m.payload.begin(), m.payload.end()}};
}

TEST(SecureMessages, RoundTrip) {
  std::array<std::byte, 256> out{};
  const SecureHello hello{key(1), key(2)};
  auto [type, payload] = parse(*encodeSecureHello(MessageType::kSecureAccept, hello, out));
  EXPECT_EQ(type, MessageType::kSecureAccept);
  EXPECT_EQ(payload.size(), 64U);
  const auto h = decodeSecureHello(payload);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->ephemeral, key(1));
  EXPECT_EQ(h->identity, key(2));

  std::tie(type, payload) = parse(*encode(PairChallenge{key(3), key(4), key(5)}, out));
  EXPECT_EQ(type, MessageType::kPairChallenge);
  const auto c = decodePairChallenge(payload);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->proof, key(5));

  std::tie(type, payload) = parse(*encode(PairReady{3, 300, 8}, out));
  const auto r = decodePairReady(payload);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->secondsLeft, 300);
  EXPECT_FALSE(encodeSecureHello(MessageType::kHello, hello, out));
}

TEST(SecureMessages, WrongSizesAndValuesAreRefused) {
  std::vector<std::byte> bytes(64);
  EXPECT_TRUE(decodeSecureHello(bytes));
  EXPECT_TRUE(decodePairRequest(bytes));
  bytes.push_back(std::byte{0});
  EXPECT_FALSE(decodeSecureHello(bytes));
  EXPECT_FALSE(decodePairRequest(bytes));
  bytes.resize(63);
  EXPECT_FALSE(decodeSecureHello(bytes));
  EXPECT_FALSE(decodePairChallenge(bytes));
  EXPECT_FALSE(decodePairProof(std::span(bytes).first(31)));
  const std::array<std::byte, 4> ready{std::byte{4}, std::byte{1}, std::byte{0}, std::byte{8}};
  EXPECT_FALSE(decodePairReady(ready)) << "more attempts than a code has";
  const std::array<std::byte, 4> digits{std::byte{3}, std::byte{1}, std::byte{0}, std::byte{9}};
  EXPECT_FALSE(decodePairReady(digits));
}

}  // namespace
}  // namespace smx::protocol
