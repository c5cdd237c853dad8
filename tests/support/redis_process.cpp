#include "support/redis_process.h"

#include <fcntl.h>
#include <hiredis/hiredis.h>
#include <signal.h>
#include <spawn.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <memory>
#include <thread>

#include "support/inscribed_process.h"

extern char** environ;

namespace inscribe::testing {
namespace {

struct ContextDeleter {
  void operator()(redisContext* context) const { redisFree(context); }
};
struct ReplyDeleter {
  void operator()(redisReply* reply) const { freeReplyObject(reply); }
};
using Context = std::unique_ptr<redisContext, ContextDeleter>;
using Reply = std::unique_ptr<redisReply, ReplyDeleter>;

Context Connect(int port, const std::string& password) {
  const timeval timeout{2, 0};
  Context context(redisConnectWithTimeout("127.0.0.1", port, timeout));
  if (context == nullptr || context->err != 0) return nullptr;
  redisSetTimeout(context.get(), timeout);
  if (!password.empty()) {
    Reply reply(static_cast<redisReply*>(
        redisCommand(context.get(), "AUTH %b", password.data(), password.size())));
    if (reply == nullptr || reply->type == REDIS_REPLY_ERROR) return nullptr;
  }
  return context;
}

}  // namespace

RedisProcess::RedisProcess(int port, std::vector<std::string> extra, std::string password)
    : port_(port == 0 ? UnusedLoopbackPort() : port), password_(std::move(password)) {
  std::vector<std::string> args = {"redis-server",        "--save", "",
                                   "--appendonly",        "no",     "--port",
                                   std::to_string(port_), "--bind", "127.0.0.1"};
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // Its log would only interleave with the test's output.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  if (posix_spawnp(&pid_, "redis-server", &actions, nullptr, argv.data(), environ) != 0) {
    pid_ = -1;
  }
  posix_spawn_file_actions_destroy(&actions);
  if (pid_ <= 0) return;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!(ready_ = Ping()) && std::chrono::steady_clock::now() < give_up) {
    if (waitpid(pid_, nullptr, WNOHANG) == pid_) {  // exited (e.g. the port was taken)
      pid_ = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

RedisProcess::~RedisProcess() { Kill(); }

std::string RedisProcess::url() const {
  return "redis://" + (password_.empty() ? "" : ":" + password_ + "@") +
         "127.0.0.1:" + std::to_string(port_);
}

void RedisProcess::Kill() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
  ready_ = false;
}

void RedisProcess::Freeze() {
  if (pid_ > 0) kill(pid_, SIGSTOP);
}

void RedisProcess::Thaw() {
  if (pid_ > 0) kill(pid_, SIGCONT);
}

bool RedisProcess::Ping() const {
  Context context = Connect(port_, password_);
  if (context == nullptr) return false;
  Reply reply(static_cast<redisReply*>(redisCommand(context.get(), "PING")));
  return reply != nullptr && reply->type == REDIS_REPLY_STATUS;
}

std::optional<std::string> RedisProcess::Get(const std::string& key) const {
  Context context = Connect(port_, password_);
  if (context == nullptr) return std::nullopt;
  Reply reply(
      static_cast<redisReply*>(redisCommand(context.get(), "GET %b", key.data(), key.size())));
  if (reply == nullptr || reply->type != REDIS_REPLY_STRING) return std::nullopt;
  return std::string(reply->str, reply->len);
}

bool RedisProcess::Set(const std::string& key, const std::string& value) const {
  Context context = Connect(port_, password_);
  if (context == nullptr) return false;
  Reply reply(static_cast<redisReply*>(redisCommand(context.get(), "SET %b %b", key.data(),
                                                    key.size(), value.data(), value.size())));
  return reply != nullptr && reply->type == REDIS_REPLY_STATUS;
}

std::optional<std::vector<std::string>> RedisProcess::Keys(const std::string& pattern) const {
  Context context = Connect(port_, password_);
  if (context == nullptr) return std::nullopt;
  Reply reply(static_cast<redisReply*>(
      redisCommand(context.get(), "KEYS %b", pattern.data(), pattern.size())));
  if (reply == nullptr || reply->type != REDIS_REPLY_ARRAY) return std::nullopt;
  std::vector<std::string> keys;
  for (std::size_t i = 0; i < reply->elements; ++i) {
    keys.emplace_back(reply->element[i]->str, reply->element[i]->len);
  }
  return keys;
}

}  // namespace inscribe::testing
