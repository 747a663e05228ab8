// The live view's pieces without a run: the address parser, the Foxglove messages and framing,
// and the server against a Beast WebSocket client in the same process (the newest-wins queue
// with a client that stops reading, and a Stop that does not wait for it).
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "ademono/core/error.h"
#include "ademono/live/foxglove.h"
#include "ademono/live/live_server.h"

namespace ademono::live {
namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

TEST(LiveAddressTest, ParsesHostAndPort) {
  EXPECT_EQ(ParseLiveAddress("8765").host, "127.0.0.1");
  EXPECT_EQ(ParseLiveAddress("8765").port, 8765);
  EXPECT_EQ(ParseLiveAddress("0").port, 0);
  EXPECT_EQ(ParseLiveAddress("0.0.0.0:9000").host, "0.0.0.0");
  EXPECT_EQ(ParseLiveAddress("[::1]:8080").host, "::1");
  EXPECT_EQ(ParseLiveAddress("localhost:1").host, "localhost");
  for (const char* bad : {"", "abc", "1.2.3:80", "99999", "host:", ":80", "127.0.0.1:80:1",
                          "example.com:80"}) {
    EXPECT_THROW(ParseLiveAddress(bad), InputError) << bad;
  }
}

TEST(FoxgloveTest, Base64AndFraming) {
  const std::string text = "foobar";
  const auto* bytes = reinterpret_cast<const uint8_t*>(text.data());
  EXPECT_EQ(Base64(bytes, 0), "");
  EXPECT_EQ(Base64(bytes, 1), "Zg==");
  EXPECT_EQ(Base64(bytes, 2), "Zm8=");
  EXPECT_EQ(Base64(bytes, 6), "Zm9vYmFy");
  const std::string h = MessageDataHeader(0x01020304, 0x1122334455667788ULL);
  ASSERT_EQ(h.size(), 13u);
  EXPECT_EQ(static_cast<uint8_t>(h[0]), 1);
  EXPECT_EQ(static_cast<uint8_t>(h[1]), 0x04);
  EXPECT_EQ(static_cast<uint8_t>(h[4]), 0x01);
  EXPECT_EQ(static_cast<uint8_t>(h[5]), 0x88);
  EXPECT_EQ(static_cast<uint8_t>(h[12]), 0x11);
  EXPECT_EQ(ToNanoseconds(1.5), 1500000000ULL);
  EXPECT_EQ(ToNanoseconds(-1), 0ULL);
}

TEST(FoxgloveTest, AdvertisesEveryChannelWithItsSchema) {
  const json advertise = json::parse(AdvertiseJson());
  ASSERT_EQ(advertise["op"], "advertise");
  ASSERT_EQ(advertise["channels"].size(), kNumChannels);
  for (const json& c : advertise["channels"]) {
    const json schema = json::parse(c["schema"].get<std::string>());
    EXPECT_EQ(schema["title"], c["schemaName"]) << c["topic"];  // npm @foxglove/schemas' title
    EXPECT_EQ(c["encoding"], "json");
    EXPECT_EQ(c["schemaEncoding"], "jsonschema");
  }
  EXPECT_EQ(Info(Channel::kMap).schema_name, std::string("foxglove.PointCloud"));
}

LiveMap TestMap(size_t points) {
  LiveMap map;
  map.timestamp = 12.25;
  for (size_t i = 0; i < points; ++i)
    map.points.push_back({Eigen::Vector3f(i * 0.5f, 1, 2), i % 2 == 0 ? 1.0f : 0.0f});
  Rigid3d a = Rigid3d::Identity(), b = Rigid3d::Identity();
  b.translation() = Eigen::Vector3d(1, 0, 0);
  map.trajectory = {{12.0, a}, {12.25, b}};
  map.keyframes = {{12.0, a}};
  map.loops = {{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 0)}};
  return map;
}

