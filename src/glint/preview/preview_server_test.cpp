#include "glint/preview/preview_server.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

namespace glint {
namespace {

using namespace std::chrono_literals;

class PreviewServerTest : public ::testing::Test {
 protected:
  PreviewServerTest() : server_(state_, "127.0.0.1", 0), client_("127.0.0.1", server_.port()) {
    client_.set_connection_timeout(5s);
    client_.set_read_timeout(5s);
  }

  PreviewState state_{"scene.yaml"};
  PreviewServer server_;
  httplib::Client client_;
};

TEST_F(PreviewServerTest, ServesThePageAtTheRootWithEverythingItNeedsInside) {
  EXPECT_GT(server_.port(), 0);
  EXPECT_EQ(server_.url(), "http://127.0.0.1:" + std::to_string(server_.port()) + "/");
  const httplib::Result page = client_.Get("/");
  ASSERT_TRUE(page) << httplib::to_string(page.error());
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
  EXPECT_NE(page->body.find("new EventSource('/events')"), std::string::npos);
  // Offline: the page loads nothing from elsewhere.
  EXPECT_EQ(page->body.find("http://"), std::string::npos);
  EXPECT_EQ(page->body.find("https://"), std::string::npos);
  EXPECT_NE(page->get_header_value("Content-Security-Policy").find("default-src 'none'"),
            std::string::npos);
}

TEST_F(PreviewServerTest, AnyOtherPathIsNotFound) {
  for (const char* path : {"/index.html", "/favicon.ico", "/events/x", "/../etc/passwd", "//"}) {
    const httplib::Result result = client_.Get(path);
    ASSERT_TRUE(result) << path;
    EXPECT_EQ(result->status, 404) << path;
  }
}

TEST_F(PreviewServerTest, AnswersOnlyGet) {
  const httplib::Result post = client_.Post("/", "x", "text/plain");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 405);
  EXPECT_EQ(post->get_header_value("Allow"), "GET");
  for (const httplib::Result& result :
       {client_.Put("/events", "x", "text/plain"), client_.Delete("/"), client_.Head("/"),
        client_.Options("/"), client_.Patch("/nowhere", "x", "text/plain")}) {
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, 405);
  }
}

TEST_F(PreviewServerTest, RangeRequestsGetNoBody) {
  // Many ranges of the page would otherwise each come with the page's bytes and part headers.
  std::string ranges = "bytes=0-0";
  for (int i = 0; i < 1000; ++i) ranges += ",-";
  for (const char* path : {"/", "/events"}) {
    const httplib::Result result = client_.Get(path, {{"Range", ranges}});
    ASSERT_TRUE(result) << path;
    EXPECT_EQ(result->status, 416) << path;
    EXPECT_TRUE(result->body.empty()) << path << ": " << result->body.size() << " bytes";
  }
  const httplib::Result page = client_.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
}

TEST_F(PreviewServerTest, RefusesHostNamesThatAreNotThisMachine) {
  // A page on another site that rebinds its name to 127.0.0.1 sends that name as Host.
  const httplib::Result foreign = client_.Get("/", {{"Host", "attacker.example:80"}});
  ASSERT_TRUE(foreign);
  EXPECT_EQ(foreign->status, 403);
  for (const char* host : {"localhost:1", "127.0.0.1", "[::1]:8642", "preview.localhost"}) {
    const httplib::Result local = client_.Get("/", {{"Host", host}});
    ASSERT_TRUE(local);
    EXPECT_EQ(local->status, 200) << host;
  }
}

