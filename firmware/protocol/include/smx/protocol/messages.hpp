#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "smx/algo/range_image.hpp"
#include "smx/protocol/wire.hpp"

// The messages of protocol version 1 (docs/protocol.md). Encoders write a whole message (header
// and payload) into a caller's buffer; decoders check a payload and return views into it, so
// neither side allocates per message. Strings are UTF-8 with a length prefix.
namespace smx::protocol {

enum class Compression : std::uint8_t { kNone = 0, kRvl = 1 };
[[nodiscard]] const char* toString(Compression compression);

struct Hello {
  std::string_view client;  // e.g. "stripemux 0.1.0"
};

struct Capabilities {
  std::string_view board;
  std::string_view firmwareVersion;
  std::string_view halBackend;  // "sim" or "linux"
  std::uint32_t depthUnitNm = 100'000;
  std::uint8_t cameras = 0;
  std::uint8_t projectors = 0;
  std::uint16_t width = 0;  // of every camera (the rig's cameras share one size on a board)
  std::uint16_t height = 0;
  std::uint16_t fps = 0;              // the capture rate the board aims at
  std::uint8_t compressionsMask = 0;  // bit (1 << Compression) for each one it can send
  std::string_view rigJson;           // the board's rig.json, stripemux-rig/1
};

struct StartStream {
  Compression compression = Compression::kRvl;
  // Ask for the merged confidence plane with each range frame (message kRangeFrameConfidence).
  // Off, the request is the one byte every device reads.
  bool confidence = false;
};

struct RangeFrameHeader {
  std::uint8_t camera = 0;  // index into the rig's cameras
  Compression compression = Compression::kRvl;
  std::uint16_t width = 0;
  std::uint16_t height = 0;
  std::uint64_t frame = 0;              // the device's frame number, from 0 at start-up
  std::int64_t captureTimestampNs = 0;  // device clock, start of exposure
  std::int64_t sentTimestampNs = 0;     // device clock, when the frame was queued for sending
  std::uint32_t depthUnitNm = 100'000;
  std::uint32_t decodeTimeUs = 0;  // the pipeline's time for this camera's frame
};

// A range frame as received: its header, the (possibly compressed) depth bytes and, in a
// kRangeFrameConfidence message, the confidence bytes (compressed as the depth is).
struct RangeFrameView {
  RangeFrameHeader header;
  std::span<const std::byte> depth;
  bool hasConfidence = false;
  std::span<const std::byte> confidence;
};

struct Statistics {
  std::uint64_t uptimeMs = 0;
  std::uint64_t framesCaptured = 0;  // camera frames acquired
  std::uint64_t framesDecoded = 0;   // range frames computed (one per camera per capture)
  std::uint64_t framesSent = 0;      // range frames fully handed to the link (this connection)
  std::uint64_t framesDropped = 0;   // dropped because the host was slow (this connection)
  std::uint64_t captureErrors = 0;   // timeouts, lost cameras
  std::uint64_t protocolErrors = 0;  // malformed messages received (this connection)
  std::uint32_t decodeTimeUsLast = 0;
  std::uint32_t decodeTimeUsMean = 0;
};

// Ask for one raw frame of every camera with exactly these projectors lit (bit i: the rig's
// projector i; 0: all off).
struct CaptureRaw {
  std::uint32_t projectorsMask = 0;
};

// One band of rows of one camera's raw frame (message kRawFrame): RGB8, rows × width pixels.
struct RawFrameHeader {
  std::uint8_t camera = 0;           // index into the rig's cameras
  std::uint32_t projectorsMask = 0;  // the projectors lit during the exposure
  std::uint16_t width = 0;           // of the whole frame
  std::uint16_t height = 0;
  std::uint16_t firstRow = 0;  // the band: rows firstRow … firstRow + rows - 1
  std::uint16_t rows = 0;
  std::uint64_t capture = 0;            // the device's raw capture number, from 0 at start-up
  std::int64_t captureTimestampNs = 0;  // device clock, the camera's frame timestamp
};

struct RawFrameView {
  RawFrameHeader header;
  std::span<const std::byte> pixels;  // rows × width × 3 bytes, r g b, row by row
};

inline constexpr std::size_t kRawFrameHeaderBytes = 29;
// A band carries at most this many bytes of pixels (and always at least one row), so a frame of
// any camera fits the receiver's payload limit in pieces that keep the host's buffer small.
inline constexpr std::size_t kRawBandPixelBytes = std::size_t{1} << 20U;

// Rows in each band of a frame `width` pixels wide (the last band may have fewer).
[[nodiscard]] constexpr int rawFrameBandRows(int width) {
  const std::size_t rowBytes = 3 * static_cast<std::size_t>(width < 1 ? 1 : width);
  return rowBytes >= kRawBandPixelBytes ? 1 : static_cast<int>(kRawBandPixelBytes / rowBytes);
}

// Bytes of every band message of one width × height frame, headers included.
[[nodiscard]] constexpr std::size_t rawFrameBound(int width, int height) {
  const int band = rawFrameBandRows(width);
  const auto bands = static_cast<std::size_t>((height + band - 1) / band);
  return bands * (kHeaderBytes + kRawFrameHeaderBytes) +
         3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

// The device's settings, a stripemux-config/1 document (docs/config.md): every setting in a
// config message, the ones to change in a set-config.
struct ConfigMessage {
  std::string_view json;
};

enum class SetConfigMode : std::uint8_t {
  kChange = 0,  // the document's settings replace the stored ones, the others stay
  kReset = 1,   // every stored setting is dropped first (the board's apply), then the document's
};

struct SetConfig {
  SetConfigMode mode = SetConfigMode::kChange;
  std::string_view json;  // may be empty with kReset
};

// The turntable's state (message kTurntable): the answer to get-turntable, and to turn-turntable
// once the move and its settle time are over.
struct TurntableState {
  bool present = false;  // false: the board has none (the other fields are 0)
  std::uint32_t stepsPerTurn = 0;
  std::int64_t position = 0;   // signed steps since start-up
  std::int64_t angleUdeg = 0;  // position · 360e6 / stepsPerTurn, rounded (micro-degrees)
  std::int64_t settledNs = 0;  // device clock at the end of the last settle; 0: no move yet
};
inline constexpr std::size_t kTurntablePayloadBytes = 29;

enum class TurnMode : std::uint8_t {
  kRelative = 0,  // turn by the angle
  kAbsolute = 1,  // turn to the angle (0: where the table stood at start-up)
};

struct TurnTurntable {
  TurnMode mode = TurnMode::kRelative;
  std::int64_t angleUdeg = 0;  // micro-degrees, right-handed about the rig's turntable axis
};

enum class ErrorCode : std::uint16_t {
  kUnsupportedVersion = 1,
  kBadRequest = 2,  // a malformed message or one not valid now (start before hello)
  kBusy = 3,        // another host is connected
  kInternal = 4,
  kNotPaired = 5,      // the device has an owner and this host is not one of its paired hosts
  kUpdateRefused = 6,  // a firmware bundle was refused (the text says why); nothing was installed
};

struct ErrorMessage {
  ErrorCode code = ErrorCode::kBadRequest;
  std::string_view text;
};

// Encoders: the whole message in `out`, or kBufferTooSmall.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const Hello& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const Capabilities& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const StartStream& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const Statistics& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const ErrorMessage& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const CaptureRaw& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const ConfigMessage& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const SetConfig& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const TurntableState& m,
                                                                std::span<std::byte> out);
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encode(const TurnTurntable& m,
                                                                std::span<std::byte> out);
// The band `header.firstRow`, `header.rows` of `image` as a raw-frame message; the header's
// width and height are taken from the image. kMalformed for a band outside the image.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encodeRawFrame(RawFrameHeader header,
                                                                        algo::ConstRgbView image,
                                                                        std::span<std::byte> out);
