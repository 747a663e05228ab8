#include "ademono/live/live_server.h"

#include <algorithm>
#include <array>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <regex>
#include <thread>

#include "ademono/core/error.h"
#include "ademono/core/thread_name.h"
#include "ademono/live/foxglove.h"
#include "ademono/report/web_assets.h"

// The live page (web/), compiled in by CMake.
namespace ademono::live::web {
extern const std::string_view kLiveHtml, kLiveJs, kLiveCss;
}  // namespace ademono::live::web

namespace ademono::live {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

namespace {

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr size_t kMaxControlQueue = 64;  // status replies queued to one client
constexpr size_t kMaxInboxFrames = 8;    // frames queued from the tracking thread
constexpr auto kReadyAfterFirstSubscribe = std::chrono::seconds(1);

// The page with every script and style inlined (as the report does): one request, no files.
std::string LivePage() {
  std::string page(web::kLiveHtml);
  auto replace = [&page](const std::string& marker, const std::string& text) {
    const size_t at = page.find(marker);
    if (at == std::string::npos) throw std::logic_error("live.html lacks " + marker);
    page.replace(at, marker.size(), text);
  };
  replace("<!--STYLE-->", "<style>" + std::string(ademono::web::kUplotCss) + "\n" +
                              std::string(web::kLiveCss) + "</style>");
  replace("<!--SCRIPTS-->", "<script>/* uPlot (MIT)\n" + std::string(ademono::web::kUplotLicense) +
                                "*/\n" + std::string(ademono::web::kUplotJs) +
                                "</script>\n<script>/* regl (MIT)\n" +
                                std::string(ademono::web::kReglLicense) + "*/\n" +
                                std::string(ademono::web::kReglJs) + "</script>\n<script>" +
                                std::string(web::kLiveJs) + "</script>");
  return page;
}

bool OffersSubprotocol(std::string_view header) {
  // A comma-separated list of tokens.
  size_t start = 0;
  while (start <= header.size()) {
    size_t end = header.find(',', start);
    if (end == std::string_view::npos) end = header.size();
    std::string_view token = header.substr(start, end - start);
    while (!token.empty() && (token.front() == ' ' || token.front() == '\t'))
      token.remove_prefix(1);
    while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) token.remove_suffix(1);
    if (token == kSubprotocol) return true;
    start = end + 1;
  }
  return false;
}

struct Pending {
  std::shared_ptr<const std::string> payload;
  uint64_t log_time = 0;
  uint64_t seq = 0;
};

}  // namespace

class Session;

class LiveServer::Impl : public std::enable_shared_from_this<LiveServer::Impl> {
 public:
  explicit Impl(const LiveOptions& o) : options(o), page(LivePage()) {}

  void Start();
  void Accept();
  void Tick();
  void PostDrain();
  void Drain();
  void Publish(Channel channel, std::shared_ptr<const std::string> payload, uint64_t log_time);
  void PublishStatus(const std::string& state, double timestamp, const LiveEnd* end);
  void Remove(Session* session);
  void UpdateReadiness();
  bool Subscribed(Channel c) const {
    return subscribers[static_cast<uint32_t>(c)].load(std::memory_order_relaxed) > 0;
  }

  LiveOptions options;
  std::string page;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  net::steady_timer tick{ioc};
  std::thread thread;
  tcp::endpoint endpoint;

  // Server thread only.
  std::vector<std::shared_ptr<Session>> sessions;  // open WebSocket connections
  std::vector<std::weak_ptr<Session>> all_sessions;  // every connection (Stop cuts them)
  std::map<uint32_t, std::pair<std::shared_ptr<const std::string>, uint64_t>> latched;
  uint64_t next_seq = 0;
  std::string run_state;
  Clock::time_point last_annotations{};
  bool stopping = false;

  // Shared with the tracking thread and the caller.
  std::array<std::atomic<int>, kNumChannels + 1> subscribers{};
  std::atomic<size_t> connected{0}, ready{0};
  std::atomic<bool> map_refresh{false};
  std::atomic<int64_t> next_image_ns{0}, next_map_ns{0};
  std::atomic<bool> ended{false}, flushed_after_end{false};
  std::atomic<uint64_t> accepted{0}, sent{0}, dropped{0}, skipped{0}, errors{0}, bytes{0};
  std::mutex inbox_mutex;
  std::deque<LiveFrame> inbox_frames;
  std::optional<LiveMap> inbox_map;
  std::optional<std::pair<LiveMap, LiveEnd>> inbox_end;
  bool drain_posted = false;
};

