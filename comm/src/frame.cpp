// SPDX-License-Identifier: MIT
// The 2013 frame codec: header encoding, datagram checks and TCP stream framing.
#include "llsf/comm/frame.h"

#include <cstring>

#include "llsf/core/assert.h"

namespace llsf::comm {

namespace {
/// Buffer capacity a StreamDecoder keeps between frames (larger buffers are released).
constexpr std::size_t kKeptCapacity = 64 * 1024;
}  // namespace

std::string_view frame_error_name(FrameError e) {
  switch (e) {
    case FrameError::kNone:
      return "none";
    case FrameError::kShortHeader:
      return "short_header";
    case FrameError::kSizeMismatch:
      return "size_mismatch";
    case FrameError::kOversized:
      return "oversized";
    case FrameError::kUnknownType:
      return "unknown_type";
    case FrameError::kBadPayload:
      return "bad_payload";
  }
  return "?";
}

void write_header(std::span<std::uint8_t, kHeaderSize> out, MessageKey key,
                  std::int64_t payload_size) {
  LLSF_DEMAND(key.component_id >= 0 && key.component_id <= 0xffff);
  LLSF_DEMAND(key.msg_type >= 0 && key.msg_type <= 0xffff);
  LLSF_DEMAND(payload_size >= 0 && payload_size <= 0xffffffffLL);
  const auto comp = static_cast<std::uint32_t>(key.component_id);
  const auto type = static_cast<std::uint32_t>(key.msg_type);
  const auto size = static_cast<std::uint32_t>(payload_size);
  out[0] = static_cast<std::uint8_t>(comp >> 8);
  out[1] = static_cast<std::uint8_t>(comp);
  out[2] = static_cast<std::uint8_t>(type >> 8);
  out[3] = static_cast<std::uint8_t>(type);
  out[4] = static_cast<std::uint8_t>(size >> 24);
  out[5] = static_cast<std::uint8_t>(size >> 16);
  out[6] = static_cast<std::uint8_t>(size >> 8);
  out[7] = static_cast<std::uint8_t>(size);
}

std::optional<FrameHeader> read_header(std::span<const std::uint8_t> in) {
  if (in.size() < static_cast<std::size_t>(kHeaderSize)) return std::nullopt;
  FrameHeader h;
  h.key.component_id = (in[0] << 8) | in[1];
  h.key.msg_type = (in[2] << 8) | in[3];
  h.payload_size = (std::int64_t{in[4]} << 24) | (std::int64_t{in[5]} << 16) |
                   (std::int64_t{in[6]} << 8) | std::int64_t{in[7]};
  return h;
}

DatagramCheck check_datagram(std::span<const std::uint8_t> datagram, int max_frame_bytes) {
  DatagramCheck r;
  const auto h = read_header(datagram);
  if (!h) {
    r.error = FrameError::kShortHeader;
    return r;
  }
  const auto len = static_cast<std::int64_t>(datagram.size());
  // Oversized first: a datagram above the limit is refused whatever its header claims.
  if (len > max_frame_bytes || kHeaderSize + h->payload_size > max_frame_bytes) {
    r.error = FrameError::kOversized;
    return r;
  }
  if (len != kHeaderSize + h->payload_size) {
    r.error = FrameError::kSizeMismatch;
    return r;
  }
  r.frame.header = *h;
  r.frame.payload = datagram.subspan(kHeaderSize);
  return r;
}

// ---------------------------------------------------------------------------------------------
// StreamDecoder
// ---------------------------------------------------------------------------------------------

StreamDecoder::StreamDecoder(std::int64_t max_payload) : max_payload_(max_payload) {
  LLSF_DEMAND(max_payload >= 0);
}

void StreamDecoder::feed(std::span<const std::uint8_t> bytes) {
  if (broken_ || bytes.empty()) return;
  // Drop the bytes already returned before growing, so the buffer stays as small as the largest
  // partial frame (the previous frame's view is invalidated here, as documented).
  if (pos_ > 0) {
    buf_.erase(buf_.begin(), buf_.begin() + pos_);
    pos_ = 0;
    // After a large frame, give its memory back instead of keeping it per connection.
    if (buf_.empty() && buf_.capacity() > kKeptCapacity) std::vector<std::uint8_t>().swap(buf_);
  }
  buf_.insert(buf_.end(), bytes.begin(), bytes.end());
}

StreamDecoder::Next StreamDecoder::next() {
  Next n;
  if (broken_) {
    n.status = Next::Status::kOversized;
    return n;
  }
  const std::span<const std::uint8_t> rest(buf_.data() + pos_, buf_.size() - pos_);
  const auto h = read_header(rest);
  if (!h) return n;
  if (h->payload_size > max_payload_) {
    broken_ = true;
    buf_.clear();
    pos_ = 0;
    n.status = Next::Status::kOversized;
    return n;
  }
  const std::int64_t total = kHeaderSize + h->payload_size;
  if (static_cast<std::int64_t>(rest.size()) < total) return n;
  n.status = Next::Status::kFrame;
  n.frame.header = *h;
  n.frame.payload = rest.subspan(kHeaderSize, static_cast<std::size_t>(h->payload_size));
  pos_ += total;
  return n;
}

}  // namespace llsf::comm
