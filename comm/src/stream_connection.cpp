// SPDX-License-Identifier: MIT
// StreamConnection: the 2013 stream framing on one TCP socket.
#include "stream_connection.h"

#include <boost/asio/write.hpp>

namespace llsf::comm::detail {

namespace asio = boost::asio;

StreamConnection::StreamConnection(asio::ip::tcp::socket socket, const MessageRegistry& registry,
                                   std::int64_t max_payload, ClientId id, StreamCounters* counters,
                                   Sink sink)
    : socket_(std::move(socket)),
      registry_(&registry),
      decoder_(max_payload),
      id_(id),
      counters_(counters),
      sink_(std::move(sink)) {
  boost::system::error_code ec;
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);
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
  decoder_.feed(std::span<const std::uint8_t>(read_buffer_.data(), n));
  for (;;) {
    const StreamDecoder::Next next = decoder_.next();
    if (next.status == StreamDecoder::Next::Status::kNeedMore) return;
    if (next.status == StreamDecoder::Next::Status::kOversized) {
      ++counters_->malformed[static_cast<std::size_t>(FrameError::kOversized)];
      close();
      return;
    }
    MessageRegistry::Decoded d = registry_->decode(next.frame);
    if (d.error != FrameError::kNone) {
      ++counters_->malformed[static_cast<std::size_t>(d.error)];
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
  }
}

bool StreamConnection::send(const google::protobuf::Message& message) {
  if (!open_) return false;
  std::vector<std::uint8_t> frame;
  if (!registry_->encode(message, frame)) return false;
  ++counters_->frames_out;
  counters_->bytes_out += static_cast<std::int64_t>(frame.size());
  write_queue_.push_back(std::move(frame));
  if (!writing_) write_next();
  return true;
}

void StreamConnection::write_next() {
  if (!open_ || write_queue_.empty()) {
    writing_ = false;
    return;
  }
  writing_ = true;
  asio::async_write(socket_, asio::buffer(write_queue_.front()),
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      if (ec) {
                        self->close();
                        return;
                      }
                      self->write_queue_.pop_front();
                      self->write_next();
                    });
}

void StreamConnection::close() {
  if (!open_) return;
  open_ = false;
  boost::system::error_code ec;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ec);
  socket_.close(ec);
  write_queue_.clear();
  StreamEvent e;
  e.kind = StreamEvent::Kind::kDisconnected;
  e.client = id_;
  sink_(std::move(e));
}

}  // namespace llsf::comm::detail
