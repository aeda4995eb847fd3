#include "footfall/viewer/png_writer.h"

#include <cerrno>
#include <cstdio>

#include "footfall/terrain/output_file.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace footfall::viewer {
namespace {

// stb's own file writer ignores write errors (a full disk gave a truncated PNG and success):
// the PNG is written through this sink, which remembers the first failure.
struct Sink {
  FILE* file = nullptr;
  int error = 0;  // errno of the first failed write
};

void Write(void* context, void* data, int size) {
  Sink* sink = static_cast<Sink*>(context);
  if (sink->error == 0 && size > 0 &&
      std::fwrite(data, 1, static_cast<size_t>(size), sink->file) != static_cast<size_t>(size))
    sink->error = errno ? errno : EIO;
}

}  // namespace

bool WritePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba,
              std::string* error) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (width <= 0 || height <= 0 || rgba.size() != pixels * 4) {
    *error = path + ": bad image size";
    return false;
  }
  std::vector<uint8_t> rgb(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    rgb[i * 3] = rgba[i * 4], rgb[i * 3 + 1] = rgba[i * 4 + 1], rgb[i * 3 + 2] = rgba[i * 4 + 2];
  }
  std::string message;
  const Status status = ReplaceFile(
      path,
      [&](std::FILE* file) {
        Sink sink;
        sink.file = file;
        const int encoded =
            stbi_write_png_to_func(Write, &sink, width, height, 3, rgb.data(), width * 3);
        if (sink.error) errno = sink.error;
        return encoded && sink.error == 0;
      },
      &message);
  if (status != Status::kOk) {
    // "cannot write 'PATH': REASON" -> "PATH: cannot write PNG: REASON"
    const size_t reason = message.rfind("': ");
    *error = path + ": cannot write PNG: " +
             (reason == std::string::npos ? message : message.substr(reason + 3));
    return false;
  }
  return true;
}

}  // namespace footfall::viewer
