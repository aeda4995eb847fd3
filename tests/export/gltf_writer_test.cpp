// The glTF writer: files read back with tinygltf hold one node per track, the keys as LINEAR
// samplers with times frame / fps, and bad input or unwritable paths give clear errors.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>

#include "footfall/export/gltf_writer.h"
#include "footfall/export/walk_writer.h"
#include "walk_fixtures.h"

using namespace footfall;

namespace {

tinygltf::Model Load(const std::string& path, bool binary) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                         : loader.LoadASCIIFromFile(&model, &error, &warning, path);
  INFO(error << warning);
  REQUIRE(ok);
  return model;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The floats of an accessor (FLOAT components, tightly packed).
std::vector<float> Floats(const tinygltf::Model& model, int accessor_index) {
  const tinygltf::Accessor& accessor = model.accessors.at(accessor_index);
  REQUIRE(accessor.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& view = model.bufferViews.at(accessor.bufferView);
  const tinygltf::Buffer& buffer = model.buffers.at(view.buffer);
  const size_t components = static_cast<size_t>(tinygltf::GetNumComponentsInType(accessor.type));
  std::vector<float> values(accessor.count * components);
  const size_t offset = view.byteOffset + accessor.byteOffset;
  REQUIRE(offset + values.size() * sizeof(float) <= view.byteOffset + view.byteLength);
  std::memcpy(values.data(), buffer.data.data() + offset, values.size() * sizeof(float));
  return values;
}

struct Channel {
  std::vector<float> times;
  std::vector<float> values;
  std::string interpolation;
};

// node name -> path ("translation", "rotation") -> the channel's sampled data.
std::map<std::string, std::map<std::string, Channel>> Channels(const tinygltf::Model& model) {
  std::map<std::string, std::map<std::string, Channel>> out;
  REQUIRE(model.animations.size() == 1);
  const tinygltf::Animation& animation = model.animations[0];
  for (const tinygltf::AnimationChannel& channel : animation.channels) {
    const tinygltf::AnimationSampler& sampler = animation.samplers.at(channel.sampler);
    const std::string& node = model.nodes.at(channel.target_node).name;
    REQUIRE(out[node].count(channel.target_path) == 0);
    Channel& c = out[node][channel.target_path];
    c.times = Floats(model, sampler.input);
    c.values = Floats(model, sampler.output);
    c.interpolation = sampler.interpolation;
    const tinygltf::Accessor& input = model.accessors.at(sampler.input);
    REQUIRE(input.minValues.size() == 1);
    REQUIRE(input.maxValues.size() == 1);
    CHECK(input.minValues[0] == c.times.front());
    CHECK(input.maxValues[0] == c.times.back());
  }
  return out;
}

void CheckPositions(const Channel& channel, const WalkTrack& track, const std::vector<size_t>& keys,
                    double fps) {
  REQUIRE(channel.times.size() == keys.size());
  REQUIRE(channel.values.size() == keys.size() * 3);
  for (size_t i = 0; i < keys.size(); ++i) {
    const WalkKey& key = track.keys[keys[i]];
    CHECK(channel.times[i] == static_cast<float>(key.frame / fps));
    if (i > 0) CHECK(channel.times[i] > channel.times[i - 1]);
    CHECK(channel.values[3 * i] == static_cast<float>(key.position.x));
    CHECK(channel.values[3 * i + 1] == static_cast<float>(key.position.y));
    CHECK(channel.values[3 * i + 2] == static_cast<float>(key.position.z));
  }
}

}  // namespace

TEST_CASE("WriteGltf writes a node per track with keyed channels", "[export][gltf]") {
  Walk walk = test::BipedWalk();
  walk.tracks[0].foot_length = 0.25;  // L's sole; R has point feet
  walk.tracks[0].foot_width = 0.1;
  const bool binary = GENERATE(false, true);
  const std::string path = test::ScratchPath(binary ? "biped.glb" : "biped.gltf");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  INFO(path);

  const std::string bytes = ReadBytes(path);
  if (binary) {
    REQUIRE(bytes.compare(0, 4, "glTF") == 0);
  } else {
    REQUIRE(bytes.front() == '{');
    CHECK(bytes.find("\"uri\": \"data:application/octet-stream;base64,") != std::string::npos);
  }

  const tinygltf::Model model = Load(path, binary);
  CHECK(model.asset.version == "2.0");
  CHECK(model.asset.generator.rfind("footfall ", 0) == 0);
  REQUIRE(model.nodes.size() == 3);
  CHECK(model.nodes[0].name == "L");
  CHECK(model.nodes[1].name == "R");
  CHECK(model.nodes[2].name == "body");
  CHECK(model.nodes[2].extras.Get("kind").Get<std::string>() == "body");
  CHECK(model.nodes[0].extras.Get("kind").Get<std::string>() == "foot");
  // A foot's foot_length where the walk has one (as the walk JSON), none for point feet.
  CHECK(model.nodes[0].extras.Get("foot_length").GetNumberAsDouble() == 0.25);
  CHECK_FALSE(model.nodes[1].extras.Has("foot_length"));
  CHECK(model.nodes[0].extras.Get("foot_width").GetNumberAsDouble() == 0.1);
  CHECK_FALSE(model.nodes[1].extras.Has("foot_width"));
  CHECK_FALSE(model.nodes[2].extras.Has("foot_length"));
  REQUIRE(model.scenes.size() == 1);
  CHECK(model.defaultScene == 0);
  CHECK(model.scenes[0].nodes == std::vector<int>{0, 1, 2});
  CHECK(model.animations[0].name == "walk");
  CHECK(model.animations[0].extras.Get("fps").GetNumberAsDouble() == 24);

  auto channels = Channels(model);
  SECTION("feet animate translation only, with every key at frame / fps seconds") {
    REQUIRE(channels["L"].size() == 1);
    CheckPositions(channels["L"]["translation"], walk.tracks[0], {0, 1, 2, 3, 4, 5}, 24);
    CHECK(channels["L"]["translation"].interpolation == "LINEAR");
    CHECK(channels["L"]["translation"].times.front() == static_cast<float>(1.0 / 24));
    // Rest pose: the first key.
    CHECK(model.nodes[0].translation == std::vector<double>{static_cast<float>(-0.1), 0, 0});
  }
  SECTION("two keys on one frame keep the later key once") {
    REQUIRE(channels["R"].size() == 1);
    CheckPositions(channels["R"]["translation"], walk.tracks[1], {0, 1, 3, 4, 5}, 24);
  }
  SECTION("bodies animate translation and unit rotations kept in one hemisphere") {
    REQUIRE(channels["body"].size() == 2);
    CheckPositions(channels["body"]["translation"], walk.tracks[2], {0, 1, 2, 3, 4}, 24);
    const Channel& rotation = channels["body"]["rotation"];
    CHECK(rotation.interpolation == "LINEAR");
    CHECK(rotation.times == channels["body"]["translation"].times);
    REQUIRE(rotation.values.size() == 5 * 4);
    const double yaw[] = {0, 60, 150, 170, 190};
    for (size_t i = 0; i < 5; ++i) {
      const float* q = &rotation.values[4 * i];
      const Quat expected = test::YawQuat(yaw[i]);
      CHECK(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) ==
            Approx(1).margin(1e-6));
      // Same rotation (up to sign) as the key.
      const double dot =
          q[0] * expected.x + q[1] * expected.y + q[2] * expected.z + q[3] * expected.w;
      CHECK(std::abs(dot) == Approx(1).margin(1e-6));
      if (i > 0) {
        const float* p = &rotation.values[4 * (i - 1)];
        CHECK(p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] > 0);
      }
    }
  }
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf writes unit rotations for keys of any length", "[export][gltf]") {
  // A walk read from JSON keeps its rotations as given: components of 1e300 overflowed their
  // squares (a zero rotation out), 1e-200 underflowed them.
  Walk walk = test::BipedWalk();
  WalkTrack& body = walk.tracks[2];
  const double scales[] = {1e300, 1e-200, 3, 1, 1};
  for (size_t i = 0; i < body.rotations.size(); ++i) {
    Quat& q = body.rotations[i];
    const double k = scales[i % 5];
    q = {q.x * k, q.y * k, q.z * k, q.w * k};
  }
  const std::string path = test::ScratchPath("scaled.gltf");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  const tinygltf::Model model = Load(path, false);
  auto channels = Channels(model);
  const Channel& rotation = channels["body"]["rotation"];
  REQUIRE(rotation.values.size() == 5 * 4);
  const double yaw[] = {0, 60, 150, 170, 190};
  for (size_t i = 0; i < 5; ++i) {
    INFO("key " << i);
    const float* q = &rotation.values[4 * i];
    const Quat expected = test::YawQuat(yaw[i]);
    const double dot =
        q[0] * expected.x + q[1] * expected.y + q[2] * expected.z + q[3] * expected.w;
    CHECK(std::abs(dot) == Approx(1).margin(1e-6));
  }
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf names crowd nodes character/track", "[export][gltf]") {
  const Walk walk = test::CrowdWalk();
  const std::string path = test::ScratchPath("crowd.glb");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  const tinygltf::Model model = Load(path, true);
  std::vector<std::string> names;
  for (const tinygltf::Node& node : model.nodes) names.push_back(node.name);
  CHECK(names == std::vector<std::string>{"ant 1/L1", "ant 1/R1", "ant 1/body", "ant-2/L1",
                                          "ant-2/R1", "ant-2/body"});
  CHECK(model.nodes[3].extras.Get("character").Get<std::string>() == "ant-2");
  CHECK(model.nodes[3].extras.Get("track").Get<std::string>() == "L1");
  auto channels = Channels(model);
  CHECK(channels.size() == 6);
  CheckPositions(channels["ant-2/R1"]["translation"], walk.tracks[4], {0, 1, 2}, 30);
  CHECK(channels["ant-2/body"].count("rotation") == 1);
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf makes repeated and empty track names unique", "[export][gltf]") {
  Walk walk = test::BipedWalk();
  walk.tracks[1].name = "L";
  walk.tracks.push_back(walk.tracks[0]);
  walk.tracks.back().name = "L_2";
  walk.tracks.push_back(walk.tracks[0]);
  walk.tracks.back().name = "";
  walk.tracks.back().keys.clear();  // a track without keys: a node, no channel
  const std::string path = test::ScratchPath("names.gltf");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  const tinygltf::Model model = Load(path, false);
  std::vector<std::string> names;
  for (const tinygltf::Node& node : model.nodes) names.push_back(node.name);
  CHECK(names == std::vector<std::string>{"L", "L_3", "body", "L_2", "track4"});
  CHECK(Channels(model).count("track4") == 0);
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf writes names that are not UTF-8 with U+FFFD", "[export][gltf]") {
  Walk walk = test::CrowdWalk();
  walk.tracks[0].name =
      "L\xff"
      "1";                                // a byte that never starts a sequence
  walk.tracks[0].character = "ant \xc3";  // a sequence cut short
  walk.tracks[1].character = walk.tracks[0].character;
  walk.tracks[2].character = walk.tracks[0].character;
  walk.stopped = "step 2: \xed\xa0\x80";  // a surrogate, not allowed in UTF-8
  const std::string replacement = "\xEF\xBF\xBD";
  for (const bool binary : {false, true}) {
    INFO("binary " << binary);
    const std::string path = test::ScratchPath(binary ? "utf8.glb" : "utf8.gltf");
    std::string error;
    REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
    const tinygltf::Model model = Load(path, binary);
    REQUIRE(model.nodes.size() == 6);
    CHECK(model.nodes[0].name == "ant " + replacement + "/L" + replacement + "1");
    CHECK(model.nodes[0].extras.Get("track").Get<std::string>() == "L" + replacement + "1");
    CHECK(model.nodes[1].extras.Get("character").Get<std::string>() == "ant " + replacement);
    CHECK(model.nodes[3].name == "ant-2/L1");  // valid names are kept as they are
    REQUIRE(model.animations.size() == 1);
    CHECK(model.animations[0].extras.Get("stopped").Get<std::string>() ==
          "step 2: " + replacement + replacement + replacement);
    std::remove(path.c_str());
  }
}

