#include "server/http/http_gate.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <unordered_map>
#include <vector>

#include "server/http/http_problem.h"

namespace skyfarm::server {

using Clock = std::chrono::steady_clock;

namespace {

// A request head longer than this is refused (431): httplib's own limits
// (8 KiB request line, 8 KiB per header line) sit well below it.
constexpr std::size_t kMaxHeadBytes = 64 * 1024;
// How often the gate looks for connections past their deadline.
constexpr std::chrono::milliseconds kSweepInterval{50};
constexpr std::size_t kRecvChunk = 16 * 1024;

// A complete response with a problem document, written once, best effort
// (non-blocking: a client that does not read it just misses it).
std::string canned_response(int status, const std::string& detail, const char* extra_header = nullptr) {
  Problem p;
  p.status = status;
  p.detail = detail;
  const std::string body = dump_json(problem_json(p, ""));
  std::string text = "HTTP/1.1 " + std::to_string(status) + " " + std::string(status_phrase(status)) + "\r\n";
  text += "Content-Type: application/problem+json\r\n";
  text += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  if (extra_header) text += std::string(extra_header) + "\r\n";
  text += "Connection: close\r\n\r\n";
  return text + body;
}

void send_best_effort(int fd, const std::string& text) {
  [[maybe_unused]] const ssize_t n = ::send(fd, text.data(), text.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

std::string seconds_text(std::chrono::milliseconds d) {
  const double s = static_cast<double>(d.count()) / 1000.0;
  std::string t = std::to_string(s);
  t.erase(t.find_last_not_of('0') + 1);
  if (!t.empty() && t.back() == '.') t.pop_back();
  return t + " s";
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y)); });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// What the gate needs to know of a request head to decide how long to hold it.
struct HeadFraming {
  // Expect, another transfer coding, odd or repeated Content-Length: the body
  // is read on the thread (httplib answers what is wrong with it).
  bool body_on_thread = false;
  bool chunked = false;
  std::uint64_t content_length = 0;
};

HeadFraming framing_of(std::string_view head) {
  HeadFraming f;
  int lengths = 0;
  int codings = 0;
  std::size_t at = head.find("\r\n");  // skip the request line
  while (at != std::string_view::npos && at + 2 < head.size()) {
    const std::size_t start = at + 2;
    const std::size_t end = head.find("\r\n", start);
    const std::string_view line = head.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
    at = end;
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    const std::string_view name = trim(line.substr(0, colon));
    const std::string_view value = trim(line.substr(colon + 1));
    if (iequals(name, "Transfer-Encoding")) {
      ++codings;
      f.chunked = iequals(value, "chunked");
    } else if (iequals(name, "Expect")) {
      f.body_on_thread = true;
    } else if (iequals(name, "Content-Length")) {
      ++lengths;
      std::uint64_t n = 0;
      bool ok = !value.empty() && value.size() <= 18;
      for (char c : value) {
        ok = ok && c >= '0' && c <= '9';
        if (ok) n = n * 10 + static_cast<std::uint64_t>(c - '0');
      }
      if (!ok) f.body_on_thread = true;  // httplib answers it (400)
      f.content_length = n;
    }
  }
  if (lengths > 1 || codings > 1 || (codings == 1 && (!f.chunked || lengths > 0))) f.body_on_thread = true;
  return f;
}

// Where a chunked body ends in `data`, scanning from `pos` (the start of a
// chunk-size line, advanced past whole chunks).  0: not all there yet;
// npos: malformed or its chunks exceed `limit` bytes (left to the thread).
constexpr std::size_t kMaxChunkLine = 1024;

std::size_t chunked_end(std::string_view data, std::size_t& pos, std::size_t& total, std::size_t limit) {
  for (;;) {
    const std::size_t eol = data.find("\r\n", pos);
    if (eol == std::string_view::npos) return data.size() - pos > kMaxChunkLine ? std::string_view::npos : 0;
    std::string_view line = data.substr(pos, eol - pos);
    if (const std::size_t semi = line.find(';'); semi != std::string_view::npos) line = line.substr(0, semi);
    line = trim(line);
    std::size_t size = 0;
    if (line.empty() || line.size() > 8) return std::string_view::npos;
    for (char c : line) {
      const int d = std::isxdigit(static_cast<unsigned char>(c)) ? (std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : (std::tolower(c) - 'a' + 10)) : -1;
      if (d < 0) return std::string_view::npos;
      size = size * 16 + static_cast<std::size_t>(d);
    }
    if (size == 0) {  // the last chunk, then trailer lines up to an empty one
      for (std::size_t at = eol + 2;;) {
        const std::size_t end = data.find("\r\n", at);
        if (end == std::string_view::npos) return data.size() - at > kMaxChunkLine ? std::string_view::npos : 0;
        if (end == at) return end + 2;
        at = end + 2;
      }
    }
    total += size;
    if (total > limit) return std::string_view::npos;
    const std::size_t next = eol + 2 + size + 2;
    if (data.size() < next) return 0;
    pos = next;
  }
}

void close_socket(int fd) {
  ::shutdown(fd, SHUT_RDWR);
  ::close(fd);
}

}  // namespace

