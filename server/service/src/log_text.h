// How footfalld's log shows text that may come from a client or the command line.
#pragma once

#include <string>

namespace footfall {

// `text` with backslashes, control characters (C0, DEL and C1) and bytes that are not UTF-8
// escaped (\\, \n, \r, \t, \xHH for each byte), so that text from a client cannot start a log
// line of its own nor send terminal escapes, and the log stays UTF-8; other characters are kept
// as they are.
std::string EscapeControl(const std::string& text);

}  // namespace footfall
