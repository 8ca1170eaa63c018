#include "smx/device/send_queue.hpp"

#include <cassert>

namespace smx::device {

SendQueue::SendQueue(std::size_t slots, std::size_t slotBytes)
    : slots_(slots < 3 ? 3 : slots), slotBytes_(slotBytes) {
  // Three at least: one being written, one being sent, one queued.
  for (Slot& slot : slots_) {
    slot.bytes.resize(slotBytes);
  }
}

SendQueue::Slot* SendQueue::oldestQueued() {
  Slot* oldest = nullptr;
  for (Slot& slot : slots_) {
    if (slot.state == State::kQueued && (oldest == nullptr || slot.order < oldest->order)) {
      oldest = &slot;
    }
  }
  return oldest;
}

SendQueue::WriteSlot SendQueue::beginWrite() {
  const std::lock_guard lock(mutex_);
  Slot* writing = nullptr;
  for (Slot& slot : slots_) {
    if (slot.state == State::kFree) {
      writing = &slot;
      break;
    }
  }
  if (writing == nullptr) {
    writing = oldestQueued();  // exists while slots >= producers + 2
    assert(writing != nullptr);
    ++dropped_;
  }
  writing->state = State::kWriting;
  return {writing->bytes, static_cast<std::size_t>(writing - slots_.data())};
}

void SendQueue::commit(const WriteSlot& slot, std::size_t bytes) {
  const std::lock_guard lock(mutex_);
  Slot& written = slots_[slot.index];
  assert(written.state == State::kWriting && bytes <= slotBytes_);
  written.size = bytes;
  written.order = nextOrder_++;
  written.state = State::kQueued;
}

void SendQueue::abandon(const WriteSlot& slot) {
  const std::lock_guard lock(mutex_);
  slots_[slot.index].state = State::kFree;
}

std::span<const std::byte> SendQueue::beginSend() {
  const std::lock_guard lock(mutex_);
  assert(sending_ == nullptr);
  sending_ = oldestQueued();
  if (sending_ == nullptr) {
    return {};
  }
  sending_->state = State::kSending;
  return std::span<const std::byte>(sending_->bytes).first(sending_->size);
}

void SendQueue::finishSend() {
  const std::lock_guard lock(mutex_);
  if (sending_ != nullptr) {
    sending_->state = State::kFree;
    sending_ = nullptr;
  }
}

void SendQueue::clear() {
  const std::lock_guard lock(mutex_);
  for (Slot& slot : slots_) {
    if (slot.state == State::kQueued) {
      slot.state = State::kFree;
    }
  }
}

std::uint64_t SendQueue::dropped() const {
  const std::lock_guard lock(mutex_);
  return dropped_;
}

std::size_t SendQueue::queued() const {
  const std::lock_guard lock(mutex_);
  std::size_t count = 0;
  for (const Slot& slot : slots_) {
    count += slot.state == State::kQueued ? 1U : 0U;
  }
  return count;
}

}  // namespace smx::device
