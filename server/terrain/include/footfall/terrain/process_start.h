// What footfall's programs inherit from the process that started them: standard descriptors it
// may have closed, signals it may have ignored, and limits that keep threads from starting.
#pragma once

#include <cstddef>
#include <string>
#include <system_error>

namespace footfall {

// Opens /dev/null on each of descriptors 0, 1 and 2 that is closed, so that files and sockets
// opened later never take their numbers (with stderr closed, footfalld's log lines went into its
// first client's connection). Call first thing in main. Returns those that were closed, as bits
// (1 << descriptor).
int OpenClosedStandardStreams();

// Writes `size` bytes of `data` to descriptor `fd` whole, as a parent may have made it
// non-blocking (Node.js does): interrupted writes are made again, and a full descriptor is waited
// for (poll), up to `first_wait_ms` before the first byte and `rest_wait_ms` for the rest once one
// is written (-1: for ever). Returns the bytes written; when fewer than `size`, *error is errno
// (EAGAIN: a wait ran out).
size_t WriteWaiting(int fd, const char* data, size_t size, int first_wait_ms, int rest_wait_ms,
                    int* error);

// Flushes std::cout: true when everything written to it reached its file; else false, after
// "PROGRAM: cannot write standard output: REASON" on stderr (REASON from errno, which the caller
// sets to 0 before writing: a full disk gave exit 0 with nothing written).
bool FlushStandardOutput(const char* program);

// Whether `signal_number` is ignored (SIG_IGN) now: a program that installs a handler leaves one
// ignored when it started so (under nohup, or as a script's background job).
bool SignalIgnored(int signal_number);

// The message of a std::system_error, with what it means when a thread could not start (the
// limit on processes, or memory for its stack).
std::string SystemErrorText(const std::system_error& e);

}  // namespace footfall
