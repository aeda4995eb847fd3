// The standard descriptors of footfall's programs, which a parent may have closed.
#pragma once

namespace footfall {

// Opens /dev/null on each of descriptors 0, 1 and 2 that is closed, so that files and sockets
// opened later never take their numbers (with stderr closed, footfalld's log lines went into its
// first client's connection). Call first thing in main.
void OpenClosedStandardStreams();

}  // namespace footfall