// One client connection, owned by the gate while it waits and by a pool
// thread while it is served.
struct Connection {
  enum class Phase { kIdle, kHead, kBody };
  int fd = -1;
  std::string pending;  // bytes received and not yet consumed by httplib
  std::size_t scanned = 0;  // pending[0, scanned) holds no "\r\n\r\n"
  Phase phase = Phase::kIdle;
  Clock::time_point idle_deadline;  // no byte yet
  Clock::time_point head_deadline;  // set once the head starts (or at the previous response's end)
  bool head_deadline_set = false;
  Clock::time_point body_deadline;  // set when the head is complete
  std::size_t needed = 0;           // bytes of pending that make the request (head + body)
  bool chunked = false;             // the body's end is found by chunked_end
  std::size_t chunk_pos = 0;        // chunked_end's place and body bytes so far
  std::size_t chunk_total = 0;
  std::size_t reserved = 0;         // of the gate's buffer budget
  std::size_t requests = 0;         // served on this connection
};

// httplib's Stream over a gated connection: reads come from the bytes the
// gate took first, then from the socket until the body deadline; writes wait
// at most the write timeout per call, as httplib's own stream does.
class GatedStream : public httplib::Stream {
 public:
  GatedStream(Connection& c, std::chrono::microseconds read_timeout, std::chrono::microseconds write_timeout,
              Clock::time_point deadline, const std::string& timeout_response, std::atomic<std::uint64_t>& timeouts)
      : c_(c), read_timeout_(read_timeout), write_timeout_(write_timeout), deadline_(deadline),
        timeout_response_(timeout_response), timeouts_(timeouts) {}

  bool is_readable() const override {
    if (offset_ < c_.pending.size()) return true;
    return wait_readable() > 0;
  }

  bool is_writable() const override {
    if (dead_ || !wait(POLLOUT, write_timeout_)) return false;
    // A client that closed its end cannot read the rest (httplib's check too).
    pollfd p{c_.fd, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0) return true;
    char b;
    return ::recv(c_.fd, &b, 1, MSG_PEEK | MSG_DONTWAIT) > 0;
  }

