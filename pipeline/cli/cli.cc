#include "pipeline/cli/cli.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <new>
#include <streambuf>
#include <string>

#include "base/csv.h"
#include "base/json_error.h"
#include "base/text_format.h"
#include "base/version.h"
#include "fit/solver_logging.h"
#include "pipeline/cli/cli_commands.h"

#include <nlohmann/json.hpp>

namespace bifilar {
namespace {

// The command and the files it was given ("bifilar ellipse on table.csv"), for a message that
// has no other context (an allocation failing outside any per-file handler).
std::string CommandAndInputs(int argc, char** argv) {
  std::string command = "bifilar";
  std::string files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    std::error_code ec;
    if (i == 1 && arg.rfind("-", 0) != 0) {
      command += " " + arg;
    } else if (std::filesystem::is_regular_file(arg, ec)) {
      files += (files.empty() ? "" : ", ") + arg;
    }
  }
  return command + (files.empty() ? std::string() : " on " + files);
}

// The console's width: every line a command prints to stdout is at most this long (issue 32:
// `fit --repeats` printed lines of 744 characters).
constexpr size_t kConsoleWidth = 160;

// A console buffer that passes text through line by line and wraps a line longer than
// kConsoleWidth at its blanks (WrapText), each continuation under the line's own indent plus
// four blanks: one place keeps every command's lines readable, whatever printed them. stdout
// passes a partial line on at a flush (a prompt before input); stderr, flushed after every
// insertion, waits for the line's end. Writers on several threads are serialised.
class ConsoleWrapBuffer : public std::streambuf {
 public:
  ConsoleWrapBuffer(std::streambuf* target, bool flush_partial)
      : target_(target), flush_partial_(flush_partial) {}
  ~ConsoleWrapBuffer() override {
    std::lock_guard<std::mutex> lock(mutex_);
    Emit();
    target_->pubsync();
  }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    std::lock_guard<std::mutex> lock(mutex_);
    Put(traits_type::to_char_type(c));
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::streamsize i = 0; i < n; ++i) Put(s[i]);
    return n;
  }
  int sync() override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (flush_partial_) Emit();
    return target_->pubsync();
  }

 private:
  void Put(char c) {
    line_ += c;
    if (c == '\n' || c == '\r') Emit();
  }
  void Emit() {
    if (line_.empty()) return;
    std::string end;
    while (!line_.empty() && (line_.back() == '\n' || line_.back() == '\r')) {
      end.insert(end.begin(), line_.back());
      line_.pop_back();
    }
    std::string text = line_;
    // An error stays on one line, as scripts and users grep it ("bifilar: error: FILE: ...",
    // "FILE: error: ..." or "  error: FILE: ..." in a list).
    const bool error = text.rfind("bifilar: ", 0) == 0 ||
                       text.rfind("error: ", text.find_first_not_of(' ')) != std::string::npos ||
                       text.find(": error: ") != std::string::npos;
    if (text.size() > kConsoleWidth && !error) {
      const size_t lead = std::min<size_t>(text.find_first_not_of(' '), 8);
      text = WrapText(text, kConsoleWidth, std::string(lead + 4, ' '));
    }
    text += end;
    target_->sputn(text.data(), static_cast<std::streamsize>(text.size()));
    line_.clear();
  }

  std::streambuf* target_;
  bool flush_partial_;
  std::mutex mutex_;
  std::string line_;
};

// Output read by programs is not wrapped: --json, and `export` (a URDF, SDF, JSBSim or CSV
// document on stdout); its --help is read by people.
bool MachineReadOutput(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return false;
  }
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--json" || (i == 1 && arg == "export")) return true;
  }
  return false;
}

// Installs ConsoleWrapBuffer on std::cout (unless its output is read by programs) and std::cerr
// for the run; restores the streams' buffers after.
class ConsoleWrap {
 public:
  explicit ConsoleWrap(bool wrap_stdout) {
    if (wrap_stdout) Install(std::cout, true, &out_, &previous_out_);
    Install(std::cerr, false, &err_, &previous_err_);
  }
  ~ConsoleWrap() {
    Restore(std::cout, &out_, previous_out_);
    Restore(std::cerr, &err_, previous_err_);
  }

