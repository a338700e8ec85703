// SPDX-License-Identifier: MIT
// StreamConnection: the 2013 stream framing on one TCP socket.
#include "stream_connection.h"

#include <boost/asio/write.hpp>
#include <cstdio>

namespace llsf::comm {

void log_to_stderr(std::string_view line) {
  std::fprintf(stderr, "llsf comm: %.*s\n", static_cast<int>(line.size()), line.data());
}

}  // namespace llsf::comm

namespace llsf::comm::detail {

namespace asio = boost::asio;

StreamConnection::StreamConnection(asio::ip::tcp::socket socket, const MessageRegistry& registry,
                                   Limits limits, ClientId id, StreamCounters* counters, Sink sink)
    : socket_(std::move(socket)),
      partial_timer_(socket_.get_executor()),
      registry_(&registry),
      limits_(std::move(limits)),
      decoder_(limits_.max_payload),
      id_(id),
      counters_(counters),
      sink_(std::move(sink)) {
  boost::system::error_code ec;
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);
  const auto ep = socket_.remote_endpoint(ec);
  peer_ = ec ? std::string("?") : ep.address().to_string() + ":" + std::to_string(ep.port());
}

void StreamConnection::start() { read(); }

void StreamConnection::read() {
  if (!open_) return;
  socket_.async_read_some(
      asio::buffer(read_buffer_),
      [self = shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
        if (ec) {
          self->close();
          return;
        }
        self->on_bytes(n);
        self->read();
      });
}

void StreamConnection::on_bytes(std::size_t n) {
  if (!open_) return;
  decoder_.feed(std::span<const std::uint8_t>(read_buffer_.data(), n));
  bool frame_done = false;
  for (;;) {
    const StreamDecoder::Next next = decoder_.next();
    if (next.status == StreamDecoder::Next::Status::kNeedMore) break;
    frame_done = true;
    if (next.status == StreamDecoder::Next::Status::kOversized) {
      ++counters_->malformed[static_cast<std::size_t>(FrameError::kOversized)];
      close_for("oversized", "a frame header announces more than " +
                                 std::to_string(limits_.max_payload) + " payload bytes");
      return;
    }
    MessageRegistry::Decoded d = registry_->decode(next.frame);
    if (d.error != FrameError::kNone) {
      ++counters_->malformed[static_cast<std::size_t>(d.error)];
      log_dropped(next.frame, d.error);
      continue;  // the framing is intact: skip this frame only
    }
    ++counters_->frames_in;
    counters_->bytes_in += kHeaderSize + next.frame.header.payload_size;
    StreamEvent e;
    e.kind = StreamEvent::Kind::kMessage;
    e.client = id_;
    e.key = d.key;
    e.message = std::move(d.message);
    sink_(std::move(e));
    if (!open_) return;  // the sink closed us
  }
  watch_partial_frame(frame_done);
}

void StreamConnection::log_dropped(const FrameView& frame, FrameError error) {
  // A tool speaking another dialect (other message numbers, another .proto) should see why its
  // frames do nothing, but a client sending garbage must not flood the log.
  if (!limits_.log || dropped_logged_ > kMaxDroppedLogged) return;
  if (dropped_logged_++ == kMaxDroppedLogged) {
    limits_.log("stream " + peer_ + ": more frames dropped; they are counted, not logged");
    return;
  }
  const std::string why =
      error == FrameError::kUnknownType  ? "no message type is registered under these numbers"
      : error == FrameError::kBadPayload ? "the payload does not parse as that type (a missing "
                                           "required field or another .proto)"
                                         : std::string(frame_error_name(error));
  limits_.log("stream " + peer_ + ": dropped a frame (component " +
              std::to_string(frame.header.key.component_id) + ", type " +
              std::to_string(frame.header.key.msg_type) + ", " +
              std::to_string(frame.header.payload_size) +
              " payload bytes): " + std::string(frame_error_name(error)) + ": " + why);
}

void StreamConnection::watch_partial_frame(bool frame_done) {
  if (limits_.partial_frame_timeout.count() <= 0) return;
  const bool partial = decoder_.buffered() > 0;
  // The frame under way keeps its first deadline, however slowly its bytes come; a frame that
  // starts after one completed gets a new one.
  if (partial == partial_watched_ && !(partial && frame_done)) return;
  partial_watched_ = partial;
  ++partial_generation_;
  if (!partial) {
    partial_timer_.cancel();
    return;
  }
  partial_timer_.expires_after(limits_.partial_frame_timeout);
  partial_timer_.async_wait([self = shared_from_this(), generation = partial_generation_](
                                const boost::system::error_code& ec) {
    if (ec || !self->open_ || generation != self->partial_generation_) return;
    self->close_for("partial_frame_timeout",
                    "a frame stayed incomplete for " +
                        std::to_string(self->limits_.partial_frame_timeout.count()) + " ms (" +
                        std::to_string(self->decoder_.buffered()) + " bytes buffered)");
  });
}

bool StreamConnection::send(const google::protobuf::Message& message) {
  if (!open_) return false;
  std::vector<std::uint8_t> frame;
  if (!registry_->encode(message, frame)) return false;
  const auto size = static_cast<std::int64_t>(frame.size());
  if (queued_bytes_ + size > limits_.max_send_queue_bytes) {
    close_for("send_queue_full", std::to_string(queued_bytes_) +
                                     " bytes not yet written, max_send_queue_bytes " +
                                     std::to_string(limits_.max_send_queue_bytes));
    return false;
  }
  ++counters_->frames_out;
  counters_->bytes_out += size;
  queued_bytes_ += size;
  write_queue_.push_back(std::move(frame));
  write_next();
  return true;
}

void StreamConnection::write_next() {
  if (!open_ || writing_ || write_queue_.empty()) return;
  // The frame under way leaves the queue now and is owned by in_flight_ until its completion
  // runs: close() drops only frames not yet started, never the buffer Asio writes from, and the
  // completion never touches the queue it did not take its frame from.
  writing_ = true;
  in_flight_ = std::move(write_queue_.front());
  write_queue_.pop_front();
  asio::async_write(socket_, asio::buffer(in_flight_),
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      self->on_written(ec);
                    });
}

void StreamConnection::on_written(const boost::system::error_code& ec) {
  writing_ = false;
  const auto written = static_cast<std::int64_t>(in_flight_.size());
  in_flight_.clear();
  // Closed meanwhile (by us, the peer or a limit): the queue was dropped; nothing to account.
  if (!open_) return;
  if (ec) {
    close();
    return;
  }
  queued_bytes_ -= written;
  write_next();
}

void StreamConnection::close_for(const char* reason, const std::string& detail) {
  if (!open_) return;
  counters_->closed_for = reason;
  if (limits_.log) limits_.log("stream " + peer_ + ": closed (" + reason + "): " + detail);
  close();
}

void StreamConnection::close() {
  if (!open_) return;
  open_ = false;
  boost::system::error_code ec;
  partial_timer_.cancel();
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ec);
  socket_.close(ec);  // pending reads, writes and waits complete with operation_aborted
  // Frames not yet started go; the one under way (in_flight_) stays until its completion.
  write_queue_.clear();
  queued_bytes_ = 0;
  StreamEvent e;
  e.kind = StreamEvent::Kind::kDisconnected;
  e.client = id_;
  sink_(std::move(e));
}

}  // namespace llsf::comm::detail