  ssize_t read(char* ptr, std::size_t size) override {
    if (dead_) return -1;
    if (offset_ >= c_.pending.size()) {
      c_.pending.clear();
      offset_ = 0;
      for (;;) {
        const int ready = wait_readable();
        if (ready == 0) {
          if (Clock::now() >= deadline_) expire();
          return -1;
        }
        if (ready < 0) return -1;
        char buf[kRecvChunk];
        const ssize_t n = ::recv(c_.fd, buf, sizeof buf, 0);
        if (n > 0) {
          c_.pending.append(buf, static_cast<std::size_t>(n));
          break;
        }
        if (n == 0) return 0;
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return -1;
      }
    }
    const std::size_t n = std::min(size, c_.pending.size() - offset_);
    std::memcpy(ptr, c_.pending.data() + offset_, n);
    offset_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    if (dead_) return -1;
    for (;;) {
      const ssize_t n = ::send(c_.fd, ptr, size, MSG_NOSIGNAL);
      if (n >= 0) {
        wrote_ = wrote_ || n > 0;
        return n;
      }
      if (errno == EINTR) continue;
      if ((errno != EAGAIN && errno != EWOULDBLOCK) || !wait(POLLOUT, write_timeout_)) return -1;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address(::getpeername, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address(::getsockname, ip, port); }
  socket_t socket() const override { return c_.fd; }

  // Drops what httplib consumed; the rest (a pipelined request) stays.
  void consume() {
    c_.pending.erase(0, offset_);
    offset_ = 0;
  }
  bool dead() const { return dead_; }

 private:
  // > 0 readable, 0 timed out (per read or the deadline), < 0 error.
  int wait_readable() const {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline_ - Clock::now());
    if (left.count() <= 0) return 0;
    return wait(POLLIN, std::min(left, read_timeout_)) ? 1 : 0;
  }

  bool wait(short events, std::chrono::microseconds timeout) const {
    pollfd p{c_.fd, events, 0};
    const int ms = static_cast<int>(std::max<long long>(0, (timeout.count() + 999) / 1000));
    int r;
    do r = ::poll(&p, 1, ms);
    while (r < 0 && errno == EINTR);
    return r > 0 && (p.revents & (events | POLLHUP | POLLERR)) != 0;
  }

  // The body did not arrive in time: 408 when nothing was answered yet, and
  // the connection is done (httplib's own error answer goes nowhere).
  void expire() {
    if (!wrote_) send_best_effort(c_.fd, timeout_response_);
    dead_ = true;
    timeouts_.fetch_add(1);
  }

  template <class F>
  void address(F f, std::string& ip, int& port) const {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (f(c_.fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) return;
    char text[INET6_ADDRSTRLEN] = {};
    if (addr.ss_family == AF_INET) {
      const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
      ::inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
      port = ntohs(a->sin_port);
    } else if (addr.ss_family == AF_INET6) {
      const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
      ::inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
      port = ntohs(a->sin6_port);
    }
    ip = text;
  }

  Connection& c_;
  const std::chrono::microseconds read_timeout_;
  const std::chrono::microseconds write_timeout_;
  const Clock::time_point deadline_;
  const std::string& timeout_response_;
  std::atomic<std::uint64_t>& timeouts_;
  std::size_t offset_ = 0;
  bool wrote_ = false;
  bool dead_ = false;
};

// The epoll thread that holds connections until their request is ready.
class ConnectionGate {
 public:
  ConnectionGate(GatedHttpServer& server, std::unique_ptr<httplib::TaskQueue> pool)
      : server_(server), options_(server.options_), pool_(std::move(pool)) {
    head_timeout_response_ =
        canned_response(408, "the request head did not arrive within " + seconds_text(options_.header_timeout));
    body_timeout_response_ =
        canned_response(408, "the request body did not arrive within " + seconds_text(options_.body_timeout));
    too_large_response_ = canned_response(431, "the request head is longer than " + std::to_string(kMaxHeadBytes) + " bytes");
    busy_response_ = canned_response(503, "too many open connections (" + std::to_string(options_.max_connections) + ")",
                                     "Retry-After: 1");
    epoll_ = ::epoll_create1(EPOLL_CLOEXEC);
    wake_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (epoll_ < 0 || wake_ < 0) {
      const int error = errno;
      if (epoll_ >= 0) ::close(epoll_);
      if (wake_ >= 0) ::close(wake_);
      pool_->shutdown();
      throw std::system_error(error, std::generic_category(), "HTTP connection gate");
    }
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = wake_;
    ::epoll_ctl(epoll_, EPOLL_CTL_ADD, wake_, &ev);
    thread_ = std::thread([this] { run(); });
  }

  ~ConnectionGate() {
    stop();
    ::close(wake_);
    ::close(epoll_);
  }

  // From httplib's accept loop: take the socket, or refuse it at the cap.
  void admit(int fd) {
    if (server_.open_.fetch_add(1) >= options_.max_connections) {
      server_.refused_.fetch_add(1);
      send_best_effort(fd, busy_response_);
      close_socket(fd);
      server_.open_.fetch_sub(1);
      return;
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    auto c = std::make_unique<Connection>();
    c->fd = fd;
    hand_to_gate(std::move(c));
  }

  // The server is going away: close everything waiting, finish what is being
  // served (handlers see the server stopping), then close those too.
  void stop() {
    {
      std::lock_guard lock(mutex_);
      if (stopped_) return;
      stopped_ = true;
    }
    wake();
    if (thread_.joinable()) thread_.join();
    pool_->shutdown();
    std::lock_guard lock(mutex_);
    for (auto& c : incoming_) finish(std::move(c));
    incoming_.clear();
  }

 private:
  void wake() {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_, &one, sizeof one);
  }

  // New connections and those back from a response; closed once stopping.
  void hand_to_gate(std::unique_ptr<Connection> c) {
    {
      std::lock_guard lock(mutex_);
      if (!stopped_) {
        incoming_.push_back(std::move(c));
        c = nullptr;
      }
    }
    if (c) finish(std::move(c));
    else wake();
  }

  void finish(std::unique_ptr<Connection> c) {
    release(*c);
    close_socket(c->fd);
    server_.open_.fetch_sub(1);
  }

  void release(Connection& c) {
    budget_used_.fetch_sub(c.reserved);
    c.reserved = 0;
  }

  void run() {
    std::vector<epoll_event> events(256);
    auto next_sweep = Clock::now() + kSweepInterval;
    for (;;) {
      const int n = ::epoll_wait(epoll_, events.data(), static_cast<int>(events.size()),
                                 static_cast<int>(kSweepInterval.count()));
      for (int i = 0; i < n; ++i) {
        const int fd = events[static_cast<std::size_t>(i)].data.fd;
        if (fd == wake_) {
          std::uint64_t count;
          [[maybe_unused]] const ssize_t r = ::read(wake_, &count, sizeof count);
          continue;
        }
        if (auto it = waiting_.find(fd); it != waiting_.end()) on_readable(it);
      }
      std::deque<std::unique_ptr<Connection>> arrived;
      bool stopping;
      {
        std::lock_guard lock(mutex_);
        arrived.swap(incoming_);
        stopping = stopped_;
      }
      for (auto& c : arrived) take(std::move(c));
      if (stopping) break;
      if (const auto now = Clock::now(); now >= next_sweep) {
        sweep(now);
        next_sweep = now + kSweepInterval;
      }
    }
    for (auto& [fd, c] : waiting_) finish(std::move(c));
    waiting_.clear();
  }

  // A connection enters the gate: fresh, or back after a response with
  // perhaps the next request already read.
  void take(std::unique_ptr<Connection> c) {
    const auto now = Clock::now();
    c->phase = Connection::Phase::kIdle;
    c->scanned = 0;
    c->needed = 0;
    c->chunked = false;
    c->idle_deadline = now + server_.keep_alive_timeout();
    c->head_deadline_set = c->requests > 0;  // a keep-alive head counts from the response's end
    if (c->head_deadline_set) c->head_deadline = now + options_.header_timeout;
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLRDHUP;
    ev.data.fd = c->fd;
    if (::epoll_ctl(epoll_, EPOLL_CTL_ADD, c->fd, &ev) != 0) {
      finish(std::move(c));
      return;
    }
    const int fd = c->fd;
    auto it = waiting_.emplace(fd, std::move(c)).first;
    if (!it->second->pending.empty()) evaluate(it, now);
  }

  using Waiting = std::unordered_map<int, std::unique_ptr<Connection>>;

  void on_readable(Waiting::iterator it) {
    Connection& c = *it->second;
    bool eof = false;
    char buf[kRecvChunk];
    for (;;) {
      const ssize_t n = ::recv(c.fd, buf, sizeof buf, 0);
      if (n > 0) {
        c.pending.append(buf, static_cast<std::size_t>(n));
        if (c.pending.size() > kMaxHeadBytes + c.needed) break;  // enough to decide
        continue;
      }
      if (n == 0) eof = true;
      else if (errno == EINTR) continue;
      else if (errno != EAGAIN && errno != EWOULDBLOCK) eof = true;
      break;
    }
    const int fd = c.fd;
    if (!c.pending.empty()) evaluate(it, Clock::now());  // may dispatch or drop it
    if (!eof) return;
    // The client closed its end: a request complete by then is still served
    // (evaluate dispatched it); anything else is dropped.
    if (auto again = waiting_.find(fd); again != waiting_.end()) drop(again);
  }

  // Moves the connection on once its request is there.
  void evaluate(Waiting::iterator it, Clock::time_point now) {
    Connection& c = *it->second;
    if (c.phase == Connection::Phase::kIdle) {
      c.phase = Connection::Phase::kHead;
      if (!c.head_deadline_set) {
        c.head_deadline = now + options_.header_timeout;
        c.head_deadline_set = true;
      }
    }
    if (c.phase == Connection::Phase::kHead) {
      const std::size_t from = c.scanned >= 3 ? c.scanned - 3 : 0;
      const std::size_t end = c.pending.find("\r\n\r\n", from);
      if (end == std::string::npos) {
        c.scanned = c.pending.size();
        if (c.pending.size() > kMaxHeadBytes) refuse(it, too_large_response_);
        return;
      }
      const std::size_t head = end + 4;
      const HeadFraming f = framing_of(std::string_view(c.pending).substr(0, head));
      c.body_deadline = now + options_.body_timeout;
      // A chunked body may reach max_buffered_body: that much is reserved.
      const std::size_t reserve_bytes = f.chunked ? options_.max_buffered_body : static_cast<std::size_t>(f.content_length);
      if (f.body_on_thread || f.content_length > options_.max_buffered_body || !reserve(c, reserve_bytes)) {
        dispatch(it);
        return;
      }
      c.phase = Connection::Phase::kBody;
      c.needed = head + static_cast<std::size_t>(f.content_length);
      c.chunked = f.chunked;
      c.chunk_pos = head;
      c.chunk_total = 0;
    }
    if (c.chunked) {
      const std::size_t end = chunked_end(c.pending, c.chunk_pos, c.chunk_total, options_.max_buffered_body);
      // Tiny chunks cost framing bytes too: past twice the limit, the thread reads on.
      if (end == 0 && c.pending.size() <= 2 * options_.max_buffered_body + kMaxHeadBytes) {
        c.needed = c.pending.size() + 1;  // read on, but not without bound
        return;
      }
      dispatch(it);  // complete, or left to httplib's own answer
      return;
    }
    if (c.pending.size() >= c.needed) dispatch(it);
  }

  bool reserve(Connection& c, std::size_t bytes) {
    if (bytes == 0) return true;
    std::size_t used = budget_used_.load();
    do {
      if (used + bytes > options_.buffer_budget) return false;
    } while (!budget_used_.compare_exchange_weak(used, used + bytes));
    c.reserved = bytes;
    return true;
  }

  void sweep(Clock::time_point now) {
    for (auto it = waiting_.begin(); it != waiting_.end();) {
      auto next = std::next(it);
      const Connection& c = *it->second;
      switch (c.phase) {
        case Connection::Phase::kIdle:
          if (now >= c.idle_deadline || (c.head_deadline_set && now >= c.head_deadline)) drop(it);
          break;
        case Connection::Phase::kHead:
          if (now >= c.head_deadline) {
            server_.head_timeouts_.fetch_add(1);
            refuse(it, head_timeout_response_);
          }
          break;
        case Connection::Phase::kBody:
          if (now >= c.body_deadline) {
            server_.body_timeouts_.fetch_add(1);
            refuse(it, body_timeout_response_);
          }
          break;
      }
      it = next;
    }
  }

  void refuse(Waiting::iterator it, const std::string& response) {
    send_best_effort(it->first, response);
    // Closing with unread input would reset the connection, and the client
    // could lose the answer: read off what is there now (bounded).
    char buf[kRecvChunk];
    for (int i = 0; i < 16 && ::recv(it->first, buf, sizeof buf, MSG_DONTWAIT) > 0; ++i) {
    }
    drop(it);
  }

  void drop(Waiting::iterator it) {
    std::unique_ptr<Connection> c = std::move(it->second);
    waiting_.erase(it);
    ::epoll_ctl(epoll_, EPOLL_CTL_DEL, c->fd, nullptr);
    finish(std::move(c));
  }

  void dispatch(Waiting::iterator it) {
    Connection* c = it->second.release();  // the task owns it (a std::function must be copyable)
    waiting_.erase(it);
    ::epoll_ctl(epoll_, EPOLL_CTL_DEL, c->fd, nullptr);
    pool_->enqueue([this, c] { serve(std::unique_ptr<Connection>(c)); });
  }

  // On a pool thread: one request, then back to the gate or closed.
  void serve(std::unique_ptr<Connection> c) {
    const bool last = ++c->requests >= server_.keep_alive_max_count() || server_.stopping();
    bool closed = false;
    bool ok = false;
    bool dead = false;
    {
      GatedStream stream(*c, server_.read_timeout(), server_.write_timeout(), c->body_deadline,
                         body_timeout_response_, server_.body_timeouts_);
      try {
        ok = server_.serve_one(stream, last, closed);
      } catch (...) {  // httplib answers handler exceptions; anything else ends the connection
        ok = false;
      }
      stream.consume();
      dead = stream.dead();
    }
    release(*c);
    if (ok && !closed && !last && !dead && !server_.stopping()) hand_to_gate(std::move(c));
    else finish(std::move(c));
  }

  GatedHttpServer& server_;
  const GateOptions& options_;
  std::unique_ptr<httplib::TaskQueue> pool_;
  int epoll_ = -1;
  int wake_ = -1;
  std::thread thread_;
  std::mutex mutex_;
  bool stopped_ = false;
  std::deque<std::unique_ptr<Connection>> incoming_;
  Waiting waiting_;  // gate thread only
  std::atomic<std::size_t> budget_used_{0};
  std::string head_timeout_response_;
  std::string body_timeout_response_;
  std::string too_large_response_;
  std::string busy_response_;
};

// What httplib's accept loop sees as its task queue: each "task" is its call
// to process_and_close_socket, which only hands the socket to the gate, so it
// runs at once on the accept thread.
class GateQueue : public httplib::TaskQueue {
 public:
  GateQueue(GatedHttpServer& server, std::unique_ptr<httplib::TaskQueue> pool)
      : server_(server), gate_(std::make_unique<ConnectionGate>(server, std::move(pool))) {
    server_.gate_ = gate_.get();
  }
  ~GateQueue() override { shutdown(); }

  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {
    if (!gate_) return;
    gate_->stop();
    server_.gate_ = nullptr;
    gate_.reset();
  }

 private:
  GatedHttpServer& server_;
  std::unique_ptr<ConnectionGate> gate_;
};

GatedHttpServer::GatedHttpServer(GateOptions options) : options_(options) {}

GatedHttpServer::~GatedHttpServer() = default;

bool GatedHttpServer::listen_after_bind() {
  if (svr_sock_ == INVALID_SOCKET) return false;
  // httplib listens with a backlog of 5; connections now cost no thread, so
  // let the kernel queue a burst of them.
  ::listen(svr_sock_, SOMAXCONN);
  pool_factory_ = new_task_queue;
  new_task_queue = [this]() -> httplib::TaskQueue* {
    std::unique_ptr<httplib::TaskQueue> pool(
        pool_factory_ ? pool_factory_() : new httplib::ThreadPool(CPPHTTPLIB_THREAD_POOL_COUNT));
    return new GateQueue(*this, std::move(pool));
  };
  const bool ok = httplib::Server::listen_after_bind();
  new_task_queue = pool_factory_;
  return ok;
}

bool GatedHttpServer::listen(const std::string& host, int port, int socket_flags) {
  return bind_to_port(host, port, socket_flags) && listen_after_bind();
}

int GatedHttpServer::open_connections() const { return open_.load(); }

GateStats GatedHttpServer::stats() const {
  GateStats s;
  s.open = open_.load();
  s.refused = refused_.load();
  s.head_timeouts = head_timeouts_.load();
  s.body_timeouts = body_timeouts_.load();
  return s;
}

void append_gate_metrics(std::string& out, const GateStats& s) {
  out += "# HELP skyfarm_http_connections_open HTTP connections open (waiting for their request or served).\n"
         "# TYPE skyfarm_http_connections_open gauge\n"
         "skyfarm_http_connections_open " + std::to_string(s.open) + "\n";
  out += "# HELP skyfarm_http_connections_refused_total HTTP connections refused at the connection cap (503).\n"
         "# TYPE skyfarm_http_connections_refused_total counter\n"
         "skyfarm_http_connections_refused_total " + std::to_string(s.refused) + "\n";
  out += "# HELP skyfarm_http_request_timeouts_total Requests whose head or body missed its deadline (408).\n"
         "# TYPE skyfarm_http_request_timeouts_total counter\n"
         "skyfarm_http_request_timeouts_total{part=\"head\"} " + std::to_string(s.head_timeouts) + "\n"
         "skyfarm_http_request_timeouts_total{part=\"body\"} " + std::to_string(s.body_timeouts) + "\n";
}

bool GatedHttpServer::process_and_close_socket(socket_t sock) {
  if (ConnectionGate* gate = gate_.load()) {
    gate->admit(sock);
    return true;
  }
  close_socket(sock);
  return false;
}

bool GatedHttpServer::serve_one(httplib::Stream& stream, bool close_connection, bool& connection_closed) {
  return process_request(stream, close_connection, connection_closed, nullptr);
}

std::chrono::microseconds GatedHttpServer::read_timeout() const {
  return std::chrono::seconds(read_timeout_sec_) + std::chrono::microseconds(read_timeout_usec_);
}

std::chrono::microseconds GatedHttpServer::write_timeout() const {
  return std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_);
}

}  // namespace skyfarm::server