 private:
  static void Install(std::ostream& stream, bool flush_partial,
                      std::unique_ptr<ConsoleWrapBuffer>* buffer, std::streambuf** previous) {
    *buffer = std::make_unique<ConsoleWrapBuffer>(stream.rdbuf(), flush_partial);
    *previous = stream.rdbuf(buffer->get());
  }
  static void Restore(std::ostream& stream, std::unique_ptr<ConsoleWrapBuffer>* buffer,
                      std::streambuf* previous) {
    if (!*buffer) return;
    stream.flush();
    stream.rdbuf(previous);
    buffer->reset();  // passes on a last partial line
  }

  std::unique_ptr<ConsoleWrapBuffer> out_, err_;
  std::streambuf* previous_out_ = nullptr;
  std::streambuf* previous_err_ = nullptr;
};

}  // namespace

CLI::Validator FiniteNumber() {
  return CLI::Validator(
      [](std::string& input) {
        // base/csv.h's ParseNumber, not stod: stod throws on underflow too, which called
        // 1e-308 (a subnormal number) "not a number". A value beyond the double range (digits
        // that read as infinity) is out of range; "inf" and "nan" are not finite.
        double value = 0.0;
        if (!ParseNumber(input, &value, NonFinite::kAccept)) {
          return "'" + input + "' is not a number";
        }
        if (std::isinf(value) && input.find_first_of("0123456789") != std::string::npos) {
          return "'" + input + "' is out of range (a finite number within +-1.8e308)";
        }
        if (!std::isfinite(value)) return "'" + input + "' is not a finite number";
        return std::string();
      },
      "NUMBER", "finite number");
}

CLI::Validator NonEmptyName() {
  return CLI::Validator(
      [](std::string& input) {
        return input.empty() ? std::string("the name is empty: nothing would be written")
                             : std::string();
      },
      "NAME");
}

uint64_t ParseSeed(const std::string& text, const std::string& flag, uint64_t max) {
  const std::string range = "[0, " + std::to_string(max) + "]";
  bool digits = !text.empty() && text.size() <= 20;
  for (char c : text) digits = digits && c >= '0' && c <= '9';
  uint64_t value = 0;
  if (digits) {
    errno = 0;
    const unsigned long long parsed = std::strtoull(text.c_str(), nullptr, 10);
    digits = errno == 0 && parsed <= max;
    value = parsed;
  }
  if (!digits) {
    throw UserError(flag + " '" + text.substr(0, 40) + "': a seed is an integer in " + range);
  }
  return value;
}

int RunCommandLine(int argc, char** argv) {
  QuietSolverLogging();  // fit/solver_logging.h: no glog preamble or solver chatter
  const ConsoleWrap wrap(!MachineReadOutput(argc, argv));
  CLI::App app{"bifilar: aircraft mass properties from bifilar pendulum IMU logs"};
  app.set_version_flag("--version", std::string("bifilar ") + ProgramVersion());
  app.require_subcommand(1);
  int exit_code = 0;
  RegisterProcessCommands(app, &exit_code);
  RegisterFitCommand(app, &exit_code);
  RegisterEllipseCommands(app, &exit_code);
  RegisterSimulateCommand(app, &exit_code);
  RegisterInspectCommands(app, &exit_code);
  RegisterExportCommand(app, &exit_code);
  RegisterWatchCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print as CLI11 does; a usage error gets the prefix every other
    // error has, so scripts and users can grep one form.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string what = e.what();
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty()) {
      std::string names;  // CLI11 says only "A subcommand is required" for `bifilar fitt`
      for (const CLI::App* sub : app.get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + sub->get_name();
      }
      what = std::string("unknown command '") + argv[1] + "'; the commands are " + names;
    }
    std::cerr << "bifilar: error: " << what << "\nRun with --help for more information.\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "bifilar: error: out of memory in `" << CommandAndInputs(argc, argv)
              << "`: one of these inputs (a file, or a count in the config or options) is far "
                 "larger than this machine can hold; see the limits in configs/README.md\n";
    return 2;
  } catch (const nlohmann::json::exception& e) {  // a path without its own handler
    std::cerr << "bifilar: error: in `" << CommandAndInputs(argc, argv)
              << "`: a JSON value could not be read or written (" << DescribeJsonError(e)
              << "); check the files named, or report this with them\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bifilar: error: " << e.what() << "\n";
    return 2;
  }
  return exit_code;
}

}  // namespace bifilar
