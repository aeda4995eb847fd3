// Standard streams over descriptors 0, 1 and 2 that wait when a descriptor is non-blocking.
#include "standard_streams.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <iostream>
#include <streambuf>

#include "footfall/terrain/process_start.h"

namespace footfall::cli {
namespace {

// Waits until `fd` is ready for `events` (or reports an error or hang-up, which the next read
// or write then meets). False only when poll itself fails.
bool WaitFor(int fd, short events) {
  pollfd p{fd, events, 0};
  for (;;) {
    if (poll(&p, 1, -1) >= 0) return true;
    if (errno != EINTR) return false;
  }
}

// A buffered stream over one descriptor, read or written whole: interrupted calls are made
// again, and a descriptor that is not ready is waited for.
class DescriptorBuf final : public std::streambuf {
 public:
  // `closed`: the descriptor was closed when the process started (it is /dev/null now): what
  // is written fails, EBADF.
  DescriptorBuf(int fd, bool closed) : fd_(fd), closed_(closed) {}
  DescriptorBuf(const DescriptorBuf&) = delete;
  DescriptorBuf& operator=(const DescriptorBuf&) = delete;

  int error() const { return error_; }
  bool HasBuffered() const { return gptr() < egptr(); }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    for (;;) {
      const ssize_t n = read(fd_, in_, sizeof in_);
      if (n > 0) {
        setg(in_, in_, in_ + n);
        return traits_type::to_int_type(*gptr());
      }
      if (n == 0) return traits_type::eof();
      if (errno == EINTR) continue;
      if ((errno == EAGAIN || errno == EWOULDBLOCK) && WaitFor(fd_, POLLIN)) continue;
      error_ = errno;
      return traits_type::eof();
    }
  }

  int_type overflow(int_type c) override {
    if (!Drain()) return traits_type::eof();
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    *pptr() = traits_type::to_char_type(c);
    pbump(1);
    return c;
  }

  int sync() override { return Drain() ? 0 : -1; }

 private:
  // Writes what is buffered; false (the error kept) when the descriptor refuses it.
  bool Drain() {
    if (!pbase()) setp(out_, out_ + sizeof out_);
    if (closed_ && pptr() > pbase()) {
      if (error_ == 0) error_ = EBADF;
      return false;
    }
    const size_t pending = static_cast<size_t>(pptr() - pbase());
    int error = 0;
    if (WriteWaiting(fd_, pbase(), pending, -1, -1, &error) < pending) {
      if (error_ == 0) error_ = error;
      return false;
    }
    setp(out_, out_ + sizeof out_);
    return true;
  }

  int fd_;
  bool closed_;
  int error_ = 0;
  char in_[1 << 16];
  char out_[1 << 16];
};

DescriptorBuf* g_in = nullptr;
DescriptorBuf* g_out = nullptr;

}  // namespace

void UseWaitingStandardStreams(int closed_at_start) {
  // Never freed: the streams are flushed at exit, after static objects are gone.
  auto closed = [closed_at_start](int fd) { return (closed_at_start & (1 << fd)) != 0; };
  auto* in = new DescriptorBuf(STDIN_FILENO, false);  // reads /dev/null: the input is empty
  auto* out = new DescriptorBuf(STDOUT_FILENO, closed(STDOUT_FILENO));
  auto* err = new DescriptorBuf(STDERR_FILENO, false);  // nowhere else to say it
  std::cout.flush();
  std::cin.rdbuf(in);
  std::cout.rdbuf(out);
  std::cerr.rdbuf(err);
  std::clog.rdbuf(err);
  g_in = in;
  g_out = out;
}

int StandardInputError() { return g_in ? g_in->error() : 0; }

int StandardOutputError() { return g_out ? g_out->error() : 0; }

bool StandardInputReady() {
  if (g_in && g_in->HasBuffered()) return true;
  pollfd p{STDIN_FILENO, POLLIN, 0};
  return poll(&p, 1, 0) > 0;
}

}  // namespace footfall::cli