// One connection: first an HTTP request (the page, or the WebSocket upgrade), then the Foxglove
// protocol. Every member is touched on the server thread only.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket socket, LiveServer::Impl* server)
      : stream_(std::move(socket)), server_(server) {}

  void Start() {
    stream_.expires_after(std::chrono::seconds(10));
    http::async_read(stream_, buffer_, request_,
                     [self = shared_from_this()](beast::error_code ec, size_t) {
                       self->OnRequest(ec);
                     });
  }

  bool IsWebSocket() const { return ws_.has_value() && open_; }
  bool Flushed() const { return !writing_ && control_.empty() && pending_.empty(); }
  bool Ready(Clock::time_point now) const {
    if (by_channel_.size() == kNumChannels) return true;
    return first_subscribe_ && now - *first_subscribe_ >= kReadyAfterFirstSubscribe;
  }
  bool SubscribedTo(Channel c) const { return by_channel_.count(static_cast<uint32_t>(c)) != 0; }

  void Enqueue(Channel channel, const std::shared_ptr<const std::string>& payload,
               uint64_t log_time, uint64_t seq) {
    if (!open_ || closing_) return;
    const uint32_t id = static_cast<uint32_t>(channel);
    if (!by_channel_.count(id)) return;
    auto [it, inserted] = pending_.try_emplace(id);
    if (!inserted) ++server_->dropped;  // newest wins: the one not yet sent is replaced
    it->second = {payload, log_time, seq};
    Write();
  }

  void Close(websocket::close_code code = websocket::close_code::normal) {
    if (!ws_ || closing_) return;
    closing_ = true;
    close_code_ = code;
    pending_.clear();
    control_.clear();
    if (!writing_) StartClose();
  }

  // The server is going away and the close handshake did not finish: drop the connection.
  void Abort() {
    beast::error_code ec;
    if (ws_) {
      beast::get_lowest_layer(*ws_).socket().close(ec);
    } else {
      stream_.socket().close(ec);
    }
    Gone();
  }

 private:
  void OnRequest(beast::error_code ec) {
    if (ec) return Gone();  // garbage, a timeout or a closed socket: nothing to answer
    if (websocket::is_upgrade(request_)) {
      const beast::string_view offered = request_[http::field::sec_websocket_protocol];
      if (!OffersSubprotocol(std::string_view(offered.data(), offered.size())))
        return Respond(http::status::bad_request, "text/plain",
                       "the live server speaks the WebSocket subprotocol foxglove.websocket.v1\n");
      if (server_->connected.load() >= server_->options.max_clients)
        return Respond(http::status::service_unavailable, "text/plain", "too many clients\n");
      ws_.emplace(std::move(stream_));
      beast::get_lowest_layer(*ws_).expires_never();
      websocket::stream_base::timeout timeout =
          websocket::stream_base::timeout::suggested(beast::role_type::server);
      timeout.handshake_timeout = std::chrono::seconds(5);
      timeout.idle_timeout = std::chrono::seconds(30);
      timeout.keep_alive_pings = true;  // a client that stops reading is closed after 30 s
      ws_->set_option(timeout);
      ws_->read_message_max(server_->options.max_client_message);
      ws_->set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
        res.set(http::field::sec_websocket_protocol, kSubprotocol);
        res.set(http::field::server, "ademono live");
      }));
      ws_->async_accept(request_, [self = shared_from_this()](beast::error_code e) {
        self->OnAccept(e);
      });
      return;
    }
    const std::string target(request_.target());
    const std::string path = target.substr(0, target.find('?'));
    if (request_.method() != http::verb::get && request_.method() != http::verb::head)
      return Respond(http::status::method_not_allowed, "text/plain", "GET only\n");
    if (path == "/" || path == "/index.html")
      return Respond(http::status::ok, "text/html; charset=utf-8", server_->page);
    return Respond(http::status::not_found, "text/plain", "not found\n");
  }

  void Respond(http::status status, const char* type, const std::string& body) {
    auto response = std::make_shared<http::response<http::string_body>>(status, request_.version());
    response->set(http::field::server, "ademono live");
    response->set(http::field::content_type, type);
    response->set(http::field::cache_control, "no-store");
    response->keep_alive(false);
    if (request_.method() != http::verb::head) response->body() = body;
    response->prepare_payload();
    stream_.expires_after(std::chrono::seconds(10));
    http::async_write(stream_, *response,
                      [self = shared_from_this(), response](beast::error_code, size_t) {
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                        self->Gone();
                      });
  }

  void OnAccept(beast::error_code ec) {
    if (ec) return Gone();
    if (server_->stopping) return Close(websocket::close_code::going_away);
    open_ = true;
    ++server_->connected;
    ++server_->accepted;
    server_->sessions.push_back(shared_from_this());
    SendControl(ServerInfoJson(server_->options.name));
    SendControl(AdvertiseJson());
    Read();
  }

  void Read() {
    ws_->async_read(read_buffer_, [self = shared_from_this()](beast::error_code ec, size_t) {
      self->OnRead(ec);
    });
  }

  void OnRead(beast::error_code ec) {
    if (ec) {
      // A protocol violation (too big: Beast has sent close 1009; bad UTF-8 or framing: 1002 /
      // 1007) counts as the client's error; otherwise the peer closed or went away.
      if (ec != websocket::error::closed && ec != net::error::eof &&
          ec != net::error::operation_aborted && ec != net::error::connection_reset &&
          ec != beast::error::timeout)
        ++server_->errors;
      return Gone();
    }
    const std::string text = beast::buffers_to_string(read_buffer_.data());
    read_buffer_.consume(read_buffer_.size());
    if (!ws_->got_text()) {
      Error("binary client messages are not accepted (the server advertises no clientPublish)");
    } else {
      HandleText(text);
    }
    if (!closing_) Read();
  }

  void Error(const std::string& message) {
    ++server_->errors;
    if (++client_errors_ > server_->options.max_client_errors) {
      Close(websocket::close_code::policy_error);
      return;
    }
    SendControl(StatusJson(2, message));
  }

  static bool Uint32(const json& j, uint32_t* out) {
    if (!j.is_number_unsigned() && !(j.is_number_integer() && j.get<int64_t>() >= 0)) return false;
    const uint64_t v = j.get<uint64_t>();
    if (v > UINT32_MAX) return false;
    *out = static_cast<uint32_t>(v);
    return true;
  }

  void HandleText(const std::string& text) {
    const json message = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (message.is_discarded()) return Error("malformed JSON");
    if (!message.is_object() || !message.contains("op") || !message["op"].is_string())
      return Error("a client message is a JSON object with a string \"op\"");
    const std::string op = message["op"].get<std::string>();
    if (op == "subscribe") {
      if (!message.contains("subscriptions") || !message["subscriptions"].is_array())
        return Error("subscribe: \"subscriptions\" must be an array");
      for (const json& s : message["subscriptions"]) {
        uint32_t id = 0, channel = 0;
        if (!s.is_object() || !s.contains("id") || !s.contains("channelId") ||
            !Uint32(s["id"], &id) || !Uint32(s["channelId"], &channel)) {
          Error("subscribe: each subscription is {\"id\": uint32, \"channelId\": uint32}");
          continue;
        }
        if (channel < 1 || channel > kNumChannels) {
          Error("subscribe: no channel " + std::to_string(channel));
          continue;
        }
        if (by_id_.count(id)) {
          Error("subscribe: subscription id " + std::to_string(id) + " is already in use");
          continue;
        }
        if (by_channel_.count(channel)) {
          Error("subscribe: already subscribed to channel " + std::to_string(channel));
          continue;
        }
        by_id_[id] = channel;
        by_channel_[channel] = id;
        ++server_->subscribers[channel];
        if (!first_subscribe_) first_subscribe_ = Clock::now();
        const Channel c = static_cast<Channel>(channel);
        if (c == Channel::kMap || c == Channel::kTrajectory || c == Channel::kScene)
          server_->map_refresh = true;
        if (auto it = server_->latched.find(channel); it != server_->latched.end())
          Enqueue(c, it->second.first, it->second.second, server_->next_seq++);
      }
      server_->UpdateReadiness();
    } else if (op == "unsubscribe") {
      if (!message.contains("subscriptionIds") || !message["subscriptionIds"].is_array())
        return Error("unsubscribe: \"subscriptionIds\" must be an array");
      for (const json& s : message["subscriptionIds"]) {
        uint32_t id = 0;
        if (!Uint32(s, &id)) {
          Error("unsubscribe: subscription ids are uint32");
          continue;
        }
        const auto it = by_id_.find(id);
        if (it == by_id_.end()) {
          Error("unsubscribe: no subscription " + std::to_string(id));
          continue;
        }
        Unsubscribe(it->second);
      }
    } else if (op == "advertise" || op == "unadvertise" || op == "getParameters" ||
               op == "setParameters" || op == "subscribeParameterUpdates" ||
               op == "unsubscribeParameterUpdates" || op == "subscribeConnectionGraph" ||
               op == "unsubscribeConnectionGraph" || op == "fetchAsset") {
      Error(op + ": not supported (the server advertises no capabilities)");
    } else {
      Error("unknown op \"" + op.substr(0, 64) + "\"");
    }
  }

  void Unsubscribe(uint32_t channel) {
    const auto c = by_channel_.find(channel);
    if (c == by_channel_.end()) return;
    by_id_.erase(c->second);
    by_channel_.erase(c);
    pending_.erase(channel);
    --server_->subscribers[channel];
  }

  void SendControl(std::string text) {
    if (!open_ || closing_) return;
    if (control_.size() >= kMaxControlQueue) {
      // A client that floods us with bad messages and reads none of the answers.
      Close(websocket::close_code::policy_error);
      return;
    }
    control_.push_back(std::move(text));
    Write();
  }

  void Write() {
    if (writing_ || !open_) return;
    if (closing_) return StartClose();
    if (!control_.empty()) {
      writing_ = true;
      ws_->text(true);
      ws_->async_write(net::buffer(control_.front()),
                       [self = shared_from_this()](beast::error_code ec, size_t n) {
                         self->writing_ = false;
                         if (!self->control_.empty()) self->control_.pop_front();
                         self->OnWrite(ec, n);
                       });
      return;
    }
    if (pending_.empty()) return;
    auto next =
        std::min_element(pending_.begin(), pending_.end(),
                         [](const auto& a, const auto& b) { return a.second.seq < b.second.seq; });
    const uint32_t channel = next->first;
    in_flight_ = std::move(next->second);
    pending_.erase(next);
    header_ = MessageDataHeader(by_channel_.at(channel), in_flight_.log_time);
    writing_ = true;
    ws_->binary(true);
    const std::array<net::const_buffer, 2> buffers{net::buffer(header_),
                                                   net::buffer(*in_flight_.payload)};
    ws_->async_write(buffers, [self = shared_from_this()](beast::error_code ec, size_t n) {
      self->writing_ = false;
      self->in_flight_ = {};
      self->OnWrite(ec, n);
    });
  }

  void OnWrite(beast::error_code ec, size_t n) {
    if (ec) return Gone();
    ++server_->sent;
    server_->bytes += n;
    Write();
  }

  void StartClose() {
    if (close_started_ || !ws_) return;
    close_started_ = true;
    writing_ = true;
    ws_->async_close(close_code_, [self = shared_from_this()](beast::error_code) {
      self->writing_ = false;
      self->Gone();
    });
  }

  // The connection is over: forget its subscriptions (the socket closes with the last handler).
  void Gone() {
    if (gone_) return;
    gone_ = true;
    for (auto it = by_channel_.begin(); it != by_channel_.end();) {
      --server_->subscribers[it->first];
      it = by_channel_.erase(it);
    }
    by_id_.clear();
    pending_.clear();
    control_.clear();
    if (open_) {
      open_ = false;
      --server_->connected;
    }
    server_->Remove(this);
  }

  beast::tcp_stream stream_;
  std::optional<websocket::stream<beast::tcp_stream>> ws_;
  LiveServer::Impl* server_;
  beast::flat_buffer buffer_;
  http::request<http::string_body> request_;
  beast::flat_buffer read_buffer_;
  bool open_ = false, closing_ = false, close_started_ = false, writing_ = false, gone_ = false;
  websocket::close_code close_code_ = websocket::close_code::normal;
  int client_errors_ = 0;
  std::optional<Clock::time_point> first_subscribe_;
  std::map<uint32_t, uint32_t> by_id_;       // subscription id -> channel
  std::map<uint32_t, uint32_t> by_channel_;  // channel -> subscription id
  std::deque<std::string> control_;
  std::map<uint32_t, Pending> pending_;  // channel -> the newest message not yet sent
  Pending in_flight_;
  std::string header_;
};

