#pragma once
// The live view of a run (docs/live.md): a Foxglove WebSocket server (subprotocol
// foxglove.websocket.v1, JSON encoding, live/foxglove.h's channels) and, on the same port, a page
// at http://HOST:PORT/ that draws the run with the report's libraries (uPlot, regl). Boost.Beast
// over Boost.Asio, on one thread of its own.
//
// It is a RunObserver (runner/live_feed.h): the tracking thread hands it copies and returns at
// once. Whatever the clients do, the run does not wait for them and its outputs do not change:
// - the hand-off to the server thread is a short bounded queue (the oldest frame is skipped when
//   the server falls behind: frames_skipped);
// - each client has one pending message per channel: a client that reads slower than the run
//   gets the newest message of each channel, the ones it replaced are dropped (messages_dropped);
// - JPEG encoding and JSON happen on the server thread, images only while someone subscribes to
//   them, at most `image_hz` per second, map snapshots at most `map_hz`;
// - a client that sends malformed, oversized or out-of-order messages gets a status error, and
//   is disconnected after `max_client_errors` of them (oversized: at once, close code 1009).

#include <atomic>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "ademono/runner/live_feed.h"

namespace ademono::live {

struct LiveOptions {
  std::string host = "127.0.0.1";  // another address only by the user's explicit choice
  uint16_t port = 8765;            // 0: any free port (Port() tells which)
  double image_hz = 10;            // images and their annotations at most this often (wall)
  // Map snapshots (cloud, trajectory, scene) at most this often while the run goes on; the final
  // one always. Encoding and parsing a cloud is the view's largest cost.
  double map_hz = 2;
  int jpeg_quality = 80;
  size_t max_clients = 16;
  size_t max_client_message = 64 * 1024;  // bytes; larger client messages close the connection
  int max_client_errors = 20;
  std::string name = "ademono";  // serverInfo's name
};
// "[HOST:]PORT" (HOST: IPv4/IPv6 address or "localhost"; "[::1]:PORT" for IPv6). InputError
// naming the argument when it is not one.
LiveOptions ParseLiveAddress(const std::string& text);

class LiveServer final : public RunObserver {
 public:
  // Binds and starts serving; InputError when the address cannot be bound (port in use).
  explicit LiveServer(const LiveOptions& options);
  ~LiveServer() override;  // Stop()
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  uint16_t Port() const;
  std::string Url() const;  // http://HOST:PORT/

  // Blocks until `clients` clients are ready (subscribed to every channel, or 1 s after their
  // first subscription) or *stop is set. True when they are.
  bool WaitForClients(size_t clients, const std::atomic<bool>* stop);
  // After OnEnd: serves until every client has disconnected, or has been sent every message and
  // `seconds` have passed; a stalled client holds it at most max(seconds, 5 s).
  void Linger(double seconds, const std::atomic<bool>* stop = nullptr);
  // Closes every connection and the port. Idempotent.
  void Stop();
  // {"url", "clients" (connections accepted), "messages_sent", "messages_dropped",
  //  "frames_skipped", "client_errors", "bytes_sent"}.
  nlohmann::json Stats() const;

  // RunObserver (any thread; they only queue).
  bool WantsFrames() const override;
  bool WantsImages() const override;
  bool WantsMapSnapshot(bool map_changed) override;
  void OnFrame(LiveFrame frame) override;
  void OnMap(LiveMap map) override;
  void OnEnd(LiveMap final_map, const LiveEnd& end) override;

  class Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace ademono::live
