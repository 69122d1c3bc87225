// Parallel execution with progress: the worker pool of `bifilar process` and its console lines.
#pragma once

#include <functional>
#include <iosfwd>
#include <mutex>
#include <string>

namespace bifilar {

// Worker threads for `jobs` (--jobs): `jobs` itself when > 0, else the hardware concurrency (at
// least 1).
int ResolveJobs(int jobs);

// Runs fn(i) for i in [0, n) on min(jobs, n) threads (the calling thread is one of them), each
// taking the next index when free. An exception in any fn stops the handing out of further work
// and is rethrown on the calling thread once every thread has joined (an escaped exception would
// otherwise terminate the program).
void ParallelFor(int n, int jobs, const std::function<void(int)>& fn);

// Progress of `total` tasks finished by any thread, written to `out` (nullptr = quiet): one line
// per task ("  fit 3/57 <line>"), or with `bar` one redrawn line ("\r  fitting [###   ] 3/57").
// `callback` (optional) is called under the same lock with (done, total, line).
class ProgressReporter {
 public:
  using Callback = std::function<void(int done, int total, const std::string& line)>;
  ProgressReporter(std::ostream* out, bool bar, int total, Callback callback = Callback())
      : out_(out), bar_(bar), total_(total), callback_(std::move(callback)) {}

  // Counts one finished task; `line` describes it (one line, no '\n'; unused by the bar).
  void TaskDone(const std::string& line);
  // Ends a bar that stopped short of `total` (Ctrl-C) with its newline; the count so far.
  int Stop();

 private:
  std::ostream* out_;
  bool bar_;
  int total_;
  Callback callback_;
  int done_ = 0;  // guarded by mutex_
  std::mutex mutex_;
};

}  // namespace bifilar
