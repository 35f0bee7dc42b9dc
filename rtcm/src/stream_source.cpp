#include "gvins/rtcm/stream_source.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include "gvins/rtcm/ntrip_client.hpp"
#include "tcp_socket.hpp"

namespace gvins::rtcm {

namespace {

using detail::closeFd;
using detail::pollMs;
using detail::waitReadable;
using Clock = StreamSource::Clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
Clock::duration duration(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

/// read(2)/recv(2) of what is there: > 0 bytes, 0 timeout, -1 end or error (`why` set).
long readFd(int fd, std::vector<std::uint8_t>& out, double timeout, bool socket, std::string& why) {
  if (!waitReadable(fd, timeout)) return 0;
  std::uint8_t buf[16384];
  for (;;) {
    const ssize_t n = socket ? ::recv(fd, buf, sizeof buf, 0) : ::read(fd, buf, sizeof buf);
    if (n > 0) {
      out.insert(out.end(), buf, buf + n);
      return n;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 0;
    why = n == 0 ? "closed by the peer" : std::strerror(errno);
    return -1;
  }
}


class FileSource final : public StreamSource {
 public:
  FileSource(const StreamUrl& u, StreamOptions o, bool stdinput)
      : StreamSource(u.display(), std::move(o), false), path_(u.path), stdin_(stdinput) {
    if (stdin_) {
      fd_ = STDIN_FILENO;
    } else {
      fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd_ < 0) throw StreamError("stream '" + name() + "': cannot open '" + path_ + "': " + std::strerror(errno));
    }
  }
  ~FileSource() override {
    if (!stdin_) closeFd(fd_);
  }

 protected:
  void connect(double) override {
    if (fd_ < 0) throw StreamError("stream '" + name() + "' is closed");
  }
  long readSome(std::vector<std::uint8_t>& out, double timeout) override {
    std::string why;
    const long n = readFd(fd_, out, timeout, false, why);
    return n < 0 ? -1 : n;
  }
  void disconnect() override {}

 private:
  std::string path_;
  bool stdin_;
  int fd_ = -1;
};

class TcpClientSource final : public StreamSource {
 public:
  TcpClientSource(const StreamUrl& u, StreamOptions o) : StreamSource(u.display(), std::move(o), true), host_(u.host), port_(u.port) {}
  ~TcpClientSource() override { closeFd(fd_); }
  bool send(const std::string& b) override {
    return fd_ >= 0 && ::send(fd_, b.data(), b.size(), MSG_NOSIGNAL | MSG_DONTWAIT) == static_cast<ssize_t>(b.size());
  }

 protected:
  void connect(double timeout) override {
    std::string err;
    fd_ = detail::connectTcp(host_, port_, timeout, err);
    if (fd_ < 0) throw StreamError(err);
  }
  long readSome(std::vector<std::uint8_t>& out, double timeout) override {
    const long n = readFd(fd_, out, timeout, true, why_);
    if (n < 0) event("connection lost: " + why_);
    return n;
  }
  void disconnect() override { closeFd(fd_); }

 private:
  std::string host_;
  int port_;
  int fd_ = -1;
  std::string why_;
};

class TcpServerSource final : public StreamSource {
 public:
  TcpServerSource(const StreamUrl& u, StreamOptions o) : StreamSource(u.display(), std::move(o), true) {
    std::string err;
    listen_ = detail::listenTcp(u.host, u.port, 1, err);
    if (listen_ < 0) throw StreamError("stream '" + name() + "': " + err);
    port_ = detail::boundPort(listen_);
  }
  ~TcpServerSource() override {
    closeFd(fd_);
    closeFd(listen_);
  }
  int boundPort() const override { return port_; }
  bool send(const std::string& b) override {
    return fd_ >= 0 && ::send(fd_, b.data(), b.size(), MSG_NOSIGNAL | MSG_DONTWAIT) == static_cast<ssize_t>(b.size());
  }

 protected:
  void connect(double timeout) override {
    if (!waitReadable(listen_, timeout)) throw StreamError("no client connected to port " + std::to_string(port_));
    fd_ = ::accept4(listen_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd_ < 0) throw StreamError(std::string("accept failed: ") + std::strerror(errno));
  }
  long readSome(std::vector<std::uint8_t>& out, double timeout) override {
    const long n = readFd(fd_, out, timeout, true, why_);
    if (n < 0) event("client lost: " + why_);
    return n;
  }
  void disconnect() override { closeFd(fd_); }

 private:
  int listen_ = -1, fd_ = -1, port_ = 0;
  std::string why_;
};

speed_t baudConstant(int baud) {
  switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    default: return B0;
  }
}

class SerialSource final : public StreamSource {
 public:
  SerialSource(const StreamUrl& u, StreamOptions o) : StreamSource(u.display(), std::move(o), true), dev_(u.path), baud_(u.baud) {}
  ~SerialSource() override { closeFd(fd_); }
  bool send(const std::string& b) override {
    return fd_ >= 0 && ::write(fd_, b.data(), b.size()) == static_cast<ssize_t>(b.size());
  }

