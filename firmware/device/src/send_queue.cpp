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

std::span<std::byte> SendQueue::beginWrite() {
  const std::lock_guard lock(mutex_);
  assert(writing_ == nullptr);
  for (Slot& slot : slots_) {
    if (slot.state == State::kFree) {
      writing_ = &slot;
      break;
    }
  }
  if (writing_ == nullptr) {
    writing_ = oldestQueued();  // exists: at most one slot is being sent
    ++dropped_;
  }
  writing_->state = State::kWriting;
  return writing_->bytes;
}

void SendQueue::commit(std::size_t bytes) {
  const std::lock_guard lock(mutex_);
  assert(writing_ != nullptr && bytes <= slotBytes_);
  writing_->size = bytes;
  writing_->order = nextOrder_++;
  writing_->state = State::kQueued;
  writing_ = nullptr;
}

void SendQueue::abandon() {
  const std::lock_guard lock(mutex_);
  if (writing_ != nullptr) {
    writing_->state = State::kFree;
    writing_ = nullptr;
  }
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