void LiveServer::Impl::Start() {
  beast::error_code ec;
  net::ip::address address;
  if (options.host == "localhost") {
    address = net::ip::make_address("127.0.0.1");
  } else {
    address = net::ip::make_address(options.host, ec);
    if (ec) throw InputError("live address: '" + options.host + "' is not an IP address");
  }
  const tcp::endpoint where(address, options.port);
  acceptor.open(where.protocol(), ec);
  if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(where, ec);
  if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) {
    throw InputError("live view: cannot listen on " + options.host + ":" +
                     std::to_string(options.port) + ": " + ec.message());
  }
  endpoint = acceptor.local_endpoint();
  Accept();
  Tick();
  thread = std::thread([self = shared_from_this()] {
    SetCurrentThreadName("ademono-live");
    self->ioc.run();
  });
}

void LiveServer::Impl::Accept() {
  acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
    if (self->stopping || !self->acceptor.is_open()) return;
    if (!ec) {
      auto session = std::make_shared<Session>(std::move(socket), self.get());
      std::erase_if(self->all_sessions, [](const auto& w) { return w.expired(); });
      self->all_sessions.push_back(session);
      session->Start();
    }
    self->Accept();
  });
}

void LiveServer::Impl::Tick() {
  UpdateReadiness();
  if (ended) {
    bool all = true;
    for (const auto& s : sessions) all = all && s->Flushed();
    flushed_after_end = all;
  }
  if (stopping) return;
  tick.expires_after(std::chrono::milliseconds(50));
  tick.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->Tick();
  });
}