 protected:
  void connect(double) override {
    const int fd = ::open(dev_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw StreamError("cannot open serial device " + dev_ + ": " + std::strerror(errno));
    termios t{};
    if (::tcgetattr(fd, &t) != 0) {
      const std::string e = std::strerror(errno);
      ::close(fd);
      throw StreamError(dev_ + " is not a serial port (" + e + ")");
    }
    // Raw bytes, 8 data bits, no parity, one stop bit, no flow control (POSIX termios).
    ::cfmakeraw(&t);
    t.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
    t.c_cflag |= CS8 | CLOCAL | CREAD;
    t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    ::cfsetispeed(&t, baudConstant(baud_));
    ::cfsetospeed(&t, baudConstant(baud_));
    if (::tcsetattr(fd, TCSANOW, &t) != 0) {
      const std::string e = std::strerror(errno);
      ::close(fd);
      throw StreamError("cannot set " + std::to_string(baud_) + " baud 8N1 on " + dev_ + ": " + e);
    }
    fd_ = fd;
  }
  long readSome(std::vector<std::uint8_t>& out, double timeout) override {
    pollfd p{fd_, POLLIN, 0};
    int rc;
    do rc = ::poll(&p, 1, pollMs(timeout));
    while (rc < 0 && errno == EINTR);
    if (rc == 0) return 0;
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL) && !(p.revents & POLLIN)) {
      event("device hung up");
      return -1;
    }
    const long n = readFd(fd_, out, 0.0, false, why_);
    if (n < 0) event("device read failed: " + why_);
    return n;
  }
  void disconnect() override { closeFd(fd_); }

 private:
  std::string dev_;
  int baud_;
  int fd_ = -1;
  std::string why_;
};

class NtripSource final : public StreamSource {
 public:
  NtripSource(const StreamUrl& u, StreamOptions o) : StreamSource(u.ntrip.display(), o, true), client_(u.ntrip, ntripOptions(o)) {}
  bool send(const std::string& b) override { return client_.send(b); }

 protected:
  void connect(double) override {
    if (options().gga) client_.setGga(trimmed(options().gga()));
    try {
      client_.connect();
    } catch (const NtripError& e) {
      throw StreamError(e.what());
    }
    lastGga_ = Clock::now();
  }
  long readSome(std::vector<std::uint8_t>& out, double timeout) override {
    client_.setReadTimeout(std::max(timeout, 1e-3));
    try {
      const std::size_t n = client_.read(out);
      if (n == 0) {
        event("caster ended the stream");
        return -1;
      }
      return static_cast<long>(n);
    } catch (const NtripError& e) {
      if (e.kind() == NtripError::Kind::Timeout) return 0;
      event(e.what());
      return -1;
    }
  }
  void afterRead() override {
    if (!options().gga || options().ggaInterval <= 0.0) return;
    const auto now = Clock::now();
    if (seconds(now - lastGga_) < options().ggaInterval) return;
    lastGga_ = now;
    const std::string g = options().gga();
    if (!g.empty()) client_.send(g);
  }
  void disconnect() override { client_.close(); }

 private:
  static NtripOptions ntripOptions(const StreamOptions& o) {
    NtripOptions n;
    n.connectTimeout = o.connectTimeout;
    return n;
  }
  static std::string trimmed(std::string s) {
    while (!s.empty() && (s.back() == '\r' || s.back() == '\n')) s.pop_back();
    return s;
  }
  NtripClient client_;
  Clock::time_point lastGga_{};
};

}  // namespace

StreamSource::StreamSource(std::string name, StreamOptions options, bool reconnectable)
    : name_(std::move(name)), opt_(std::move(options)), reconnectable_(reconnectable), backoff_(opt_.retryInitial) {}