TEST_CASE("WriteGltf keeps a far walk precise under a root origin node", "[export][gltf]") {
  // A walk on a UTM terrain: float32 near 5e5 steps by 1/32, so keys a few millimetres apart
  // would land on the same float and planted feet slide. The root's double translation plus the
  // children's small floats keep every key.
  const Walk walk = test::FarWalk();
  const Vec3 origin = GltfOrigin(walk);
  CHECK(origin == Vec3{500000, 0, -300000});  // y, within 1024, keeps its values
  CHECK(MaxFloatRounding(walk) < 1e-4);
  const bool binary = GENERATE(false, true);
  const std::string path = test::ScratchPath(binary ? "far.glb" : "far.gltf");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  INFO(path);
  const tinygltf::Model model = Load(path, binary);

  // The track nodes keep their indices; the root comes last and is the scene's only root.
  REQUIRE(model.nodes.size() == 4);
  CHECK(model.nodes[0].name == "L");
  CHECK(model.nodes[2].name == "body");
  const tinygltf::Node& root = model.nodes[3];
  CHECK(root.name == "footfall_origin");
  CHECK(root.children == std::vector<int>{0, 1, 2});
  CHECK(root.rotation.empty());
  CHECK(root.scale.empty());
  CHECK(root.matrix.empty());
  REQUIRE(model.scenes.size() == 1);
  CHECK(model.scenes[0].nodes == std::vector<int>{3});
  CHECK(root.translation == std::vector<double>{origin.x, origin.y, origin.z});
  CHECK(root.extras.Get("kind").Get<std::string>() == "origin");
  const tinygltf::Value& extra_origin = root.extras.Get("origin");
  REQUIRE(extra_origin.ArrayLen() == 3);
  for (int a = 0; a < 3; ++a)
    CHECK(extra_origin.Get(a).GetNumberAsDouble() == root.translation[static_cast<size_t>(a)]);
  if (!binary) {
    // Written as plain JSON numbers (the origin is whole units).
    CHECK(ReadBytes(path).find("500000") != std::string::npos);
  }

  auto channels = Channels(model);
  const std::pair<const char*, std::vector<size_t>> tracks[] = {
      {"L", {0, 1, 2, 3, 4, 5}}, {"R", {0, 1, 3, 4, 5}}, {"body", {0, 1, 2, 3, 4}}};
  double float_only_worst = 0;
  for (size_t t = 0; t < 3; ++t) {
    const WalkTrack& track = walk.tracks[t];
    const std::vector<size_t>& keys = tracks[t].second;
    const Channel& channel = channels[tracks[t].first]["translation"];
    REQUIRE(channel.values.size() == keys.size() * 3);
    for (size_t i = 0; i < keys.size(); ++i) {
      INFO("track " << track.name << " key " << keys[i]);
      const Vec3& want = track.keys[keys[i]].position;
      const float* local = &channel.values[3 * i];
      // The children's floats are offsets of at most a few units on the far axes, and the
      // height (about 120, within 1024) as it is.
      CHECK(std::fabs(local[0]) < 2);
      CHECK(local[1] == static_cast<float>(want.y));
      CHECK(std::fabs(local[2]) < 2);
      const Vec3 world{root.translation[0] + local[0], root.translation[1] + local[1],
                       root.translation[2] + local[2]};
      CHECK(Distance(world, want) < 1e-4);
      // Without the root the same key as float32 misses by more than that.
      const Vec3 float_only{static_cast<float>(want.x), static_cast<float>(want.y),
                            static_cast<float>(want.z)};
      CHECK(Distance(float_only, want) > 1e-4);
      float_only_worst = std::max(float_only_worst, Distance(float_only, want));
    }
    // The rest pose is the first key, relative to the root too.
    const std::vector<double>& rest = model.nodes[t].translation;
    REQUIRE(rest.size() == 3);
    const Vec3 rest_world{root.translation[0] + rest[0], root.translation[1] + rest[1],
                          root.translation[2] + rest[2]};
    CHECK(Distance(rest_world, track.keys[0].position) < 1e-4);
  }
  CHECK(float_only_worst > 0.01);
  CHECK(channels["body"].count("rotation") == 1);
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf adds no root node to a walk near the origin", "[export][gltf]") {
  Walk walk = test::BipedWalk();
  std::string error;
  SECTION("keys within 1024 units keep the flat layout and world floats") {
    for (WalkTrack& t : walk.tracks)
      for (WalkKey& k : t.keys) k.position = k.position + Vec3{-1023, 100, 1023};
    CHECK(GltfOrigin(walk) == Vec3{});
    const std::string path = test::ScratchPath("near.gltf");
    REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
    const tinygltf::Model model = Load(path, false);
    REQUIRE(model.nodes.size() == 3);
    CHECK(model.scenes[0].nodes == std::vector<int>{0, 1, 2});
    for (const tinygltf::Node& node : model.nodes) CHECK(node.children.empty());
    auto channels = Channels(model);
    CheckPositions(channels["L"]["translation"], walk.tracks[0], {0, 1, 2, 3, 4, 5}, 24);
    CHECK(ReadBytes(path).find("footfall_origin") == std::string::npos);
    std::remove(path.c_str());
  }
  SECTION("keys spread either side of the origin: the origin would be 0, so no root") {
    walk.tracks[0].keys[0].position.x = -2000;
    walk.tracks[0].keys[5].position.x = 2000;
    CHECK(GltfOrigin(walk) == Vec3{});
  }
  SECTION("one coordinate beyond 1024 offsets its axis by the rounded centre of the bounds") {
    walk.tracks[2].keys[4].position.y = 1025;     // y bounds [0, 1025]
    CHECK(GltfOrigin(walk) == Vec3{0, 513, 0});   // x and z are within 1024
    walk.tracks[2].keys[4].position.y = -1024.5;  // y bounds [-1024.5, 0.93]
    CHECK(GltfOrigin(walk) == Vec3{0, -512, 0});  // -511.785 rounds to -512
  }
  SECTION("a track named footfall_origin keeps its name; the root is suffixed") {
    walk = test::FarWalk();
    walk.tracks[0].name = "footfall_origin";
    const std::string path = test::ScratchPath("named.glb");
    REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
    const tinygltf::Model model = Load(path, true);
    REQUIRE(model.nodes.size() == 4);
    CHECK(model.nodes[0].name == "footfall_origin");
    CHECK(model.nodes[3].name == "footfall_origin_2");
    CHECK(model.nodes[3].extras.Get("kind").Get<std::string>() == "origin");
    std::remove(path.c_str());
  }
}

