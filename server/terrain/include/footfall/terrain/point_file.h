// The terrain point file: ASCII, one sample per line "x y z nx ny nz", whitespace separated
// decimal numbers (each with at most one sign: "+-1" is not a number).
// '#' starts a comment; blank lines are skipped; CRLF line ends and a leading UTF-8 byte order
// mark are accepted. Coordinates must be within +-terrain::kMaxCoordinate. A sample's index is its
// 0-based order among data lines. Normals are normalised on load.
#pragma once

#include <iosfwd>
#include <string>

#include "footfall/terrain/samples.h"

namespace footfall {

// Reads a point file. On error returns kIoError (cannot open) or kParseError, with a message
// "FILE:LINE: what was expected" in *error; *out is then left empty.
Status ReadPointFile(const std::string& path, RawSamples* out, std::string* error);

// Same, from a stream; `name` is used in messages.
Status ReadPointStream(std::istream& in, const std::string& name, RawSamples* out,
                       std::string* error);

// Writes samples as a point file with a header comment (ReplaceFile: a failed write leaves the
// old file whole); kIoError if the file cannot be written.
Status WritePointFile(const std::string& path, const RawSamples& samples, std::string* error);

}  // namespace footfall
