// flash-begin, flash-data, flash-progress and update-status (docs/protocol.md, 15–20): the
// documented byte layout, written out by hand here, and malformed payloads refused.
#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "smx/protocol/update_messages.hpp"

namespace smx::protocol {
namespace {

using Bytes = std::vector<std::byte>;

Bytes bytes(std::initializer_list<int> values) {
  Bytes out;
  for (const int v : values) {
    out.push_back(static_cast<std::byte>(v));
  }
  return out;
}

void append(Bytes& out, std::string_view text) {
  out.push_back(static_cast<std::byte>(text.size() & 0xFFU));
  out.push_back(static_cast<std::byte>(text.size() >> 8U));
  for (const char c : text) {
    out.push_back(static_cast<std::byte>(c));
  }
}

TEST(UpdateMessages, FlashBeginIsTheSizeAsU64) {
  Bytes buffer(64);
  const auto message = encode(FlashBegin{0x0102030405ULL}, buffer);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 15);
  const Bytes payload(message->begin() + kHeaderBytes, message->end());
  EXPECT_EQ(payload, bytes({5, 4, 3, 2, 1, 0, 0, 0}));
  EXPECT_EQ(decodeFlashBegin(payload).value().size, 0x0102030405ULL);
  EXPECT_FALSE(decodeFlashBegin(bytes({1, 2, 3})).has_value());
}

TEST(UpdateMessages, FlashDataChunksAreOneTo32KiB) {
  EXPECT_FALSE(decodeFlashData({}).has_value());
  EXPECT_TRUE(decodeFlashData(Bytes(32768)).has_value());
  EXPECT_FALSE(decodeFlashData(Bytes(32769)).has_value());
}

TEST(UpdateMessages, FlashProgressIsStepBytesText) {
  Bytes buffer(128);
  const auto message = encode(FlashProgress{FlashStep::kVerified, 258, "ok"}, buffer);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 18);
  Bytes expected = bytes({2, 2, 1, 0, 0, 0, 0, 0, 0});
  append(expected, "ok");
  EXPECT_EQ(Bytes(message->begin() + kHeaderBytes, message->end()), expected);
  const auto back = decodeFlashProgress(expected);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->step, FlashStep::kVerified);
  EXPECT_EQ(back->bytes, 258U);
  EXPECT_EQ(back->text, "ok");
  for (const int step : {0, 6}) {
    Bytes bad = expected;
    bad[0] = static_cast<std::byte>(step);
    EXPECT_FALSE(decodeFlashProgress(bad).has_value()) << step;
  }
  expected.push_back(std::byte{0});
  EXPECT_FALSE(decodeFlashProgress(expected).has_value());
}

TEST(UpdateMessages, UpdateStatusIsOutcomeThenFourStrings) {
  Bytes expected = bytes({2});
  append(expected, "a");
  append(expected, "0.2.0");
  append(expected, "0.3.0");
  append(expected, "exited");
  Bytes buffer(128);
  const auto message =
      encode(UpdateStatus{UpdateOutcomeCode::kRolledBack, "a", "0.2.0", "0.3.0", "exited"}, buffer);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(std::to_integer<int>((*message)[5]), 20);
  EXPECT_EQ(Bytes(message->begin() + kHeaderBytes, message->end()), expected);
  const auto back = decodeUpdateStatus(expected);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->outcome, UpdateOutcomeCode::kRolledBack);
  EXPECT_EQ(back->runningSlot, "a");
  EXPECT_EQ(back->reason, "exited");
  expected[0] = std::byte{3};
  EXPECT_FALSE(decodeUpdateStatus(expected).has_value());
  EXPECT_FALSE(decodeUpdateStatus(bytes({1, 5, 0})).has_value());
}

}  // namespace
}  // namespace smx::protocol