TEST_CASE("WriteGltf rejects walks glTF cannot hold", "[export][gltf]") {
  const std::string path = test::ScratchPath("bad.gltf");
  std::string error;
  Walk walk = test::BipedWalk();
  SECTION("a negative frame") {
    walk.tracks[1].keys[0].frame = -2;
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("track 1 'R' key 0 is at frame -2"));
  }
  SECTION("fps not above zero") {
    walk.fps = 0;
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("fps"));
  }
  SECTION("a NaN position") {
    walk.tracks[0].keys[2].position.y = std::nan("");
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("track 0 'L' key 2 has a non-finite position"));
  }
  SECTION("a zero body quaternion") {
    walk.tracks[2].rotations[1] = {0, 0, 0, 0};
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("track 2 'body' key 1 has a zero rotation quaternion"));
  }
  SECTION("distinct frames that float seconds cannot tell apart") {
    // At 1e6 fps from frame 1e9, frames a millionth of a second apart share a float time:
    // merging them silently dropped keys.
    walk.fps = 1e6;
    for (WalkTrack& t : walk.tracks)
      for (WalkKey& k : t.keys) k.frame += 1e9;
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("glTF times are float seconds, and frames 1000000001"));
    CHECK_THAT(error, Catch::Contains("start the walk nearer frame 0 (whatever the fps"));
  }
  SECTION("a body key without its rotation") {
    walk.tracks[2].rotations.pop_back();
    CHECK(WriteGltf(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("track 2 'body' has 4 rotations for 5 keys"));
  }
  std::ifstream written(path);
  CHECK_FALSE(written.good());  // nothing written
}

