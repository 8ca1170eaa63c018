#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "smx/protocol/wire.hpp"

// Cuts a received byte stream into messages and checks their framing (magic, version, type,
// length limit, CRC). Bytes go in through writable()/commit(); next() returns complete messages.
// A bad message is reported once and skipped: the parser then searches the stream for the next
// magic, so every error consumes at least one byte and garbage can neither crash nor stall it.
// The buffer is allocated once, at construction; nothing else allocates.
namespace smx::protocol {

struct ParserCounters {
  std::uint64_t messages = 0;      // good messages returned
  std::uint64_t errors = 0;        // bad messages and stretches of garbage, each counted once
  std::uint64_t bytesSkipped = 0;  // bytes thrown away while resynchronising
};

class StreamParser {
 public:
  // `maxPayloadBytes`: the largest payload this receiver accepts (kOversized above it).
  explicit StreamParser(std::size_t maxPayloadBytes);

  // Where to put received bytes; never empty after next() returned "need more bytes".
  [[nodiscard]] std::span<std::byte> writable();
  void commit(std::size_t bytes);
  // Convenience for tests and tools: copies as much of `bytes` as fits, returns how much.
  std::size_t feed(std::span<const std::byte> bytes);

  // The next message (its payload valid until the next call of next(), writable() or feed()),
  // std::nullopt when more bytes are needed, or the error that made it skip bytes.
  [[nodiscard]] ProtocolResult<std::optional<Message>> next();

  [[nodiscard]] const ParserCounters& counters() const { return counters_; }
  // Forgets buffered bytes (a new connection).
  void reset();

 private:
  [[nodiscard]] std::span<const std::byte> buffered() const;
  std::unexpected<ProtocolError> skipAfterError(ProtocolErrc code, const char* message);

  std::vector<std::byte> buffer_;
  std::size_t maxPayloadBytes_;
  std::size_t begin_ = 0;  // first unread byte
  std::size_t end_ = 0;    // one past the last received byte
  ParserCounters counters_;
};

}  // namespace smx::protocol
