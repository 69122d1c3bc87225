// The solvers' own logging (Ceres logs through glog). Without this, the first warning prints
// "Logging before InitGoogleLogging() is written to STDERR" and solver chatter such as "Residual
// and Jacobian evaluation failed" reaches the user's terminal; our results carry the solvers'
// outcome in their summaries instead (issue 9 item 13).
#pragma once

namespace bifilar {

// Initialises glog once per process (to stderr only, never log files) and keeps only fatal
// messages (the solvers' errors name no file; their outcome is in the summaries). Thread-safe
// and idempotent; called by the command line, FitEllipse and the trace fit's solver.
void QuietSolverLogging();

}  // namespace bifilar