TEST(FoxgloveTest, PointCloudPacksPositionColourAndProbability) {
  const json cloud = json::parse(PointCloudJson(TestMap(3)));
  EXPECT_EQ(cloud["point_stride"], 20);
  EXPECT_EQ(cloud["timestamp"]["sec"], 12);
  EXPECT_EQ(cloud["timestamp"]["nsec"], 250000000);
  EXPECT_EQ(cloud["fields"].size(), 8u);
  // 3 points x 20 bytes = 60 bytes = 80 base64 characters.
  EXPECT_EQ(cloud["data"].get<std::string>().size(), 80u);
  uint8_t rgb[3];
  StaticProbabilityColor(1.0f, rgb);
  EXPECT_EQ(rgb[0], 0);
  EXPECT_GT(rgb[1], 200);
  StaticProbabilityColor(0.0f, rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_EQ(rgb[1], 0);
}

TEST(FoxgloveTest, SceneHasKeyframesPathAndLoops) {
  const json scene = json::parse(SceneJson(TestMap(0)));
  ASSERT_EQ(scene["entities"].size(), 3u);
  EXPECT_EQ(scene["entities"][0]["id"], "keyframes");
  EXPECT_EQ(scene["entities"][0]["cubes"].size(), 1u);
  EXPECT_EQ(scene["entities"][1]["lines"][0]["points"].size(), 2u);
  EXPECT_EQ(scene["entities"][2]["lines"][0]["type"], 2);  // LINE_LIST
  const json trajectory = json::parse(TrajectoryJson(TestMap(0)));
  EXPECT_EQ(trajectory["poses"][1]["position"]["x"], 1.0);
}

LiveFrame TestFrame(size_t index) {
  LiveFrame f;
  f.frame = index;
  f.timestamp = 1.0 + index * 0.033;
  f.tracked = true;
  f.state = TrackingState::kOk;
  f.cam_from_world = Rigid3d::Identity();
  f.points = {{10, 20}, {30, 40}, {50, 60}};
  f.labels = {PointLabel::kKept, PointLabel::kKept, PointLabel::kDynamicStage1};
  Detection d;
  d.box = cv::Rect2f(5, 6, 70, 80);
  d.class_name = "person";
  d.score = 0.9f;
  f.detections = {d};
  f.inliers = 2;
  return f;
}

TEST(FoxgloveTest, FrameMessages) {
  const LiveFrame f = TestFrame(7);
  const json stats = json::parse(FrameStatsJson(f));
  EXPECT_EQ(stats["frame"], 7);
  EXPECT_EQ(stats["state"], "ok");
  EXPECT_EQ(stats["labels"]["kept"], 2);
  EXPECT_TRUE(stats["depth_scale"].is_null());
  EXPECT_TRUE(stats["scale_sigma"].is_null());
  LiveFrame scaled = TestFrame(8);
  scaled.depth_scale = 1.1;
  scaled.scale_sigma = 0.02;
  const json scaled_stats = json::parse(FrameStatsJson(scaled));
  EXPECT_DOUBLE_EQ(scaled_stats["depth_scale"].get<double>(), 1.1);
  EXPECT_DOUBLE_EQ(scaled_stats["scale_sigma"].get<double>(), 0.02);
  const json annotations = json::parse(ImageAnnotationsJson(f));
  ASSERT_EQ(annotations["points"].size(), 3u);  // kept, stage 1, the box
  EXPECT_EQ(annotations["points"][0]["points"].size(), 2u);
  EXPECT_EQ(annotations["points"][2]["type"], 2);  // LINE_LOOP
  EXPECT_EQ(annotations["texts"][0]["text"], "person 0.90");
  const json tf = json::parse(TransformJson(f));
  EXPECT_EQ(tf["parent_frame_id"], "world");
  EXPECT_EQ(tf["rotation"]["w"], 1.0);
}

// A Foxglove client on a Beast WebSocket, synchronous.
class Client {
 public:
  explicit Client(uint16_t port) : ws_(ioc_) {
    tcp::resolver resolver(ioc_);
    net::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
      req.set(beast::http::field::sec_websocket_protocol, "foxglove.websocket.v1");
    }));
    ws_.handshake("127.0.0.1", "/");
  }
  // The next message: text as JSON; binary as {"sub", "payload"}.
  json Read() {
    beast::flat_buffer buffer;
    ws_.read(buffer);
    const std::string data = beast::buffers_to_string(buffer.data());
    if (ws_.got_text()) return json::parse(data);
    const uint32_t sub = static_cast<uint8_t>(data[1]) | static_cast<uint8_t>(data[2]) << 8 |
                         static_cast<uint8_t>(data[3]) << 16 | static_cast<uint8_t>(data[4]) << 24;
    return {{"sub", sub}, {"payload", json::parse(data.substr(13))}};
  }
  void Send(const json& message) {
    ws_.text(true);
    ws_.write(net::buffer(message.dump()));
  }
  void Subscribe(uint32_t id, Channel channel) {
    Send({{"op", "subscribe"},
          {"subscriptions", {{{"id", id}, {"channelId", static_cast<uint32_t>(channel)}}}}});
  }
  websocket::stream<tcp::socket>& Stream() { return ws_; }

 private:
  net::io_context ioc_;
  websocket::stream<tcp::socket> ws_;
};

