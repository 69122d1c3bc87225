// Serial and UDP byte streams over standalone Asio (byte_stream.h).
#include "pipeline/live/byte_stream.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <functional>
#include <system_error>

#include <asio.hpp>

namespace bifilar::live {
namespace {

// Runs `io` until the one pending operation completes or timeout_s passes; on a timeout the
// operation is cancelled and its handler run (it then reports operation_aborted, or its result
// when it completed in the meantime). `done` is set by the handler.
void RunWithTimeout(asio::io_context& io, double timeout_s, const bool& done,
                    const std::function<void()>& cancel) {
  const double wait_s = std::isfinite(timeout_s) ? std::clamp(timeout_s, 0.0, 1e6) : 1e6;
  io.restart();
  io.run_for(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(wait_s)));
  if (!done) {
    cancel();
    io.restart();
    io.run();
  }
}

class SerialStream : public ByteStream {
 public:
  SerialStream(std::string device, int baud) : device_(std::move(device)), baud_(baud) {}

  bool Open(std::string* error) {
    std::error_code ec;
    port_.open(device_, ec);
    if (ec) {
      *error = Describe() + ": cannot open: " + ec.message() +
               (ec.value() == EACCES
                    ? " (add the user to the dialout group: sudo usermod -aG dialout $USER)"
                    : "");
      return false;
    }
    port_.set_option(asio::serial_port::baud_rate(static_cast<unsigned>(baud_)), ec);
    if (ec) {
      *error = Describe() + ": the system does not know the baud rate " + std::to_string(baud_) +
               " (use a standard rate such as 57600, 115200, 921600)";
      return false;
    }
    port_.set_option(asio::serial_port::character_size(8), ec);
    if (!ec) port_.set_option(asio::serial_port::parity(asio::serial_port::parity::none), ec);
    if (!ec) {
      port_.set_option(asio::serial_port::stop_bits(asio::serial_port::stop_bits::one), ec);
    }
    if (!ec) {
      port_.set_option(asio::serial_port::flow_control(asio::serial_port::flow_control::none), ec);
    }
    if (ec) {
      *error = Describe() + ": cannot set 8N1 without flow control: " + ec.message();
      return false;
    }
    return true;
  }

  bool Read(std::string* chunk, double timeout_s, std::string* why) override {
    if (!port_.is_open()) {
      *why = closed_why_;
      return false;
    }
    bool done = false;
    std::error_code result;
    std::size_t got = 0;
    port_.async_read_some(asio::buffer(buffer_), [&](const std::error_code& ec, std::size_t n) {
      result = ec;
      got = n;
      done = true;
    });
    RunWithTimeout(io_, timeout_s, done, [this] {
      std::error_code ignored;
      port_.cancel(ignored);
    });
    chunk->append(buffer_.data(), got);
    if (!result || result == asio::error::operation_aborted) return true;
    closed_why_ =
        Describe() + ": " +
        (result == asio::error::eof ? std::string("end of stream (device closed)")
                                    : result.message() + " (device closed or unplugged?)");
    *why = closed_why_;
    std::error_code ignored;
    port_.close(ignored);
    return false;
  }

  std::string Describe() const override {
    return "serial " + device_ + " at " + std::to_string(baud_) + " baud";
  }

 private:
  std::string device_;
  int baud_;
  std::string closed_why_;  // why the port was closed (a read after that repeats it)
  asio::io_context io_;
  asio::serial_port port_{io_};
  std::array<char, kByteStreamMaxReadBytes> buffer_;
};

class UdpStream : public ByteStream {
 public:
  bool Open(const std::string& host, int port, std::string* error) {
    std::error_code ec;
    const asio::ip::address address = asio::ip::make_address(host, ec);
    if (ec) {
      *error = "udp " + host + ":" + std::to_string(port) + ": not an IP address (" + ec.message() +
               "); use 0.0.0.0 for every interface or 127.0.0.1";
      return false;
    }
    const asio::ip::udp::endpoint endpoint(address, static_cast<unsigned short>(port));
    socket_.open(endpoint.protocol(), ec);
    if (!ec) socket_.bind(endpoint, ec);
    if (ec) {
      *error =
          "udp " + host + ":" + std::to_string(port) + ": cannot bind: " + ec.message() +
          (ec.value() == EADDRINUSE ? " (another program, e.g. a ground station, holds the port)"
                                    : "");
      return false;
    }
    local_ = socket_.local_endpoint(ec);
    return true;
  }

  int port() const { return local_.port(); }

  bool Read(std::string* chunk, double timeout_s, std::string* why) override {
    bool done = false;
    std::error_code result;
    std::size_t got = 0;
    asio::ip::udp::endpoint sender;
    socket_.async_receive_from(asio::buffer(buffer_), sender,
                               [&](const std::error_code& ec, std::size_t n) {
                                 result = ec;
                                 got = n;
                                 done = true;
                               });
    RunWithTimeout(io_, timeout_s, done, [this] {
      std::error_code ignored;
      socket_.cancel(ignored);
    });
    if (result && result != asio::error::operation_aborted) {
      *why = Describe() + ": " + result.message();
      return false;
    }
    chunk->append(buffer_.data(), got);
    // The datagrams already queued, while they fit in this read.
    std::size_t total = got;
    std::error_code ec;
    while (total < kByteStreamMaxReadBytes) {
      const std::size_t available = socket_.available(ec);
      if (ec || available == 0 || total + available > kByteStreamMaxReadBytes) break;
      const std::size_t n = socket_.receive_from(asio::buffer(buffer_), sender, 0, ec);
      if (ec) break;
      chunk->append(buffer_.data(), n);
      total += n;
    }
    return true;
  }

  std::string Describe() const override {
    return "udp " + local_.address().to_string() + ":" + std::to_string(local_.port());
  }

 private:
  asio::io_context io_;
  asio::ip::udp::socket socket_{io_};
  asio::ip::udp::endpoint local_;
  std::array<char, kByteStreamMaxReadBytes> buffer_;
};

}  // namespace

std::unique_ptr<ByteStream> OpenSerial(const std::string& device, int baud, std::string* error) {
  if (baud <= 0) {
    *error = "serial " + device + ": the baud rate must be > 0, not " + std::to_string(baud);
    return nullptr;
  }
  auto stream = std::make_unique<SerialStream>(device, baud);
  if (!stream->Open(error)) return nullptr;
  return stream;
}

std::unique_ptr<ByteStream> OpenUdp(const std::string& bind_host, int port, int* bound_port,
                                    std::string* error) {
  if (port < 0 || port > 65535) {
    *error = "udp " + bind_host + ":" + std::to_string(port) + ": the port must be 1..65535";
    return nullptr;
  }
  auto stream = std::make_unique<UdpStream>();
  if (!stream->Open(bind_host, port, error)) return nullptr;
  if (bound_port != nullptr) *bound_port = stream->port();
  return stream;
}

std::unique_ptr<ByteStream> OpenUdp(const std::string& bind_host, int port, std::string* error) {
  return OpenUdp(bind_host, port, nullptr, error);
}

}  // namespace bifilar::live
