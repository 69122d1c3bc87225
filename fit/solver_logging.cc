#include "fit/solver_logging.h"

#include <mutex>

#include <glog/logging.h>

namespace bifilar {

void QuietSolverLogging() {
  static std::once_flag once;
  std::call_once(once, [] {
    FLAGS_logtostderr = true;  // never files under /tmp
    // Ceres logs a failed evaluation at ERROR ("Terminating: Residual and Jacobian evaluation
    // failed") with no word of which log was being fitted; the fit's summary carries the outcome
    // to the trace's record, so only FATAL (a crash) may reach stderr.
    FLAGS_minloglevel = google::GLOG_FATAL;
    if (!google::IsGoogleLoggingInitialized()) google::InitGoogleLogging("bifilar");
  });
}

}  // namespace bifilar