void LiveServer::Impl::UpdateReadiness() {
  const Clock::time_point now = Clock::now();
  size_t n = 0;
  for (const auto& s : sessions) n += s->IsWebSocket() && s->Ready(now);
  ready = n;
}

void LiveServer::Impl::Remove(Session* session) {
  sessions.erase(std::remove_if(sessions.begin(), sessions.end(),
                                [session](const auto& s) { return s.get() == session; }),
                 sessions.end());
  UpdateReadiness();
}

void LiveServer::Impl::Publish(Channel channel, std::shared_ptr<const std::string> payload,
                               uint64_t log_time) {
  const uint32_t id = static_cast<uint32_t>(channel);
  if (Info(channel).latched) latched[id] = {payload, log_time};
  const uint64_t seq = next_seq++;
  // Copy: a failed write may remove a session while we iterate.
  const std::vector<std::shared_ptr<Session>> targets = sessions;
  for (const auto& s : targets) s->Enqueue(channel, payload, log_time, seq);
}

void LiveServer::Impl::PublishStatus(const std::string& state, double timestamp,
                                     const LiveEnd* end) {
  run_state = state;
  Publish(Channel::kRunStatus,
          std::make_shared<const std::string>(RunStatusJson(state, timestamp, end)),
          ToNanoseconds(timestamp));
}

