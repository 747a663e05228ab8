#pragma once
// The live view's messages: Foxglove's well-known schemas (npm @foxglove/schemas, compiled in as
// JSON schemas by CMake from .deps/foxglove/schemas) and ademono's own two, JSON-encoded, and the
// binary framing of the Foxglove WebSocket protocol (foxglove.websocket.v1). Pure functions, no
// networking: live_server.h sends what these make.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "ademono/runner/live_feed.h"

namespace ademono::live {

// The channels a live server advertises, in id order (ids 1..kNumChannels).
enum class Channel : uint32_t {
  kTransform = 1,   // /tf                    foxglove.FrameTransform   world -> camera
  kPose,            // /camera/pose           foxglove.PoseInFrame
  kTrajectory,      // /trajectory            foxglove.PosesInFrame     every tracked frame so far
  kMap,             // /map                   foxglove.PointCloud       when the map changes
  kImage,           // /camera/image          foxglove.CompressedImage  JPEG
  kAnnotations,     // /camera/annotations    foxglove.ImageAnnotations keypoints by label, boxes
  kScene,           // /scene                 foxglove.SceneUpdate      keyframes, loops, path
  kFrameStats,      // /ademono/frame         ademono.FrameStats        per-frame numbers
  kRunStatus,       // /ademono/run           ademono.RunStatus         waiting, running, finished
};
inline constexpr uint32_t kNumChannels = 9;

struct ChannelInfo {
  Channel id;
  const char* topic;
  const char* schema_name;
  std::string_view schema;  // JSON schema text
  bool latched;  // a new subscriber gets the last message at once (it only changes now and then)
};
const std::vector<ChannelInfo>& Channels();
const ChannelInfo& Info(Channel channel);

// Control messages (JSON text frames).
std::string ServerInfoJson(const std::string& name);
std::string AdvertiseJson();
// level: 0 info, 1 warning, 2 error.
std::string StatusJson(int level, const std::string& message);

// Message payloads (JSON), each valid against its channel's schema.
std::string TransformJson(const LiveFrame& frame);  // frame.cam_from_world must be set
std::string PoseJson(const LiveFrame& frame);
std::string TrajectoryJson(const LiveMap& map);
std::string PointCloudJson(const LiveMap& map);
// `jpeg`: the encoded image.
std::string CompressedImageJson(const LiveFrame& frame, const std::vector<uint8_t>& jpeg);
std::string ImageAnnotationsJson(const LiveFrame& frame);
std::string SceneJson(const LiveMap& map);
std::string FrameStatsJson(const LiveFrame& frame);
// state: "waiting" (for clients, --live-wait-clients), "running" or "finished" (with `end`).
std::string RunStatusJson(const std::string& state, double timestamp, const LiveEnd* end);

// Binary "message data" frame: opcode 1, subscription id (u32 LE), log time ns (u64 LE), then
// the payload. Only the 13-byte header; the payload follows it on the wire.
std::string MessageDataHeader(uint32_t subscription_id, uint64_t log_time_ns);
uint64_t ToNanoseconds(double seconds);

// Colour of a map point by its static probability: red (moving) through yellow to green.
void StaticProbabilityColor(float p, uint8_t rgb[3]);
// RFC 4648 base64 (JSON has no bytes: Foxglove's schemas say contentEncoding base64).
std::string Base64(const uint8_t* data, size_t size);

}  // namespace ademono::live