StreamSource::~StreamSource() = default;

std::unique_ptr<StreamSource> StreamSource::open(const StreamUrl& url, StreamOptions options) {
  switch (url.type) {
    case StreamType::File: return std::make_unique<FileSource>(url, std::move(options), false);
    case StreamType::Stdin: return std::make_unique<FileSource>(url, std::move(options), true);
    case StreamType::TcpClient: return std::make_unique<TcpClientSource>(url, std::move(options));
    case StreamType::TcpServer: return std::make_unique<TcpServerSource>(url, std::move(options));
    case StreamType::Serial: return std::make_unique<SerialSource>(url, std::move(options));
    case StreamType::Ntrip: return std::make_unique<NtripSource>(url, std::move(options));
  }
  throw StreamError("unknown stream type");
}

bool StreamSource::send(const std::string&) { return false; }

std::vector<std::string> StreamSource::takeEvents() {
  std::vector<std::string> e;
  e.swap(events_);
  return e;
}

void StreamSource::dropped(const std::string& why) {
  disconnect();
  connected_ = false;
  ++counters_.drops;
  outage_ = true;
  outageStart_ = Clock::now();
  nextAttempt_ = outageStart_ + duration(backoff_);
  event("dropped (" + why + "), gap " + std::to_string(counters_.drops) + "; reconnecting");
}

StreamSource::Status StreamSource::read(std::vector<std::uint8_t>& out, double timeout) {
  if (ended_) return Status::End;
  const auto deadline = Clock::now() + duration(timeout);
  for (;;) {
    auto now = Clock::now();
    if (!connected_) {
      if (everConnected_ && !reconnectable_) {
        ended_ = true;
        return Status::End;
      }
      if (!outage_) {
        outage_ = true;
        outageStart_ = now;
      }
      if (opt_.maxOutage > 0.0 && seconds(now - outageStart_) > opt_.maxOutage) {
        event("no connection for " + std::to_string(seconds(now - outageStart_)) + " s; giving up");
        ended_ = true;
        return Status::End;
      }
      if (now < nextAttempt_) {
        const auto until = std::min(nextAttempt_, deadline);
        if (until > now) std::this_thread::sleep_for(until - now);
        if (Clock::now() >= deadline) return Status::Timeout;
        continue;
      }
      try {
        connect(std::max(0.01, std::min(opt_.connectTimeout, seconds(deadline - now) + 0.01)));
      } catch (const StreamError& e) {
        if (counters_.failedAttempts++ == 0 || !reconnectable_) event(std::string("cannot connect: ") + e.what());
        if (!reconnectable_) {
          ended_ = true;
          return Status::End;
        }
        nextAttempt_ = Clock::now() + duration(backoff_);
        backoff_ = std::min(2.0 * backoff_, opt_.retryMax);
        if (Clock::now() >= deadline) return Status::Timeout;
        continue;
      }
      now = Clock::now();
      if (everConnected_) {
        gapOpen_ = true;
        event("reconnected " + std::to_string(seconds(now - outageStart_)) + " s after the drop");
      } else if (reconnectable_) {
        event("connected");
      }
      connected_ = everConnected_ = true;
      outage_ = false;
      backoff_ = opt_.retryInitial;
      ++counters_.connects;
      lastData_ = now;
    }
    const double left = std::max(0.0, seconds(deadline - now));
    const long n = readSome(out, left);
    if (n > 0) {
      counters_.bytes += n;
      lastData_ = Clock::now();
      if (gapOpen_) {
        gapOpen_ = false;
        const double gap = seconds(lastData_ - outageStart_);
        counters_.gapSeconds += gap;
        event("data again " + std::to_string(gap) + " s after the drop");
      }
      afterRead();
      return Status::Data;
    }
    if (n < 0) {
      if (!reconnectable_) {
        ended_ = true;
        disconnect();
        return Status::End;
      }
      dropped("connection ended");
      continue;
    }
    if (opt_.idleTimeout > 0.0 && seconds(Clock::now() - lastData_) > opt_.idleTimeout) {
      dropped("no data for " + std::to_string(opt_.idleTimeout) + " s");
      continue;
    }
    if (Clock::now() >= deadline) return Status::Timeout;
  }
}

}  // namespace gvins::rtcm