void WaitFor(const std::function<bool()>& condition) {
  for (int i = 0; i < 500 && !condition(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

TEST(LiveServerTest, ServesSubscribersAndDropsForAStalledOne) {
  LiveOptions options;
  options.port = 0;  // any free port
  LiveServer server(options);
  ASSERT_GT(server.Port(), 0);
  EXPECT_FALSE(server.WantsFrames());

  Client reader(server.Port());
  EXPECT_EQ(reader.Read()["op"], "serverInfo");
  EXPECT_EQ(reader.Read()["op"], "advertise");
  reader.Subscribe(41, Channel::kFrameStats);
  reader.Subscribe(42, Channel::kMap);
  WaitFor([&] { return server.WantsMapSnapshot(false); });
  EXPECT_TRUE(server.WantsFrames());
  EXPECT_FALSE(server.WantsImages());  // nobody subscribed to images

  // Out of order: unsubscribing what was never subscribed is an error; the connection lives on.
  reader.Send({{"op", "unsubscribe"}, {"subscriptionIds", {99}}});
  const json status = reader.Read();
  EXPECT_EQ(status["op"], "status");
  EXPECT_EQ(status["level"], 2);

  server.OnFrame(TestFrame(0));
  const json first = reader.Read();
  EXPECT_EQ(first["sub"], 41);
  EXPECT_EQ(first["payload"]["frame"], 0);

  // A second client subscribes to the map and stops reading: big clouds pile up for it until
  // the socket buffers are full, then only the newest waits and the rest are dropped.
  Client stalled(server.Port());
  stalled.Read();
  stalled.Read();
  stalled.Subscribe(1, Channel::kMap);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const LiveMap big = TestMap(60000);  // 1.6 MB of JSON per cloud
  for (int i = 0; i < 60; ++i) {
    server.OnMap(big);
    // The reader keeps up: it gets every cloud (latest first is fine), the stalled one does not.
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
  }
  server.OnFrame(TestFrame(1));
  // The reader still gets frame 1 after whatever clouds it had pending.
  for (int i = 0; i < 200; ++i) {
    const json m = reader.Read();
    if (m["sub"] == 41) {
      EXPECT_EQ(m["payload"]["frame"], 1);
      break;
    }
  }
  WaitFor([&] { return server.Stats()["messages_dropped"].get<uint64_t>() > 0; });
  const json stats = server.Stats();
  EXPECT_GT(stats["messages_dropped"].get<uint64_t>(), 0u) << stats.dump();
  EXPECT_EQ(stats["clients"], 2);
  EXPECT_EQ(stats["client_errors"], 1);

  // Stop does not wait for the stalled client longer than its close handshake allows.
  const auto start = std::chrono::steady_clock::now();
  server.Stop();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
}

TEST(LiveServerTest, RejectsABusyPortWithAnInputError) {
  LiveOptions options;
  options.port = 0;
  LiveServer first(options);
  options.port = first.Port();
  EXPECT_THROW(LiveServer second(options), InputError);
}

TEST(LiveServerTest, NewSubscriberGetsTheLatchedFinalState) {
  LiveOptions options;
  options.port = 0;
  LiveServer server(options);
  LiveEnd end;
  end.frames = 3;
  end.tracked = 2;
  server.OnEnd(TestMap(5), end);
  server.Linger(0);  // no client: returns at once
  Client late(server.Port());
  late.Read();
  late.Read();
  late.Subscribe(7, Channel::kRunStatus);
  const json status = late.Read();
  EXPECT_EQ(status["sub"], 7);
  EXPECT_EQ(status["payload"]["state"], "finished");
  EXPECT_EQ(status["payload"]["tracked"], 2);
}

}  // namespace
}  // namespace ademono::live
