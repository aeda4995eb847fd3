// What footfall's programs inherit from the process that started them: standard descriptors it
// may have closed, signals it may have ignored, and limits that keep threads from starting.
#pragma once

#include <string>
#include <system_error>

namespace footfall {

// Opens /dev/null on each of descriptors 0, 1 and 2 that is closed, so that files and sockets
// opened later never take their numbers (with stderr closed, footfalld's log lines went into its
// first client's connection). Call first thing in main. Returns those that were closed, as bits
// (1 << descriptor).
int OpenClosedStandardStreams();

// Whether `signal_number` is ignored (SIG_IGN) now: a program that installs a handler leaves one
// ignored when it started so (under nohup, or as a script's background job).
bool SignalIgnored(int signal_number);

// The message of a std::system_error, with what it means when a thread could not start (the
// limit on processes, or memory for its stack).
std::string SystemErrorText(const std::system_error& e);

}  // namespace footfall