TEST_F(PreviewServerTest, StreamsTheStatusAndTilesAsServerSentEvents) {
  const PixelRegion whole{0, 0, 20, 10};
  Film film(20, 10, whole);
  state_.sceneBuilt("", whole, Encoding::Linear);
  state_.renderStarting(0, 2);
  state_.tileFinished({0, 0, 16, 10}, film, 1, 2);
  std::string received;
  const httplib::Result stream =
      client_.Get("/events", [&received](const char* data, std::size_t length) {
        received.append(data, length);
        return received.find("event: tiles") == std::string::npos ||
               received.find("event: status") == std::string::npos;
      });
  EXPECT_FALSE(stream);  // the receiver ended it
  EXPECT_NE(received.find("retry: 1000"), std::string::npos);
  EXPECT_NE(
      received.find("data: {\"width\":20,\"height\":10,\"tiles\":[{\"x\":0,\"y\":0,\"w\":16,"),
      std::string::npos)
      << received;
  EXPECT_NE(received.find("\"phase\":\"rendering\""), std::string::npos) << received;
}

TEST_F(PreviewServerTest, ASecondServerOnTheSamePortFailsClearly) {
  PreviewState other("other");
  try {
    PreviewServer second(other, "127.0.0.1", server_.port());
    FAIL() << "two servers listen on port " << server_.port();
  } catch (const PreviewError& error) {
    EXPECT_NE(std::string(error.what()).find("the port is in use"), std::string::npos)
        << error.what();
  }
}

TEST(PreviewServer, RefusesAnAddressThatIsNoIpAddress) {
  PreviewState state("s");
  EXPECT_THROW(PreviewServer(state, "example.org", 0), PreviewError);
  EXPECT_THROW(PreviewServer(state, "127.0.0.1", 70000), PreviewError);
}

TEST(PreviewServer, KnowsWhichAddressesOnlyThisMachineReaches) {
  EXPECT_TRUE(PreviewServer::isLoopback("127.0.0.1"));
  EXPECT_TRUE(PreviewServer::isLoopback("127.1.2.3"));
  EXPECT_TRUE(PreviewServer::isLoopback("::1"));
  EXPECT_FALSE(PreviewServer::isLoopback("0.0.0.0"));
  EXPECT_FALSE(PreviewServer::isLoopback("::"));
  EXPECT_FALSE(PreviewServer::isLoopback("192.168.1.2"));
  EXPECT_FALSE(PreviewServer::isLoopback("localhost"));  // a name: not an address
}

TEST(PreviewServer, StopsPromptlyWithAStreamOpen) {
  PreviewState state("s");
  auto server = std::make_unique<PreviewServer>(state, "127.0.0.1", 0);
  httplib::Client client("127.0.0.1", server->port());
  std::thread reader(
      [&client]() { client.Get("/events", [](const char*, std::size_t) { return true; }); });
  std::this_thread::sleep_for(200ms);
  const auto start = std::chrono::steady_clock::now();
  server.reset();
  EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
  reader.join();
}

// The render's outcome reaches an open page before the server stops: ended() then drain() then
// stop(), as a render that ends without lingering (or is interrupted) does. Without the drain the
// stream was closed before it sent the outcome in most runs.
TEST(PreviewServer, AnOpenPageIsSentTheOutcomeBeforeTheServerStops) {
  for (int run = 0; run < 5; ++run) {
    PreviewState state("s");
    const PixelRegion whole{0, 0, 20, 10};
    state.sceneBuilt("", whole, Encoding::Linear);
    state.renderStarting(0, 2);
    auto server = std::make_unique<PreviewServer>(state, "127.0.0.1", 0);
    httplib::Client client("127.0.0.1", server->port());
    std::string received;
    std::atomic<bool> streaming{false};
    std::thread reader([&]() {
      client.Get("/events", [&](const char* data, std::size_t length) {
        received.append(data, length);
        streaming = true;
        return true;
      });
    });
    while (!streaming) std::this_thread::sleep_for(5ms);
    state.ended(PreviewPhase::Interrupted, "interrupted");
    server->drain(2s);
    server->stop();
    reader.join();
    EXPECT_NE(received.find("\"phase\":\"interrupted\""), std::string::npos) << received;
  }
}

}  // namespace
}  // namespace glint
