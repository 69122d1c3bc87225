// `bifilar.watch`: `bifilar watch` (pipeline/commands/watch_command.h) as a Python generator.
// RunWatch runs in a thread of its own; its updates, events and final result go through a queue
// that WatchRun.next() hands to Python one at a time, waiting with the GIL released and checking
// for Ctrl-C (KeyboardInterrupt) every 0.1 s. close() (the generator closed or collected) asks
// RunWatch to stop and waits for it: the saved log is complete and fitted either way.
#include "python/src/common.h"

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "pipeline/commands/watch_command.h"

namespace bifilar {
namespace python {
namespace {

class WatchRun {
 public:
  explicit WatchRun(WatchCommandOptions o) {
    o.on_update = [this](const WatchUpdate& u) { Push(WatchUpdateToJson(u)); };
    o.on_event = [this](const std::string& e) { Push(nlohmann::json{{"event", e}}); };
    o.keep_going = [this] {
      std::lock_guard<std::mutex> lock(mutex_);
      return !stop_;
    };
    thread_ = std::thread([this, o] {
      try {
        WatchCommandResult r = RunWatch(o);
        nlohmann::json final = r.json;
        final["final"] = true;
        Push(final);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = e.what();
      }
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
      changed_.notify_all();
    });
  }
  ~WatchRun() { Close(); }

  // The next item (a dict), or None when the watch has ended. Raises ValueError with the
  // watch's error, KeyboardInterrupt on Ctrl-C.
  py::object Next() {
    while (true) {
      nlohmann::json item;
      bool have = false, finished = false;
      std::string error;
      {
        py::gil_scoped_release release;
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait_for(lock, std::chrono::milliseconds(100),
                          [this] { return !queue_.empty() || done_; });
        if (!queue_.empty()) {
          item = std::move(queue_.front());
          queue_.pop_front();
          have = true;
        } else if (done_) {
          finished = true;
          error = error_;
        }
      }
      if (have) return ToPython(item);
      if (finished) {
        if (!error.empty()) throw UserError(error);
        return py::none();
      }
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    if (thread_.joinable()) {
      py::gil_scoped_release release;
      thread_.join();
    }
  }

 private:
  void Push(nlohmann::json item) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(item));
    changed_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<nlohmann::json> queue_;
  bool stop_ = false, done_ = false;
  std::string error_;
  std::thread thread_;
};

}  // namespace

void BindWatch(py::module_& m) {
  py::class_<WatchRun>(m, "WatchRun").def("next", &WatchRun::Next).def("close", &WatchRun::Close);
  m.def(
      "watch_start",
      [](const std::string& source, const std::string& config, const std::string& save,
         double target_percent, double counter_rate_hz, const std::string& counter_column,
         int cycles, bool stop_at_target, double idle_end_s, bool append, int serve_port) {
        WatchCommandOptions o;
        o.source = source;
        o.config_path = config;
        o.save_path = save;
        o.engine.target_percent = target_percent;
        o.counter_rate_hz = counter_rate_hz;
        o.counter_column = counter_column;
        o.stop_after_cycles = cycles;
        o.stop_at_target = stop_at_target;
        o.idle_end_s = idle_end_s;
        o.append_on_reconnect = append;
        o.serve_port = serve_port;
        return std::make_unique<WatchRun>(o);
      },
      py::arg("source"), py::arg("config"), py::arg("save"), py::arg("target_percent"),
      py::arg("counter_rate_hz"), py::arg("counter_column"), py::arg("cycles"),
      py::arg("stop_at_target"), py::arg("idle_end_s"), py::arg("append"), py::arg("serve_port"));
}

}  // namespace python
}  // namespace bifilar
