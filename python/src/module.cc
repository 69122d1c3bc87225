// The Python module's native part, `bifilar._core`: thin bindings over the same library calls the
// command line makes (pipeline/trace/trace_process.h, pipeline/campaign/campaign.h, fit/ellipse.h,
// pipeline/commands/simulate_spec.h). Records are built by the CLI's own JSON serializers
// (pipeline/records/results_json.h, pipeline/records/ellipse_json.h) and converted to Python dicts,
// so a field the CLI gains appears here with no change. The public, documented API is
// python/bifilar/__init__.py.
//
// Errors: bifilar::UserError (and std::invalid_argument) become ValueError with the message the
// CLI prints after "bifilar: error: "; nothing here aborts the interpreter. The GIL is released
// while the library works (fits, campaigns, simulation, file reading).
//
// One file per component, as pycolmap does (python/src/<file>.cc, each with its Bind... function,
// python/src/common.h); this file makes the module and its error translation.
#include "python/src/common.h"

#include <stdexcept>

#include "base/user_error.h"
#include "base/version.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/config/config.h"

PYBIND11_MODULE(_core, m) {
  using namespace bifilar;
  using namespace bifilar::python;
  m.doc() = "Native part of the bifilar Python module; use the functions of `bifilar` instead.";

  // Bad input from a user: ValueError with the CLI's message.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const UserError& e) {  // (a message naming a non-UTF-8 file name: surrogates)
      PyErr_SetObject(PyExc_ValueError, Text(e.what()).ptr());
    } catch (const std::invalid_argument& e) {
      PyErr_SetObject(PyExc_ValueError, Text(e.what()).ptr());
    }
  });

  BindFit(m);
  BindLogs(m);
  BindEllipse(m);
  BindTensor(m);
  BindCampaign(m);
  BindSimulate(m);
  BindWatch(m);
  m.attr("version") = ProgramVersion();
  // The ranges of the whole-number arguments, from the constants the C++ checks use:
  // bifilar/__init__.py refuses a value outside them by name, before a cast to int could fail
  // ("Unable to cast Python instance of type <class 'int'> to C++ type").
  py::dict int_ranges;
  int_ranges["whiteness_lags"] = py::make_tuple(1, kMaxWhitenessLags);
  int_ranges["bootstrap"] = py::make_tuple(0, kMaxBootstrapReplicates);
  int_ranges["jobs"] = py::make_tuple(0, kMaxJobs);
  m.attr("int_ranges") = int_ranges;
}
