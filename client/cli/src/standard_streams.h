// The command line's standard streams, read and written through their descriptors so that a
// non-blocking one is waited for instead of failing. A parent process may have made its own
// pipe or terminal non-blocking (Node.js does) and handed it on: through stdio, `footfall query`
// then ended its input early and lost its answers, "Resource temporarily unavailable".
#pragma once

namespace footfall::cli {

// Makes std::cin, std::cout and std::cerr read and write descriptors 0, 1 and 2 directly,
// waiting (poll) whenever a descriptor is not ready. Call once, before any use of the streams;
// stdio's stdin, stdout and stderr must not be used afterwards. `closed_at_start`: the
// descriptors OpenClosedStandardStreams found closed (bits 1 << fd); output to a standard
// output closed at start fails (EBADF), as it would have, rather than vanish into /dev/null.
void UseWaitingStandardStreams(int closed_at_start);

// The errno of the read that ended std::cin early (0 when it reached the end of its input).
int StandardInputError();

// The errno of the first failed write to std::cout (0 when none failed).
int StandardOutputError();

// Whether std::cin can give more input without waiting: buffered text, or a descriptor with
// data or at its end.
bool StandardInputReady();

}  // namespace footfall::cli
