// Raw ONC RPC for tests of footfalld: call records built byte by byte, and clients that
// misbehave on purpose (no client library, no libtirpc client).
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace footfall::test {

// Appends `v` in XDR (big-endian, 4 bytes).
void Put32(std::vector<unsigned char>* b, uint32_t v);
// Appends `v` in XDR (IEEE double, big-endian, 8 bytes).
void PutDouble(std::vector<unsigned char>* b, double v);

// A complete one-fragment call record of footfall's program for `proc`, with already encoded
// arguments.
std::vector<unsigned char> CallRecord(uint32_t xid, uint32_t proc,
                                      const std::vector<unsigned char>& args);

// A full snap batch call on server terrain `terrain` (FF_MAX_BATCH points), whose reply is the
// largest.
std::vector<unsigned char> FullBatchCall(uint32_t terrain);

// The handles of the terrains footfalld on 127.0.0.1:`port` holds, in its order (FF_LIST); false
// when the call fails.
bool ListServerTerrains(int port, std::vector<uint32_t>* handles);

// A client on its own thread that sends `record` again and again and never reads a reply, until
// destroyed; when the server drops it, it counts the drop and connects again. Tests read the
// counters (no assertions on its thread). `receive_buffer` [Units: bytes], when not 0, is its
// socket's SO_RCVBUF: a small one makes the server's replies queue in small buffers.
class Flooder {
 public:
  Flooder(int port, std::vector<unsigned char> record, int receive_buffer = 0);
  ~Flooder();
  Flooder(const Flooder&) = delete;
  Flooder& operator=(const Flooder&) = delete;

  int drops() const { return drops_; }
  int blocked() const { return blocked_; }  // sends that waited 100 ms on a full socket

 private:
  void Run();

  const int port_;
  const std::vector<unsigned char> record_;
  const int receive_buffer_;
  std::atomic<bool> stop_{false};
  std::atomic<int> drops_{0}, blocked_{0};
  std::thread thread_;
};

}  // namespace footfall::test