TEST_CASE("WriteGltf refuses a .glb larger than its 32-bit lengths hold", "[export][gltf]") {
  // (Past 4 GiB tinygltf wrote the lengths wrapped round: a corrupt file, reported written.)
  // The limit lowered to a few kilobytes stands for 4 GiB here.
  const Walk walk = test::CrowdWalk();
  const std::string path = test::ScratchPath("large.glb");
  std::string error;
  GltfOptions options;
  options.binary = true;
  REQUIRE(WriteGltf(walk, path, options, &error) == Status::kOk);
  const double written = static_cast<double>(ReadBytes(path).size());
  std::remove(path.c_str());
  // Refused at one byte below its size: the estimate never falls short of the file.
  options.max_glb_bytes = written - 1;
  CHECK(WriteGltf(walk, path, options, &error) == Status::kLimitExceeded);
  CHECK_THAT(error, Catch::Contains("as .glb, whose lengths are 32-bit"));
  CHECK_THAT(error, Catch::Contains("write .gltf, .json or .mel"));
  CHECK_FALSE(std::ifstream(path).good());  // nothing written
  options.max_glb_bytes = 100 * written;    // within it: written
  CHECK(WriteGltf(walk, path, options, &error) == Status::kOk);
  options.binary = false;  // .gltf has no such limit
  CHECK(WriteGltf(walk, test::ScratchPath("large.gltf"), options, &error) == Status::kOk);
}

