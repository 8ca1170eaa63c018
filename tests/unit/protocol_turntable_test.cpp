// get-turntable, turntable and turn-turntable (docs/protocol.md, messages 29-31): the documented
// byte layout, round trips and malformed payloads refused.
#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <vector>

#include "smx/protocol/messages.hpp"

namespace smx::protocol {
namespace {

using Bytes = std::vector<std::byte>;

std::uint64_t readLe(std::span<const std::byte> bytes, std::size_t at, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) {
    value |= std::to_integer<std::uint64_t>(bytes[at + i]) << (8 * i);
  }
  return value;
}

TEST(TurntableMessages, TurntableIsPresentStepsPositionAngleSettled) {
  Bytes buffer(128);
  const TurntableState state{.present = true,
                             .stepsPerTurn = 3200,
                             .position = -800,
                             .angleUdeg = -90'000'000,
                             .settledNs = 0x0102030405060708};
  const auto message = encode(state, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(message->size(), kHeaderBytes + kTurntablePayloadBytes);
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 30);
  EXPECT_EQ(readLe(*message, kHeaderBytes, 1), 1U);
  EXPECT_EQ(readLe(*message, kHeaderBytes + 1, 4), 3200U);
  EXPECT_EQ(readLe(*message, kHeaderBytes + 5, 8), static_cast<std::uint64_t>(-800));
  EXPECT_EQ(readLe(*message, kHeaderBytes + 13, 8), static_cast<std::uint64_t>(-90'000'000));
  EXPECT_EQ(readLe(*message, kHeaderBytes + 21, 8), 0x0102030405060708U);
  const auto back = decodeTurntable(message->subspan(kHeaderBytes));
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->present);
  EXPECT_EQ(back->stepsPerTurn, 3200U);
  EXPECT_EQ(back->position, -800);
  EXPECT_EQ(back->angleUdeg, -90'000'000);
  EXPECT_EQ(back->settledNs, 0x0102030405060708);
}

TEST(TurntableMessages, TurnTurntableIsModeThenAngle) {
  Bytes buffer(64);
  const auto message = encode(TurnTurntable{TurnMode::kAbsolute, -45'500'000}, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(message->size(), kHeaderBytes + 9);
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 31);
  EXPECT_EQ(readLe(*message, kHeaderBytes, 1), 1U);
  EXPECT_EQ(readLe(*message, kHeaderBytes + 1, 8), static_cast<std::uint64_t>(-45'500'000));
  const auto back = decodeTurnTurntable(message->subspan(kHeaderBytes));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->mode, TurnMode::kAbsolute);
  EXPECT_EQ(back->angleUdeg, -45'500'000);

  const auto get = encodeEmpty(MessageType::kGetTurntable, buffer);
  ASSERT_TRUE(get.has_value());
  EXPECT_EQ(get->size(), kHeaderBytes);
  EXPECT_EQ(std::to_integer<int>((*get)[5]), 29);
  EXPECT_TRUE(isKnown(MessageType::kTurnTurntable));
  EXPECT_STREQ(toString(MessageType::kGetTurntable), "get-turntable");
}

TEST(TurntableMessages, MalformedPayloadsAreRefused) {
  Bytes buffer(128);
  const auto turn = encode(TurnTurntable{TurnMode::kRelative, 1}, buffer);
  ASSERT_TRUE(turn.has_value());
  Bytes payload(turn->begin() + kHeaderBytes, turn->end());
  EXPECT_FALSE(decodeTurnTurntable(std::span(payload).first(8)).has_value());
  payload.push_back(std::byte{0});
  EXPECT_FALSE(decodeTurnTurntable(payload).has_value());
  payload.pop_back();
  payload[0] = std::byte{2};  // no such mode
  EXPECT_FALSE(decodeTurnTurntable(payload).has_value());

  const auto state = encode(TurntableState{.present = true, .stepsPerTurn = 200}, buffer);
  ASSERT_TRUE(state.has_value());
  Bytes table(state->begin() + kHeaderBytes, state->end());
  EXPECT_TRUE(decodeTurntable(table).has_value());
  EXPECT_FALSE(decodeTurntable(std::span(table).first(28)).has_value());
  table[0] = std::byte{2};  // present is 0 or 1
  EXPECT_FALSE(decodeTurntable(table).has_value());
  table[0] = std::byte{1};
  table[1] = std::byte{0};  // a table of 0 steps per turn
  EXPECT_FALSE(decodeTurntable(table).has_value());
  // A board without a table: present 0, every field 0.
  const auto absent = encode(TurntableState{}, buffer);
  ASSERT_TRUE(absent.has_value());
  const auto decoded = decodeTurntable(absent->subspan(kHeaderBytes));
  ASSERT_TRUE(decoded.has_value());
  EXPECT_FALSE(decoded->present);
}

}  // namespace
}  // namespace smx::protocol
