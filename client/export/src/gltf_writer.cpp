#include "footfall/export/gltf_writer.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <ostream>
#include <streambuf>
#include <vector>

#include "file_output.h"
#include "footfall/steps/foot_rotations.h"
#include "footfall/steps/linear_units.h"
#include "footfall/terrain/file_extension.h"
#include "footfall/terrain/large_memory.h"
#include "footfall/terrain/output_file.h"
#include "footfall/terrain/shown_text.h"
#include "footfall/terrain/text_stream.h"
#include "footfall/version.h"
#include "walk_prep.h"

namespace footfall {
namespace {

using walk_export::SetError;

// Animation data grouped by element type, one buffer view each: all time inputs, all VEC3
// outputs, all VEC4 outputs. Accessors point into them with 4-byte aligned offsets.
struct Streams {
  std::vector<float> times;
  std::vector<float> vec3;
  std::vector<float> vec4;
};

enum StreamId { kTimes, kVec3, kVec4, kStreamCount };

struct PendingAccessor {
  StreamId stream;
  size_t first_float;  // offset into the stream, in floats
  tinygltf::Accessor accessor;
};

// Keys of one track as glTF samples: ascending float times (seconds), duplicates dropped.
struct Samples {
  std::vector<float> times;
  std::vector<size_t> keys;  // index into track.keys for each time
};

Status TrackSamples(const WalkTrack& track, size_t track_index, double fps, Samples* samples,
                    std::string* error) {
  for (size_t index : KeyOrder(track)) {
    const WalkKey& key = track.keys[index];
    if (key.frame < 0) {
      TextStream message;
      message << "glTF animation times must be >= 0 but track " << track_index << " '"
              << walk_export::QualifiedTrackName(track, track_index) << "' key " << index
              << " is at frame " << key.frame << "; start the walk at frame 0 or later";
      SetError(error, message.str());
      return Status::kInvalidArgument;
    }
    const float time = static_cast<float>(key.frame / fps);
    if (!samples->times.empty() && time <= samples->times.back()) {
      const WalkKey& before = track.keys[samples->keys.back()];
      if (before.frame != key.frame) {
        // Distinct frames that float seconds cannot tell apart: merging them would lose keys.
        TextStream message;
        message.precision(10);
        message << "glTF times are float seconds, and frames " << before.frame << " and "
                << key.frame << " of track " << track_index << " '"
                << walk_export::QualifiedTrackName(track, track_index) << "' both become " << time
                << " s at " << fps
                << " fps; start the walk nearer frame 0 (whatever the fps, a float tells frames "
                   "apart only up to about 1e7; JSON and MEL keep every key)";
        SetError(error, message.str());
        return Status::kInvalidArgument;
      }
      samples->keys.back() = index;  // keys on the same frame: the later one wins
      continue;
    }
    samples->times.push_back(time);
    samples->keys.push_back(index);
  }
  return Status::kOk;
}

tinygltf::Value NodeExtras(const WalkTrack& track) {
  tinygltf::Value::Object extras;
  extras["kind"] = tinygltf::Value(std::string(track.kind == TrackKind::kBody ? "body" : "foot"));
  extras["character"] = tinygltf::Value(walk_export::ValidUtf8(track.character));
  extras["track"] = tinygltf::Value(walk_export::ValidUtf8(track.name));
  // A foot's sole, as the walk JSON carries it (a custom property once imported).
  if (track.kind == TrackKind::kFoot && track.foot_length > 0)
    extras["foot_length"] = tinygltf::Value(track.foot_length);
  if (track.kind == TrackKind::kFoot && track.foot_width > 0)
    extras["foot_width"] = tinygltf::Value(track.foot_width);
  return tinygltf::Value(std::move(extras));
}

int AddAccessor(std::vector<PendingAccessor>* pending, Streams* streams, StreamId stream,
                const std::vector<float>& values, int type, size_t count) {
  std::vector<float>& data = stream == kTimes  ? streams->times
                             : stream == kVec3 ? streams->vec3
                                               : streams->vec4;
  PendingAccessor entry;
  entry.stream = stream;
  entry.first_float = data.size();
  data.insert(data.end(), values.begin(), values.end());
  entry.accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  entry.accessor.type = type;
  entry.accessor.count = count;
  pending->push_back(std::move(entry));
  return static_cast<int>(pending->size() - 1);
}

// An output stream's buffer writing straight to a C file (which buffers): tinygltf writes to a
// std::ostream, ReplaceFile hands out a FILE*. A short write sets the stream's badbit.
class FileStreamBuf : public std::streambuf {
 public:
  explicit FileStreamBuf(std::FILE* file) : file_(file) {}