TEST_CASE("MaxFloatRounding: how far glTF's float positions move a walk's keys", "[export][gltf]") {
  Walk walk = test::BipedWalk();
  CHECK(MaxFloatRounding(walk) < 1e-7);
  // At UTM-like coordinates floats are a quarter unit apart, but the keys are written relative
  // to the root origin node.
  for (WalkTrack& t : walk.tracks)
    for (WalkKey& k : t.keys) k.position = k.position + Vec3{5e5, 0, 4e6};
  CHECK(GltfOrigin(walk) == Vec3{500000, 0, 4000001});  // z bounds [4e6, 4e6 + 1]
  CHECK(MaxFloatRounding(walk) < 1e-4);
  // A walk spanning 4e6 units: its keys are 2e6 from any one origin, where floats are a quarter
  // unit apart.
  walk.tracks[0].keys[0].position.z = 0.3;
  CHECK(MaxFloatRounding(walk) > 0.01);
  CHECK(MaxFloatRounding(walk) <= 0.25);
}

TEST_CASE("WriteGltf reports unwritable paths as I/O errors", "[export][gltf]") {
  const std::string path = test::ScratchPath("no-such-dir") + "/walk.glb";
  std::string error;
  CHECK(WriteGltf(test::BipedWalk(), path, &error) == Status::kIoError);
  CHECK_THAT(error, Catch::Contains(path));
  CHECK(WriteGltf(test::BipedWalk(), path, nullptr) == Status::kIoError);
}

