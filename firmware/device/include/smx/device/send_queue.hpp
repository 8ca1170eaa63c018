#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

// The bounded queue between the capture loop's decoders (producers, one per camera) and the
// network thread (consumer). The slots are allocated once; a message is written in place. When
// the host is slow and every slot is taken, a producer takes the oldest queued message's slot:
// that frame is dropped and counted, and capture never waits for the network. Slots being
// written or sent are never taken; there must be at least producers + 2 slots.
namespace smx::device {

class SendQueue {
 public:
  SendQueue(std::size_t slots, std::size_t slotBytes);

  struct WriteSlot {
    std::span<std::byte> bytes;
    std::size_t index = 0;
  };
  // Producer: a slot to write one message into (taking the oldest queued one if none is free),
  // then commit() it with the message's size, or abandon() it.
  [[nodiscard]] WriteSlot beginWrite();
  void commit(const WriteSlot& slot, std::size_t bytes);
  void abandon(const WriteSlot& slot);

  // Consumer: the oldest queued message, now being sent (empty if none), then finishSend().
  [[nodiscard]] std::span<const std::byte> beginSend();
  void finishSend();

  // Drops everything queued (not what is being written or sent): the host went away.
  void clear();

  [[nodiscard]] std::uint64_t dropped() const;
  [[nodiscard]] std::size_t queued() const;
  [[nodiscard]] std::size_t slotBytes() const { return slotBytes_; }

 private:
  enum class State : std::uint8_t { kFree, kWriting, kQueued, kSending };
  struct Slot {
    std::vector<std::byte> bytes;
    std::size_t size = 0;
    std::uint64_t order = 0;  // when it was queued
    State state = State::kFree;
  };

  Slot* oldestQueued();

  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::size_t slotBytes_;
  Slot* sending_ = nullptr;
  std::uint64_t nextOrder_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace smx::device