// A message without payload: stop-stream, get-statistics, get-config, get-turntable.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encodeEmpty(MessageType type,
                                                                     std::span<std::byte> out);
// A range frame of `depth` (width × height from the plane). RVL falls back to kNone when the
// compressed image would be larger than the raw one; the header says which was sent.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encodeRangeFrame(
    RangeFrameHeader header, algo::ConstDepthPlane depth, std::span<std::byte> out);
// The same with the confidence plane of the depth (a kRangeFrameConfidence message); both planes
// go RVL or both raw. kMalformed when the planes differ in size.
[[nodiscard]] ProtocolResult<std::span<const std::byte>> encodeRangeFrame(
    RangeFrameHeader header, algo::ConstDepthPlane depth,
    algo::ImageView<const std::uint8_t> confidence, std::span<std::byte> out);
// Bytes a range frame of that size needs at most, with or without its confidence plane.
[[nodiscard]] constexpr std::size_t rangeFrameBound(int width, int height,
                                                    bool withConfidence = false) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  return kHeaderBytes + 44 + (withConfidence ? 3 : 2) * pixels;
}

[[nodiscard]] ProtocolResult<Hello> decodeHello(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<Capabilities> decodeCapabilities(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<StartStream> decodeStartStream(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<Statistics> decodeStatistics(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<ErrorMessage> decodeError(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<void> decodeEmpty(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<CaptureRaw> decodeCaptureRaw(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<ConfigMessage> decodeConfig(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<SetConfig> decodeSetConfig(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<TurntableState> decodeTurntable(std::span<const std::byte> payload);
[[nodiscard]] ProtocolResult<TurnTurntable> decodeTurnTurntable(std::span<const std::byte> payload);
// Checks the band against its own frame size (inside it, pixels = rows × width × 3); the
// receiver checks the frame size against what the device announced.
[[nodiscard]] ProtocolResult<RawFrameView> decodeRawFrame(std::span<const std::byte> payload);
// The payload of a kRangeFrame or a kRangeFrameConfidence message (`type` says which).
[[nodiscard]] ProtocolResult<RangeFrameView> decodeRangeFrame(
    std::span<const std::byte> payload, MessageType type = MessageType::kRangeFrame);
// Expands a range frame's depth bytes into `out` (width × height values, row by row).
[[nodiscard]] ProtocolResult<void> decodeRangeDepth(const RangeFrameView& frame,
                                                    std::span<std::uint16_t> out);
// Expands its confidence bytes into `out` (width × height values, row by row).
[[nodiscard]] ProtocolResult<void> decodeRangeConfidence(const RangeFrameView& frame,
                                                         std::span<std::uint8_t> out);

}  // namespace smx::protocol
