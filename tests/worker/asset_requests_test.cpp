// The farm worker's asset questions (worker/asset_requests.h): one question
// per id, answers reach every waiter, a refusal and a timeout are told apart.
#include "worker/asset_requests.h"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <thread>

#include "worker/mesh_cache.h"

namespace skyfarm {
namespace {

using namespace std::chrono_literals;

const std::string kId = "sha256:" + std::string(64, 'd');

// Waits (bounded) until the I/O side has a question to send.
std::vector<std::string> questions(AssetRequests& requests) {
  for (int i = 0; i < 1000; ++i) {
    std::vector<std::string> ids = requests.take_unsent();
    if (!ids.empty()) return ids;
    std::this_thread::sleep_for(5ms);
  }
  return {};
}

TEST(AssetRequests, OneQuestionPerIdAndTheAnswerReachesEveryWaiter) {
  std::atomic<int> wakes{0};
  AssetRequests requests([&] { ++wakes; });
  auto first = std::async(std::launch::async, [&] { return requests.fetch(kId, 10s); });
  EXPECT_EQ(questions(requests), std::vector<std::string>{kId});
  auto second = std::async(std::launch::async, [&] { return requests.fetch(kId, 10s); });
  while (wakes.load() < 2) std::this_thread::sleep_for(1ms);
  EXPECT_TRUE(requests.take_unsent().empty()) << "asked already";
  EXPECT_TRUE(requests.answer(api::AssetMsg{kId, true, "", "FILE"}));
  EXPECT_EQ(first.get(), "FILE");
  EXPECT_EQ(second.get(), "FILE");
  EXPECT_FALSE(requests.answer(api::AssetMsg{kId, true, "", "FILE"})) << "a late answer fulfils nothing";
}

TEST(AssetRequests, ARefusalIsAnErrorNamingTheAsset) {
  AssetRequests requests([] {});
  auto asked = std::async(std::launch::async, [&] { return requests.fetch(kId, 10s); });
  ASSERT_EQ(questions(requests).size(), 1u);
  requests.answer(api::AssetMsg{kId, false, "no asset here", ""});
  try {
    asked.get();
    ADD_FAILURE() << "no error";
  } catch (const AssetUnavailable&) {
    ADD_FAILURE() << "a refusal is final, not worth asking again";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(kId), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no asset here"), std::string::npos) << e.what();
  }
}

TEST(AssetRequests, NoAnswerInTimeIsUnavailableAndANewSessionAsksAgain) {
  AssetRequests requests([] {});
  EXPECT_THROW(requests.fetch(kId, 1ms), AssetUnavailable);
  EXPECT_TRUE(requests.take_unsent().empty()) << "the timed-out question is withdrawn";
  auto asked = std::async(std::launch::async, [&] { return requests.fetch(kId, 10s); });
  ASSERT_EQ(questions(requests).size(), 1u);
  requests.resend_all();
  EXPECT_EQ(requests.take_unsent(), std::vector<std::string>{kId}) << "asked again on the new socket";
  requests.unsent(kId);
  EXPECT_EQ(requests.take_unsent(), std::vector<std::string>{kId}) << "a send that failed is retried";
  requests.close("the worker is stopping");
  EXPECT_THROW(asked.get(), AssetUnavailable);
  EXPECT_THROW(requests.fetch(kId, 10s), AssetUnavailable) << "closed: at once";
}

}  // namespace
}  // namespace skyfarm