TEST_CASE("WriteWalk dispatches on the file extension", "[export]") {
  const Walk walk = test::BipedWalk();
  std::string error;
  SECTION("glTF binary for .GLB in any case") {
    const std::string path = test::ScratchPath("upper.GLB");
    REQUIRE(WriteWalk(walk, path, &error) == Status::kOk);
    CHECK(ReadBytes(path).compare(0, 4, "glTF") == 0);
    std::remove(path.c_str());
  }
  SECTION("glTF JSON for .gltf") {
    const std::string path = test::ScratchPath("walk.gltf");
    REQUIRE(WriteWalk(walk, path, &error) == Status::kOk);
    CHECK(ReadBytes(path).front() == '{');
    std::remove(path.c_str());
  }
  SECTION("MEL for .mel") {
    const std::string path = test::ScratchPath("walk.mel");
    REQUIRE(WriteWalk(walk, path, &error) == Status::kOk);
    CHECK(ReadBytes(path).find("spaceLocator") != std::string::npos);
    std::remove(path.c_str());
  }
  SECTION("an unknown extension is an invalid argument naming the path") {
    const std::string path = test::ScratchPath("walk.json");
    CHECK(WriteWalk(walk, path, &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains(path) && Catch::Contains("'.json'") &&
                          Catch::Contains(".gltf, .glb and .mel"));
    CHECK_FALSE(IsWalkExportPath(path));
    CHECK(WriteWalk(walk, test::ScratchPath("dir.mel/walk"), &error) == Status::kInvalidArgument);
    CHECK_THAT(error, Catch::Contains("no extension"));
  }
  CHECK(IsWalkExportPath("a/b.Mel"));
}

TEST_CASE("WriteGltf keys the feet's rotations when asked, each foot on its ground",
          "[export][gltf]") {
  const Walk walk = test::TiltedFootWalk();
  const std::string path = test::ScratchPath("feet.gltf");
  std::string error;
  REQUIRE(WriteGltf(walk, path, &error) == Status::kOk);
  CHECK(Channels(Load(path, false))["L"].count("rotation") == 0);  // not unless asked
  GltfOptions options;
  options.foot_rotations = true;
  REQUIRE(WriteGltf(walk, path, options, &error) == Status::kOk);
  auto channels = Channels(Load(path, false));
  REQUIRE(channels["L"].count("rotation") == 1);
  const Channel& rotation = channels["L"]["rotation"];
  CHECK(rotation.times == channels["L"]["translation"].times);
  const std::vector<test::FootAxes> axes = test::TiltedFootAxes();
  REQUIRE(rotation.values.size() == 4 * axes.size());
  for (size_t i = 0; i < axes.size(); ++i) {
    const float* v = &rotation.values[4 * i];
    const Quat q{v[0], v[1], v[2], v[3]};
    CHECK(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) ==
          Approx(1).margin(1e-6));
    const Vec3 up = test::Rotated(q, {0, 1, 0}), forward = test::Rotated(q, {0, 0, 1});
    INFO("key " << i);
    CHECK(Distance(up, axes[i].up) < 1e-6);
    CHECK(Distance(forward, axes[i].forward) < 1e-6);
  }
  std::remove(path.c_str());
}

