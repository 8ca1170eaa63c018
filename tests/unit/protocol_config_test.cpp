// get-config, config and set-config (docs/protocol.md): the documented byte layout and malformed
// payloads refused.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
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

std::string_view textAt(std::span<const std::byte> bytes, std::size_t at, std::size_t size) {
  return {reinterpret_cast<const char*>(bytes.data() + at), size};
}

TEST(ConfigMessages, SetConfigIsModeThenLengthPrefixedJson) {
  Bytes buffer(128);
  const std::string_view json = R"({"fps":10})";
  const auto message = encode(SetConfig{SetConfigMode::kReset, json}, buffer);
  ASSERT_TRUE(message.has_value());
  ASSERT_EQ(message->size(), kHeaderBytes + 1 + 4 + json.size());
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 14);  // the type byte
  EXPECT_EQ(readLe(*message, kHeaderBytes, 1), 1U);
  EXPECT_EQ(readLe(*message, kHeaderBytes + 1, 4), json.size());
  EXPECT_EQ(textAt(*message, kHeaderBytes + 5, json.size()), json);
  const auto back = decodeSetConfig(message->subspan(kHeaderBytes));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->mode, SetConfigMode::kReset);
  EXPECT_EQ(back->json, json);
}

TEST(ConfigMessages, ConfigIsLengthPrefixedJson) {
  Bytes buffer(128);
  const std::string_view json = R"({"format":"stripemux-config/1"})";
  const auto message = encode(ConfigMessage{json}, buffer);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 13);
  EXPECT_EQ(readLe(*message, kHeaderBytes, 4), json.size());
  const auto back = decodeConfig(message->subspan(kHeaderBytes));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->json, json);
  EXPECT_STREQ(toString(MessageType::kGetConfig), "get-config");
  EXPECT_TRUE(isKnown(MessageType::kSetConfig));
  EXPECT_FALSE(isKnown(static_cast<MessageType>(32)));
}

TEST(ConfigMessages, MalformedSetConfigIsRefused) {
  // An unknown mode, a length beyond the payload, bytes after the text.
  const std::array<std::byte, 5> unknownMode{std::byte{2}};
  EXPECT_FALSE(decodeSetConfig(unknownMode).has_value());
  const std::array<std::byte, 5> tooLong{std::byte{0}, std::byte{9}};
  EXPECT_FALSE(decodeSetConfig(tooLong).has_value());
  const std::array<std::byte, 7> trailing{std::byte{0},   std::byte{1},  {}, {}, {},
                                          std::byte{'x'}, std::byte{'y'}};
  EXPECT_FALSE(decodeSetConfig(trailing).has_value());
  const std::array<std::byte, 2> tooShort{};
  EXPECT_FALSE(decodeConfig(tooShort).has_value());
}

}  // namespace
}  // namespace smx::protocol
