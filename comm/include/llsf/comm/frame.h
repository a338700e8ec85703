// SPDX-License-Identifier: MIT
// The 2013 refbox frame protocol (llsf2013-rules.md §9.2): an 8-byte big-endian header
// (component id u16, message type u16, payload size u32) followed by the protobuf payload. One
// frame per UDP datagram (<= 1024 bytes); on TCP, frames follow each other in the byte stream.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace llsf::comm {

/// Size of the frame header in bytes.
inline constexpr int kHeaderSize = 8;
/// Largest UDP frame (header + payload) the 2013 tools send and receive, in bytes.
inline constexpr int kMaxDatagramSize = 1024;
/// Default largest TCP payload the stream decoder accepts, in bytes (the 2013 tools set no limit;
/// a bound keeps a bad size field from allocating gigabytes).
inline constexpr int kDefaultMaxStreamPayload = 1 << 20;

/// The (component id, message type) pair that identifies a message type on the wire.
struct MessageKey {
  int component_id = 0;
  int msg_type = 0;
  friend constexpr auto operator<=>(MessageKey, MessageKey) = default;
};

/// A decoded frame header.
struct FrameHeader {
  MessageKey key;
  std::int64_t payload_size = 0;  ///< bytes
};

/// Why a frame was rejected. kNone means it was accepted.
enum class FrameError {
  kNone,
  kShortHeader,   ///< fewer than 8 bytes
  kSizeMismatch,  ///< datagram length != 8 + payload size
  kOversized,     ///< larger than the allowed frame/payload size
  kUnknownType,   ///< (component id, message type) not in the registry
  kBadPayload,    ///< the payload does not parse as the registered message type
};
/// Number of FrameError values (for per-error counter arrays).
inline constexpr int kFrameErrorCount = 6;
/// "short_header", "size_mismatch", ... (as in statistics and docs/comm.md).
std::string_view frame_error_name(FrameError e);

/// Writes the 8-byte header for `key` and `payload_size` to `out` (which must hold 8 bytes).
/// Requires 0 <= component id, message type <= 65535 and 0 <= payload_size <= 2^32 - 1.
void write_header(std::span<std::uint8_t, kHeaderSize> out, MessageKey key,
                  std::int64_t payload_size);
/// Reads a header from the first 8 bytes of `in`; nullopt if `in` is shorter.
std::optional<FrameHeader> read_header(std::span<const std::uint8_t> in);

/// A frame split into header and payload (the payload points into the input).
struct FrameView {
  FrameHeader header;
  std::span<const std::uint8_t> payload;
};

/// Result of checking one datagram's framing (not yet its payload).
struct DatagramCheck {
  FrameError error = FrameError::kNone;
  FrameView frame;  ///< valid only if error == kNone
};

/// Checks that `datagram` is exactly one frame of at most `max_frame_bytes` bytes.
DatagramCheck check_datagram(std::span<const std::uint8_t> datagram,
                             int max_frame_bytes = kMaxDatagramSize);

/// Incremental TCP stream framing: feed bytes as they arrive (any split, even one byte at a
/// time) and take complete frames out. Reuses its buffer; copyable and movable.
class StreamDecoder {
 public:
  explicit StreamDecoder(std::int64_t max_payload = kDefaultMaxStreamPayload);

  /// Appends received bytes.
  void feed(std::span<const std::uint8_t> bytes);

  /// The result of next().
  struct Next {
    enum class Status {
      kNeedMore,   ///< no complete frame buffered
      kFrame,      ///< `frame` is the next frame; valid until the next feed()/next()
      kOversized,  ///< the header announces a payload > max_payload: the stream cannot be
                   ///< resynchronised and should be closed (the decoder stays in this state)
    };
    Status status = Status::kNeedMore;
    FrameView frame;
  };
  /// The next complete frame, if one is buffered.
  Next next();

  /// Bytes buffered but not yet returned as frames.
  std::int64_t buffered() const { return static_cast<std::int64_t>(buf_.size()) - pos_; }
  /// True after an oversized header (see Next::Status::kOversized).
  bool broken() const { return broken_; }

 private:
  std::vector<std::uint8_t> buf_;
  std::int64_t pos_ = 0;  ///< start of the first unreturned byte in buf_
  std::int64_t max_payload_;
  bool broken_ = false;
};

}  // namespace llsf::comm