void LiveServer::Impl::PostDrain() {
  // Called with inbox_mutex held.
  if (drain_posted) return;
  drain_posted = true;
  net::post(ioc, [self = shared_from_this()] { self->Drain(); });
}

void LiveServer::Impl::Drain() {
  std::deque<LiveFrame> frames;
  std::optional<LiveMap> map;
  std::optional<std::pair<LiveMap, LiveEnd>> end;
  {
    std::lock_guard lock(inbox_mutex);
    frames.swap(inbox_frames);
    map.swap(inbox_map);
    end.swap(inbox_end);
    drain_posted = false;
  }
  auto make = [](std::string s) { return std::make_shared<const std::string>(std::move(s)); };
  for (LiveFrame& f : frames) {
    if (run_state != "running" && run_state != "finished")
      PublishStatus("running", f.timestamp, nullptr);
    const uint64_t t = ToNanoseconds(f.timestamp);
    if (f.cam_from_world) {
      if (Subscribed(Channel::kTransform)) Publish(Channel::kTransform, make(TransformJson(f)), t);
      if (Subscribed(Channel::kPose)) Publish(Channel::kPose, make(PoseJson(f)), t);
    }
    if (Subscribed(Channel::kFrameStats)) Publish(Channel::kFrameStats, make(FrameStatsJson(f)), t);
    // Images come at most image_hz (LiveServer::WantsImages); their annotations with them, or
    // at that rate without an image viewer.
    const Clock::time_point now = Clock::now();
    const bool annotate =
        !f.image.empty() ||
        (!Subscribed(Channel::kImage) &&
         now - last_annotations >= std::chrono::duration<double>(1.0 / options.image_hz));
    if (annotate && Subscribed(Channel::kAnnotations)) {
      last_annotations = now;
      Publish(Channel::kAnnotations, make(ImageAnnotationsJson(f)), t);
    }
    if (!f.image.empty() && Subscribed(Channel::kImage)) {
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", f.image, jpeg, {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
      Publish(Channel::kImage, make(CompressedImageJson(f, jpeg)), t);
    }
  }
  auto publish_map = [&](const LiveMap& m, bool always) {
    const uint64_t t = ToNanoseconds(m.timestamp);
    if (always || Subscribed(Channel::kTrajectory))
      Publish(Channel::kTrajectory, make(TrajectoryJson(m)), t);
    if (always || Subscribed(Channel::kMap)) Publish(Channel::kMap, make(PointCloudJson(m)), t);
    if (always || Subscribed(Channel::kScene)) Publish(Channel::kScene, make(SceneJson(m)), t);
  };
  if (map && !end) publish_map(*map, false);
  if (end) {
    // The run's final outputs, latched for anyone who subscribes during the linger.
    publish_map(end->first, true);
    PublishStatus("finished", end->first.timestamp, &end->second);
    ended = true;
  }
}

