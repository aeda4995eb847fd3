#include "raw_rpc.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <rpc/rpc.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "footfall.h"

namespace footfall::test {

void Put32(std::vector<unsigned char>* b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b->push_back(static_cast<unsigned char>(v >> s));
}

void PutDouble(std::vector<unsigned char>* b, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  Put32(b, static_cast<uint32_t>(bits >> 32));
  Put32(b, static_cast<uint32_t>(bits));
}

std::vector<unsigned char> CallRecord(uint32_t xid, uint32_t proc,
                                      const std::vector<unsigned char>& args) {
  std::vector<unsigned char> body;
  Put32(&body, xid);
  Put32(&body, 0);  // CALL
  Put32(&body, 2);  // RPC version
  Put32(&body, FOOTFALL_PROG);
  Put32(&body, FOOTFALL_V1);
  Put32(&body, proc);
  Put32(&body, 0), Put32(&body, 0);  // AUTH_NONE credentials
  Put32(&body, 0), Put32(&body, 0);  // AUTH_NONE verifier
  body.insert(body.end(), args.begin(), args.end());
  std::vector<unsigned char> record;
  Put32(&record, 0x80000000u | static_cast<uint32_t>(body.size()));
  record.insert(record.end(), body.begin(), body.end());
  return record;
}

std::vector<unsigned char> FullBatchCall(uint32_t terrain) {
  std::vector<unsigned char> batch;
  Put32(&batch, terrain);
  Put32(&batch, FF_MAX_BATCH);
  for (int i = 0; i < FF_MAX_BATCH; ++i)
    PutDouble(&batch, i % 30), PutDouble(&batch, 0), PutDouble(&batch, 0);
  return CallRecord(1, FF_SNAP_BATCH, batch);
}

bool ListServerTerrains(int port, std::vector<uint32_t>* handles) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  int sock = RPC_ANYSOCK;
  CLIENT* c = clnttcp_create(&addr, FOOTFALL_PROG, FOOTFALL_V1, &sock, 0, 0);
  if (!c) return false;
  ff_list_reply reply{};
  const bool ok = ff_list_1(nullptr, &reply, c) == RPC_SUCCESS;
  if (ok) {
    handles->assign(reply.terrains.terrains_val,
                    reply.terrains.terrains_val + reply.terrains.terrains_len);
    xdr_free(reinterpret_cast<xdrproc_t>(xdr_ff_list_reply), reinterpret_cast<char*>(&reply));
  }
  clnt_destroy(c);
  return ok;
}

Flooder::Flooder(int port, std::vector<unsigned char> record, int receive_buffer)
    : port_(port),
      record_(std::move(record)),
      receive_buffer_(receive_buffer),
      thread_([this] { Run(); }) {}

Flooder::~Flooder() {
  stop_ = true;
  thread_.join();
}

void Flooder::Run() {
  int fd = -1;
  size_t at = 0;
  while (!stop_) {
    if (fd < 0) {
      fd = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_port = htons(static_cast<uint16_t>(port_));
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      const timeval wait{0, 100000};
      setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &wait, sizeof wait);
      if (receive_buffer_ > 0)
        setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_, sizeof receive_buffer_);
      if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        close(fd), fd = -1;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        continue;
      }
      at = 0;
    }
    const ssize_t n = send(fd, record_.data() + at, record_.size() - at, MSG_NOSIGNAL);
    if (n > 0) {
      at = (at + static_cast<size_t>(n)) % record_.size();
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      ++blocked_;
    } else {
      close(fd), fd = -1;
      ++drops_;
    }
  }
  if (fd >= 0) close(fd);
}

}  // namespace footfall::test