TEST_CASE("WriteGltf converts a walk in another unit to metres", "[export][gltf]") {
  // glTF's unit is the metre: a walk in centimetres (a character scaled onto a terrain in
  // centimetres) was read 100 times too large by Blender and Unreal.
  Walk walk = test::FarWalk();
  walk.tracks[0].foot_length = 25, walk.tracks[0].foot_width = 10;
  const std::string metres_path = test::ScratchPath("far_m.glb");
  const std::string cm_path = test::ScratchPath("far_cm.glb");
  std::string error;
  GltfOptions metres;
  metres.binary = true;
  REQUIRE(WriteGltf(walk, metres_path, metres, &error) == Status::kOk);
  Walk in_cm = walk;
  in_cm.unit = "cm";
  REQUIRE(WriteGltf(in_cm, cm_path, metres, &error) == Status::kOk);
  const tinygltf::Model a = Load(metres_path, true), b = Load(cm_path, true);
  REQUIRE(a.nodes.size() == b.nodes.size());
  // The far walk (5e5 cm is 5 km) still has its origin node, in metres.
  const std::vector<double>& origin = b.nodes.back().translation;
  REQUIRE(origin.size() == 3);
  CHECK(origin == std::vector<double>{5000, 0, -3000});
  CHECK(b.nodes[0].extras.Get("foot_length").GetNumberAsDouble() == 0.25);
  CHECK(b.nodes[0].extras.Get("foot_width").GetNumberAsDouble() == Approx(0.1).epsilon(1e-12));
  auto ca = Channels(a), cb = Channels(b);
  const std::vector<double>& far_origin = a.nodes.back().translation;
  for (const char* node : {"L", "R", "body"}) {
    INFO(node);
    const Channel &ta = ca[node]["translation"], &tb = cb[node]["translation"];
    CHECK(ta.times == tb.times);
    REQUIRE(ta.values.size() == tb.values.size());
    for (size_t i = 0; i < ta.values.size(); ++i) {
      const size_t axis = i % 3;
      const double world_cm = far_origin[axis] + ta.values[i];
      const double world_m = origin[axis] + tb.values[i];
      CHECK(world_m == Approx(world_cm / 100).margin(1e-6));
    }
    // Rotations are the same.
    CHECK(ca[node].count("rotation") == cb[node].count("rotation"));
    if (ca[node].count("rotation"))
      CHECK(ca[node]["rotation"].values == cb[node]["rotation"].values);
  }
  // "m" is the same file as none; an unknown unit is refused, naming the units known.
  Walk in_m = walk;
  in_m.unit = "m";
  const std::string m_path = test::ScratchPath("far_named_m.glb");
  REQUIRE(WriteGltf(in_m, m_path, metres, &error) == Status::kOk);
  CHECK(ReadBytes(m_path) == ReadBytes(metres_path));
  Walk in_furlongs = walk;
  in_furlongs.unit = "furlong";
  const std::string bad_path = test::ScratchPath("far_furlong.glb");
  CHECK(WriteGltf(in_furlongs, bad_path, metres, &error) == Status::kInvalidArgument);
  CHECK_THAT(error, Catch::Contains("the walk's unit 'furlong' is none of mm, cm, m, km, in, ft, "
                                    "yd or mi"));
  CHECK_FALSE(std::ifstream(bad_path).good());
  for (const std::string& path : {metres_path, cm_path, m_path}) std::remove(path.c_str());
}