LiveOptions ParseLiveAddress(const std::string& text) {
  static const std::regex kPattern(R"(^(?:(\[[0-9a-fA-F:.]+\]|[^:\[\]]+):)?([0-9]{1,5})$)");
  std::smatch m;
  LiveOptions o;
  if (!std::regex_match(text, m, kPattern))
    throw InputError("live address '" + text +
                     "': expected [HOST:]PORT, e.g. 8765 or 127.0.0.1:8765");
  if (m[1].matched) {
    std::string host = m[1].str();
    if (host.front() == '[') host = host.substr(1, host.size() - 2);
    beast::error_code ec;
    if (host != "localhost") {
      net::ip::make_address(host, ec);
      if (ec) throw InputError("live address '" + text + "': '" + host + "' is not an IP address");
    }
    o.host = host;
  }
  const long port = std::stol(m[2].str());
  if (port > 65535) throw InputError("live address '" + text + "': port above 65535");
  o.port = static_cast<uint16_t>(port);
  return o;
}

LiveServer::LiveServer(const LiveOptions& options) : impl_(std::make_shared<Impl>(options)) {
  if (!(options.image_hz > 0) || !(options.map_hz > 0))
    throw InputError("live view: the image and map rates must be positive");
  impl_->Start();
}

LiveServer::~LiveServer() { Stop(); }

uint16_t LiveServer::Port() const { return impl_->endpoint.port(); }

std::string LiveServer::Url() const {
  const net::ip::address a = impl_->endpoint.address();
  const std::string host = a.is_v6() ? "[" + a.to_string() + "]" : a.to_string();
  return "http://" + host + ":" + std::to_string(Port()) + "/";
}