 protected:
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    return static_cast<std::streamsize>(std::fwrite(s, 1, static_cast<size_t>(n), file_));
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char byte = traits_type::to_char_type(c);
    return std::fwrite(&byte, 1, 1, file_) == 1 ? c : traits_type::eof();
  }

 private:
  std::FILE* file_;
};

bool EndsWithGlb(const std::string& path) { return FileExtension(path) == "glb"; }

// The name and extras kind of the root node that holds a far walk's origin.
constexpr const char* kOriginNodeName = "footfall_origin";

// What glTF stores for position `p`: a float relative to `origin`.
Vec3 StoredFloats(const Vec3& p, const Vec3& origin) {
  return {static_cast<float>(p.x - origin.x), static_cast<float>(p.y - origin.y),
          static_cast<float>(p.z - origin.z)};
}

// `walk` with its lengths (positions, foot lengths and widths) multiplied by `factor` (its unit as
// it was).
Walk ScaledWalk(const Walk& walk, double factor) {
  Walk out = walk;
  for (WalkTrack& track : out.tracks) {
    track.foot_length *= factor, track.foot_width *= factor;
    for (WalkKey& key : track.keys) key.position = key.position * factor;
  }
  return out;
}

}  // namespace

Status WriteGltf(const Walk& walk, const std::string& path, const GltfOptions& options,
                 std::string* error) {
  if (!walk.unit.empty() && walk.unit != "m") {
    const double metres = MetresPerLinearUnit(walk.unit);
    if (!(metres > 0)) {
      SetError(error, "cannot write glTF '" + path + "': the walk's unit '" + ShownText(walk.unit) +
                          "' is none of " + LinearUnitNames());
      return Status::kInvalidArgument;
    }
    try {
      Walk in_metres = ScaledWalk(walk, metres);
      in_metres.unit = "m";
      return WriteGltf(in_metres, path, options, error);
    } catch (const std::bad_alloc&) {
      SetError(error,
               "cannot write glTF '" + path + "': out of memory converting the walk to metres");
      return Status::kLimitExceeded;
    }
  }
  Status status = walk_export::CheckWalk(walk, error);
  if (status != Status::kOk) return status;
  // tinygltf serialises in functions that may not throw: running out of memory there aborts the
  // process (and loses the outputs not yet written). A walk this process cannot hold as glTF is
  // refused first. Measured peaks: about 9 KB a track (its accessors, views and their JSON),
  // and the buffer twice over for .glb (its streams, then the buffer), five times as base64 text
  // for .gltf.
  // Which tracks are keyed with rotations: bodies, and feet when asked.
  auto rotated = [&options](const WalkTrack& track) {
    return track.kind == TrackKind::kBody || options.foot_rotations;
  };
  double buffer_bytes = 0;
  for (const WalkTrack& track : walk.tracks)
    buffer_bytes +=
        static_cast<double>(track.keys.size()) * (rotated(track) ? 4 + 12 + 16 : 4 + 12);
  constexpr double kGlbBytesPerTrack = 2048, kGlbHeaderBytes = 28;
  const double glb_bytes =
      buffer_bytes + kGlbBytesPerTrack * static_cast<double>(walk.tracks.size()) + kGlbHeaderBytes;
  if (options.binary && glb_bytes > options.max_glb_bytes) {
    TextStream m;
    m.precision(3);
    m << "the walk takes about " << glb_bytes / 1e9 << " GB as .glb, whose lengths are 32-bit: it "
      << "holds at most " << options.max_glb_bytes / 1e9
      << " GB (write .gltf, .json or .mel, or fewer characters or steps)";
    SetError(error, m.str());
    return Status::kLimitExceeded;
  }
  const double needed = buffer_bytes * (options.binary ? 2 : 5) +
                        9e3 * static_cast<double>(walk.tracks.size()) + 64e6;
  const double available = AvailableMemoryBytes();
  if (available > 0 && needed > available) {
    TextStream m;
    m.precision(3);
    m << "writing the walk as glTF needs about " << needed / 1e9 << " GB, more than the "
      << available / 1e9
      << " GB this process has free (write .json or .mel, or fewer characters or steps)";
    SetError(error, m.str());
    return Status::kLimitExceeded;
  }

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "footfall " FOOTFALL_VERSION " (tinygltf)";

  std::vector<std::string> names;
  names.reserve(walk.tracks.size());
  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    names.push_back(walk_export::ValidUtf8(walk_export::QualifiedTrackName(walk.tracks[t], t)));
  }
  // A far walk's tracks are children of one root at its origin (the header says why).
  const Vec3 origin = GltfOrigin(walk);
  const bool has_root = origin != Vec3{};
  if (has_root) names.push_back(kOriginNodeName);  // last: a track keeps its own name
  names = walk_export::UniqueNames(names);

  Streams streams;
  {
    // Sized for every key (keys sharing a frame are dropped): grown a track at a time, the
    // streams were copied over and over.
    size_t keys = 0, rotated_keys = 0;
    for (const WalkTrack& track : walk.tracks)
      keys += track.keys.size(), rotated_keys += rotated(track) ? track.keys.size() : 0;
    streams.times.reserve(keys);
    streams.vec3.reserve(3 * keys);
    streams.vec4.reserve(4 * rotated_keys);
  }
  std::vector<PendingAccessor> pending;
  tinygltf::Animation animation;
  animation.name = "walk";
  tinygltf::Scene scene;
  scene.name = "walk";
  FootOrientation feet(walk);

  for (size_t t = 0; t < walk.tracks.size(); ++t) {
    const WalkTrack& track = walk.tracks[t];
    const bool body = track.kind == TrackKind::kBody, turns = rotated(track);
    tinygltf::Node node;
    node.name = names[t];
    node.extras = NodeExtras(track);

    Samples samples;
    status = TrackSamples(track, t, walk.fps, &samples, error);
    if (status != Status::kOk) return status;

    if (!samples.keys.empty()) {
      const size_t count = samples.keys.size();
      std::vector<float> translations;
      std::vector<float> rotations;
      translations.reserve(count * 3);
      const std::vector<Quat> foot_rotations =
          turns && !body ? feet.Rotations(t) : std::vector<Quat>{};
      Quat previous;
      for (size_t i = 0; i < count; ++i) {
        const Vec3 stored = StoredFloats(track.keys[samples.keys[i]].position, origin);
        translations.insert(translations.end(),
                            {static_cast<float>(stored.x), static_cast<float>(stored.y),
                             static_cast<float>(stored.z)});
        if (turns) {
          Quat q =
              body ? Normalized(track.Rotation(samples.keys[i])) : foot_rotations[samples.keys[i]];
          // q and -q are the same rotation; keep neighbours in one hemisphere so that
          // interpolation takes the short way.
          if (i > 0 &&
              q.x * previous.x + q.y * previous.y + q.z * previous.z + q.w * previous.w < 0) {
            q = {-q.x, -q.y, -q.z, -q.w};
          }
          previous = q;
          rotations.insert(rotations.end(), {static_cast<float>(q.x), static_cast<float>(q.y),
                                             static_cast<float>(q.z), static_cast<float>(q.w)});
        }
      }
      node.translation = {translations[0], translations[1], translations[2]};
      if (turns) node.rotation = {rotations[0], rotations[1], rotations[2], rotations[3]};

      const int input =
          AddAccessor(&pending, &streams, kTimes, samples.times, TINYGLTF_TYPE_SCALAR, count);
      // The validator requires min and max on animation inputs; they must equal the stored
      // float values exactly, which a double holding a float does.
      pending[input].accessor.minValues = {samples.times.front()};
      pending[input].accessor.maxValues = {samples.times.back()};

      const int node_index = static_cast<int>(model.nodes.size());
      auto add_channel = [&](int output, const char* target_path) {
        tinygltf::AnimationSampler sampler;
        sampler.input = input;
        sampler.output = output;
        sampler.interpolation = "LINEAR";
        animation.samplers.push_back(sampler);
        tinygltf::AnimationChannel channel;
        channel.sampler = static_cast<int>(animation.samplers.size() - 1);
        channel.target_node = node_index;
        channel.target_path = target_path;
        animation.channels.push_back(channel);
      };
      add_channel(AddAccessor(&pending, &streams, kVec3, translations, TINYGLTF_TYPE_VEC3, count),
                  "translation");
      if (turns) {
        add_channel(AddAccessor(&pending, &streams, kVec4, rotations, TINYGLTF_TYPE_VEC4, count),
                    "rotation");
      }
    }
    if (!has_root) scene.nodes.push_back(static_cast<int>(model.nodes.size()));
    model.nodes.push_back(std::move(node));
  }
  if (has_root) {
    tinygltf::Node root;
    root.name = names.back();
    // JSON numbers, written with full double precision (GltfOrigin makes them integers).
    root.translation = {origin.x, origin.y, origin.z};
    for (size_t t = 0; t < walk.tracks.size(); ++t) root.children.push_back(static_cast<int>(t));
    tinygltf::Value::Object extras;
    extras["kind"] = tinygltf::Value(std::string("origin"));
    extras["origin"] = tinygltf::Value(tinygltf::Value::Array{
        tinygltf::Value(origin.x), tinygltf::Value(origin.y), tinygltf::Value(origin.z)});
    root.extras = tinygltf::Value(std::move(extras));
    scene.nodes.push_back(static_cast<int>(model.nodes.size()));
    model.nodes.push_back(std::move(root));
  }

  // One buffer holding the three streams back to back, one buffer view per non-empty stream.
  std::vector<float>* stream_data[kStreamCount] = {&streams.times, &streams.vec3, &streams.vec4};
  int view_of[kStreamCount] = {-1, -1, -1};
  tinygltf::Buffer buffer;
  buffer.data.reserve((streams.times.size() + streams.vec3.size() + streams.vec4.size()) *
                      sizeof(float));
  for (int s = 0; s < kStreamCount; ++s) {
    std::vector<float>& data = *stream_data[s];
    if (data.empty()) continue;
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = data.size() * sizeof(float);
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    buffer.data.insert(buffer.data.end(), bytes, bytes + view.byteLength);
    std::vector<float>().swap(data);  // copied: freed before the next is
    view_of[s] = static_cast<int>(model.bufferViews.size());
    model.bufferViews.push_back(view);
  }
  if (!buffer.data.empty()) model.buffers.push_back(std::move(buffer));
  for (PendingAccessor& entry : pending) {
    entry.accessor.bufferView = view_of[entry.stream];
    entry.accessor.byteOffset = entry.first_float * sizeof(float);
    model.accessors.push_back(std::move(entry.accessor));
  }

  tinygltf::Value::Object animation_extras;
  animation_extras["fps"] = tinygltf::Value(walk.fps);
  if (!walk.stopped.empty())
    animation_extras["stopped"] = tinygltf::Value(walk_export::ValidUtf8(walk.stopped));
  animation.extras = tinygltf::Value(std::move(animation_extras));
  // An animation needs at least one channel; a walk without keys has none.
  if (!animation.channels.empty()) model.animations.push_back(std::move(animation));
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;

  // Serialised straight into the file (ReplaceFile: a failed write leaves the old file whole),
  // never whole in memory.
  tinygltf::TinyGLTF gltf;
  std::string failed;  // what went wrong inside tinygltf, if it did
  std::string message;
  status = ReplaceFile(
      path,
      [&](std::FILE* file) {
        FileStreamBuf file_buffer(file);
        std::ostream out(&file_buffer);
        try {
          // Its JSON library throws on what it cannot write; no exception leaves this function.
          if (!gltf.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/true, options.binary)) {
            failed = "tinygltf could not serialise the walk for '" + path + "'";
            return false;
          }
        } catch (const std::exception& e) {
          failed = "tinygltf could not serialise the walk for '" + path + "': " + e.what();
          return false;
        }
        out.flush();
        return static_cast<bool>(out);
      },
      &message);
  if (!failed.empty()) {
    SetError(error, failed);
    return Status::kInternalError;
  }
  if (status != Status::kOk) SetError(error, message);
  return status;
}

