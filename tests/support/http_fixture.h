// A test fixture serving the HTTP API (server/http/http_api.h) over a fake job
// backend on a free loopback port, behind the connection gate
// (server/http/http_gate.h, options in gate_): serve(options) binds and listens,
// client() talks to it, TearDown stops it.
#pragma once
#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <memory>
#include <thread>

#include "server/http/http_api.h"
#include "server/http/http_gate.h"
#include "tests/server/http/fake_backend.h"

namespace skyfarm::server::testing {

class HttpFixture : public ::testing::Test {
 protected:
  void serve(HttpOptions options) {
    api_ = std::make_unique<HttpApi>(backend_, std::move(options));
    server_ = std::make_unique<GatedHttpServer>(gate_);
    api_->register_routes(*server_);
    port_ = server_->bind_to_any_port("127.0.0.1");
    ASSERT_GT(port_, 0);
    thread_ = std::thread([this] { server_->listen_after_bind(); });
    for (int i = 0; i < 2000 && !server_->is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(server_->is_running());
  }
  void TearDown() override {
    if (server_) server_->stop();
    if (thread_.joinable()) thread_.join();
  }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_connection_timeout(2);
    c.set_read_timeout(read_timeout_s_);
    return c;
  }

  FakeBackend backend_;
  std::unique_ptr<HttpApi> api_;
  GateOptions gate_;
  std::unique_ptr<GatedHttpServer> server_;
  std::thread thread_;
  int port_ = 0;
  int read_timeout_s_ = 5;
};

}  // namespace skyfarm::server::testing