bool LiveServer::WaitForClients(size_t clients, const std::atomic<bool>* stop) {
  if (clients == 0) return true;
  net::post(impl_->ioc, [impl = impl_] {
    if (impl->run_state.empty()) impl->PublishStatus("waiting", 0, nullptr);
  });
  while (impl_->ready.load() < clients) {
    if (stop != nullptr && stop->load()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

void LiveServer::Linger(double seconds, const std::atomic<bool>* stop) {
  const Clock::time_point start = Clock::now();
  const auto wanted = std::chrono::duration<double>(std::max(0.0, seconds));
  const auto cap = std::chrono::duration<double>(std::max(seconds, 5.0));
  while (true) {
    const auto elapsed = Clock::now() - start;
    if (elapsed >= cap || (stop != nullptr && stop->load())) return;
    if (impl_->ended) {
      if (impl_->connected.load() == 0) return;
      if (impl_->flushed_after_end && elapsed >= wanted) return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void LiveServer::Stop() {
  if (!impl_->thread.joinable()) return;
  net::post(impl_->ioc, [impl = impl_] {
    impl->stopping = true;
    beast::error_code ec;
    impl->acceptor.close(ec);
    impl->tick.cancel();
    const auto sessions = impl->sessions;
    for (const auto& s : sessions) s->Close(websocket::close_code::going_away);
  });
  // The close handshakes get a second; then whatever is left is cut.
  for (int i = 0; i < 50 && impl_->connected.load() > 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  net::post(impl_->ioc, [impl = impl_] {
    for (const auto& w : impl->all_sessions) {
      if (auto s = w.lock()) s->Abort();
    }
    impl->ioc.stop();
  });
  impl_->thread.join();
  // The aborted operations' handlers hold the sessions and impl itself: run them out here, so
  // nothing is left in the io_context (no reference cycle through it).
  // (The thread may have ended before the abort above ran, which then stops a poll: restart.)
  do {
    impl_->ioc.restart();
  } while (impl_->ioc.poll() > 0);
  impl_->sessions.clear();
  impl_->all_sessions.clear();
}

json LiveServer::Stats() const {
  return {{"url", Url()},
          {"clients", impl_->accepted.load()},
          {"messages_sent", impl_->sent.load()},
          {"messages_dropped", impl_->dropped.load()},
          {"frames_skipped", impl_->skipped.load()},
          {"client_errors", impl_->errors.load()},
          {"bytes_sent", impl_->bytes.load()}};
}

bool LiveServer::WantsFrames() const { return impl_->connected.load() > 0; }

bool LiveServer::WantsImages() const {
  if (!impl_->Subscribed(Channel::kImage)) return false;
  const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          Clock::now().time_since_epoch())
                          .count();
  return now >= impl_->next_image_ns.load();
}

namespace {
int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}
}  // namespace

bool LiveServer::WantsMapSnapshot(bool map_changed) {
  const bool watched = impl_->Subscribed(Channel::kMap) ||
                       impl_->Subscribed(Channel::kTrajectory) ||
                       impl_->Subscribed(Channel::kScene);
  if (!watched) return false;
  const int64_t now = NowNs();
  // A new subscriber gets a fresh snapshot at once; changes at most map_hz.
  if (impl_->map_refresh.exchange(false) ||
      (map_changed && now >= impl_->next_map_ns.load())) {
    impl_->next_map_ns = now + static_cast<int64_t>(1e9 / impl_->options.map_hz);
    return true;
  }
  return false;
}

void LiveServer::OnFrame(LiveFrame frame) {
  if (!frame.image.empty()) {
    const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            Clock::now().time_since_epoch())
                            .count();
    impl_->next_image_ns = now + static_cast<int64_t>(1e9 / impl_->options.image_hz);
  }
  std::lock_guard lock(impl_->inbox_mutex);
  if (impl_->inbox_frames.size() >= kMaxInboxFrames) {
    impl_->inbox_frames.pop_front();
    ++impl_->skipped;
  }
  impl_->inbox_frames.push_back(std::move(frame));
  impl_->PostDrain();
}

void LiveServer::OnMap(LiveMap map) {
  std::lock_guard lock(impl_->inbox_mutex);
  impl_->inbox_map = std::move(map);
  impl_->PostDrain();
}

void LiveServer::OnEnd(LiveMap final_map, const LiveEnd& end) {
  std::lock_guard lock(impl_->inbox_mutex);
  impl_->inbox_end.emplace(std::move(final_map), end);
  impl_->PostDrain();
}

}  // namespace ademono::live