Status WriteGltf(const Walk& walk, const std::string& path, std::string* error) {
  GltfOptions options;
  options.binary = EndsWithGlb(path);
  return WriteGltf(walk, path, options, error);
}

double MaxTimeRounding(const Walk& walk) {
  double worst = 0;
  for (const WalkTrack& track : walk.tracks) {
    for (const WalkKey& key : track.keys) {
      const double kept = static_cast<double>(static_cast<float>(key.frame / walk.fps));
      worst = std::max(worst, std::fabs(kept * walk.fps - key.frame));
    }
  }
  return worst;
}

double MaxFloatRounding(const Walk& walk) {
  const Vec3 origin = GltfOrigin(walk);
  double worst = 0;
  for (const WalkTrack& track : walk.tracks) {
    for (const WalkKey& key : track.keys) {
      const Vec3& p = key.position;
      worst = std::max(worst, Distance(origin + StoredFloats(p, origin), p));
    }
  }
  return worst;
}

Vec3 GltfOrigin(const Walk& walk) {
  double low[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
  double high[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  bool far[3] = {false, false, false};
  for (const WalkTrack& track : walk.tracks) {
    for (const WalkKey& key : track.keys) {
      const double p[3] = {key.position.x, key.position.y, key.position.z};
      for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(p[a])) continue;
        low[a] = std::min(low[a], p[a]);
        high[a] = std::max(high[a], p[a]);
        far[a] = far[a] || std::fabs(p[a]) > kGltfLocalExtent;
      }
    }
  }
  double origin[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    if (!far[a]) continue;
    // Halves first: the sum of two coordinates near the double limit would overflow.
    origin[a] = std::round(low[a] / 2 + high[a] / 2);
    if (origin[a] == 0) origin[a] = 0;  // never -0 (it would read "-0.0")
  }
  return {origin[0], origin[1], origin[2]};
}

}  // namespace footfall
