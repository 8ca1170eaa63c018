#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "smx/protocol/secure_messages.hpp"
#include "smx/protocol/wire.hpp"

// The owner's encrypted channel (docs/security.md): session keys from the handshake, then each
// direction one crypto_secretstream_xchacha20poly1305 stream of records
//   u32 ciphertext length (little-endian) | ciphertext (plaintext + 17 bytes)
// after the stream's 24-byte header. The first record each way is the key confirmation. Buffers
// are allocated once at construction; a session and every record after it allocate nothing.
namespace smx::protocol {

enum class Role : std::uint8_t { kHost, kDevice };

struct KeyPair {
  Key32 publicKey{};
  Key32 secretKey{};
};

// A fresh X25519 key pair (crypto_kx); the public half of a secret key.
[[nodiscard]] KeyPair generateKeyPair();
[[nodiscard]] Key32 publicKeyOf(const Key32& secretKey);

struct SessionKeys {
  Key32 hostToDevice{};
  Key32 deviceToHost{};
  Key32 transcript{};  // BLAKE2b of both hellos: what the confirmations repeat
};

// BLAKE2b-512(X25519(e, e') ‖ X25519(s, s') ‖ transcript) split in two, the transcript being
// BLAKE2b-256 of a label and the host's then the device's ephemeral and static public keys.
// nullopt when a peer key is a low-order point (a shared secret of zeros).
[[nodiscard]] std::optional<SessionKeys> deriveSessionKeys(Role role, const KeyPair& ephemeral,
                                                           const KeyPair& identity,
                                                           const SecureHello& peer);

inline constexpr std::size_t kRecordPlainBytes = std::size_t{64} << 10U;
inline constexpr std::size_t kRecordTagBytes = 17;     // crypto_secretstream ABYTES
inline constexpr std::size_t kStreamHeaderBytes = 24;  // crypto_secretstream HEADERBYTES
inline constexpr std::size_t kRecordLengthBytes = 4;

// Both directions of one session on one side.
class SecureChannel {
 public:
  SecureChannel();
  ~SecureChannel();
  SecureChannel(const SecureChannel&) = delete;
  SecureChannel& operator=(const SecureChannel&) = delete;

  // Starts a session: the outgoing stream's header and key confirmation wait in pending().
  void start(const SessionKeys& keys, Role role);
  // Forgets the session (keys wiped).
  void reset();
  [[nodiscard]] bool started() const { return started_; }
  // The peer's key confirmation arrived and matched: its records can be trusted.
  [[nodiscard]] bool confirmed() const { return confirmed_; }

  // Encrypts up to kRecordPlainBytes of `plain` as one record when nothing is pending; returns
  // the plaintext bytes taken (0 while the previous record still waits to be sent).
  std::size_t seal(std::span<const std::byte> plain);
  // Ciphertext to send, and how much of it the socket took.
  [[nodiscard]] std::span<const std::byte> pending() const;
  void sent(std::size_t bytes);

  // Where received ciphertext goes: never more than the record being read still needs, so no
  // bytes of the next record are consumed early.
  [[nodiscard]] std::span<std::byte> writable();
  void commit(std::size_t bytes);
  // Copies decrypted bytes into `out`; 0 when a record is not complete yet. A record that fails
  // to decrypt (tampered, replayed, reordered, truncated, wrong key) or a bad confirmation is an
  // error, and the channel stays broken.
  [[nodiscard]] ProtocolResult<std::size_t> read(std::span<std::byte> out);
  [[nodiscard]] bool hasPlain() const { return plainBegin_ < plainEnd_; }

 private:
  struct State;
  [[nodiscard]] ProtocolResult<void> openRecord();
  std::size_t appendRecord(std::span<const std::byte> plain);

  std::unique_ptr<State> state_;
  Key32 transcript_{};
  bool started_ = false;
  bool confirmed_ = false;
  bool broken_ = false;
  std::vector<std::byte> out_;  // header and one record
  std::size_t outBegin_ = 0;
  std::size_t outEnd_ = 0;
  std::vector<std::byte> in_;  // the record (or header) being received
  std::size_t inHave_ = 0;
  std::size_t inNeed_ = 0;
  bool headerRead_ = false;
  bool lengthRead_ = false;
  std::vector<std::byte> plain_;
  std::size_t plainBegin_ = 0;
  std::size_t plainEnd_ = 0;
};

}  // namespace smx::protocol
