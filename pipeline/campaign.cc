#include "pipeline/campaign.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "fit/ellipse_plot.h"
#include "pipeline/cache.h"
#include "pipeline/campaign_inputs.h"
#include "pipeline/ellipse_json.h"
#include "pipeline/output_set.h"
#include "pipeline/report.h"
#include "pipeline/results_json.h"
#include "pipeline/user_error.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;


bool HasWildcard(const std::string& component) {
  return component.find_first_of("*?{") != std::string::npos;
}

std::vector<std::string> SplitPath(const std::string& pattern) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : pattern) {
    if (c == '/') {
      if (!part.empty()) parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  if (!part.empty()) parts.push_back(part);
  return parts;
}

// One path component of a pattern as a regex: '*' any run, '?' one character, '{pitch_deg}' a
// captured run (parsed as a number afterwards, so a non-number is reported, not skipped).
std::regex ComponentRegex(const std::string& component, bool* captures) {
  std::string re;
  for (size_t i = 0; i < component.size(); ++i) {
    const char c = component[i];
    if (c == '*') {
      re += "[^/]*";
    } else if (c == '?') {
      re += "[^/]";
    } else if (c == '{') {
      const size_t end = component.find('}', i);
      const std::string name = end == std::string::npos ? "" : component.substr(i + 1, end - i - 1);
      if (name != "pitch_deg") {
        throw UserError("runs.pattern: unknown placeholder in '" + component +
                        "' (only {pitch_deg} is known)");
      }
      if (*captures) throw UserError("runs.pattern: {pitch_deg} may appear only once");
      *captures = true;
      re += "([^/]*?)";
      i = end;
    } else {
      if (std::string("\\^$.|+()[]").find(c) != std::string::npos) re += '\\';
      re += c;
    }
  }
  return std::regex(re);
}

struct GlobHit {
  std::string path;
  std::optional<std::string> pitch_text;
};

void GlobWalk(const fs::path& dir, const std::vector<std::string>& parts, size_t index,
              std::optional<std::string> pitch_text, std::vector<GlobHit>* hits) {
  const bool last = index + 1 == parts.size();
  const std::string& part = parts[index];
  if (!HasWildcard(part)) {
    const fs::path next = dir / part;
    std::error_code ec;
    if (last) {
      if (fs::exists(next, ec)) hits->push_back({next.string(), pitch_text});
    } else if (fs::is_directory(next, ec)) {
      GlobWalk(next, parts, index + 1, pitch_text, hits);
    }
    return;
  }
  bool captures = false;
  const std::regex re = ComponentRegex(part, &captures);
  std::error_code ec;
  std::vector<fs::path> entries;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    entries.push_back(it->path());
  }
  std::sort(entries.begin(), entries.end());
  for (const fs::path& entry : entries) {
    std::smatch match;
    const std::string name = entry.filename().string();
    if (!std::regex_match(name, match, re)) continue;
    std::optional<std::string> text = pitch_text;
    if (captures) text = match[1].str();
    std::error_code ec2;
    if (last) {
      if (!fs::is_directory(entry, ec2)) hits->push_back({entry.string(), text});
    } else if (fs::is_directory(entry, ec2)) {
      GlobWalk(entry, parts, index + 1, text, hits);
    }
  }
}

// A pitch written in a path: "-80", "10", "12.5", "+5", "m80" (minus), "p10" (plus).
bool ParsePitchText(std::string text, double* pitch_deg) {
  double sign = 1.0;
  if (!text.empty() && (text[0] == 'm' || text[0] == 'n')) {
    sign = -1.0;
    text = text.substr(1);
  } else if (!text.empty() && text[0] == 'p') {
    text = text.substr(1);
  }
  if (text.empty()) return false;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return false;
  *pitch_deg = sign * value;
  return *pitch_deg >= -180.0 && *pitch_deg <= 180.0;
}

// How a log is named to the user: relative to runs.root when inside it (pitch_10/trial_1.csv),
// else relative to the config folder, else the absolute path.
std::string Display(const CampaignConfig& config, const std::string& path) {
  for (const std::string& base : {config.runs.root, config.folder}) {
    if (base.empty()) continue;
    const std::string rel = fs::path(path).lexically_relative(base).string();
    if (!rel.empty() && rel.rfind("..", 0) != 0) return rel;
  }
  return path;
}

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      cells.push_back(cell);
      cell.clear();
    } else if (c != '\r') {
      cell += c;
    }
  }
  cells.push_back(cell);
  for (std::string& s : cells) {
    while (!s.empty() && s.front() == ' ') s.erase(s.begin());
    while (!s.empty() && s.back() == ' ') s.pop_back();
  }
  return cells;
}

std::vector<RunFile> DiscoverTable(const CampaignConfig& config) {
  std::ifstream in(config.runs.table);
  if (!in) throw UserError(config.runs.table + ": cannot open runs table (runs.table)");
  std::vector<RunFile> runs;
  std::string line;
  int line_no = 0;
  int path_col = -1, pitch_col = -1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \r\t") == std::string::npos) continue;
    const std::vector<std::string> cells = SplitCsvLine(line);
    if (path_col < 0) {
      for (size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "path" || cells[i] == "file") path_col = static_cast<int>(i);
        if (cells[i] == "pitch_deg") pitch_col = static_cast<int>(i);
      }
      if (path_col < 0 || pitch_col < 0) {
        throw UserError(config.runs.table + ":" + std::to_string(line_no) +
                        ": runs table needs a header with columns 'path' and 'pitch_deg'");
      }
      continue;
    }
    RunFile run;
    const std::string rel = static_cast<int>(cells.size()) > path_col ? cells[path_col] : "";
    run.path = ResolvePath(config.runs.root, rel);
    run.display = Display(config, run.path);
    double pitch = 0.0;
    if (rel.empty()) {
      run.display = config.runs.table + ":" + std::to_string(line_no);
      run.error = run.display + ": empty path in runs table";
    } else if (static_cast<int>(cells.size()) <= pitch_col ||
               !ParsePitchText(cells[pitch_col], &pitch)) {
      run.error = config.runs.table + ":" + std::to_string(line_no) + ": pitch of '" + rel +
                  "' is not a number in [-180, 180]";
    } else {
      run.pitch_nominal_deg = pitch;
      std::error_code ec;
      if (!fs::exists(run.path, ec)) {
        run.error = run.display + ": listed in " + config.runs.table + ":" +
                    std::to_string(line_no) + " but not found";
      }
    }
    runs.push_back(run);
  }
  return runs;
}

std::vector<RunFile> DiscoverTare(const CampaignConfig& config) {
  std::vector<RunFile> tare;
  for (const std::string& pattern : config.rig_inertia.tare_patterns) {
    const std::vector<std::string> parts = SplitPath(pattern);
    size_t fixed = 0;
    while (fixed < parts.size() && !HasWildcard(parts[fixed])) ++fixed;
    if (fixed == parts.size()) {  // a plain file name
      RunFile run;
      run.path = pattern;
      run.display = Display(config, pattern);
      run.role = TraceRole::kTare;
      std::error_code ec;
      if (!fs::exists(pattern, ec)) run.error = run.display + ": tare log not found";
      tare.push_back(run);
      continue;
    }
    fs::path dir = pattern.rfind('/', 0) == 0 ? fs::path("/") : fs::path(".");
    for (size_t i = 0; i < fixed; ++i) dir /= parts[i];
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
      throw UserError("rig.inertia.tare.logs: folder '" + dir.string() + "' does not exist");
    }
    std::vector<GlobHit> hits;
    const std::vector<std::string> rest(parts.begin() + fixed, parts.end());
    for (const std::string& part : rest) {
      if (part.find('{') != std::string::npos) {
        throw UserError("rig.inertia.tare.logs: placeholders are not allowed in tare patterns");
      }
    }
    GlobWalk(dir, rest, 0, std::nullopt, &hits);
    if (hits.empty()) {
      throw UserError("rig.inertia.tare.logs: no file matches '" + pattern + "'");
    }
    for (const GlobHit& hit : hits) {
      RunFile run;
      run.path = fs::path(hit.path).lexically_normal().string();
      run.display = Display(config, run.path);
      run.role = TraceRole::kTare;
      tare.push_back(run);
    }
  }
  return tare;
}

// Runs fn(i) for i in [0, n) on `jobs` threads. An exception in any fn stops the handing out of
// further work and is rethrown on the calling thread once every thread has joined (an escaped
// exception would otherwise terminate the program).
template <typename Fn>
void ParallelFor(int n, int jobs, Fn fn) {
  std::atomic<int> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&] {
    try {
      for (int i = next++; i < n; i = next++) fn(i);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next = n;
    }
  };
  const int threads = std::max(1, std::min(jobs, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}

double SampleStd(const std::vector<double>& v) {
  if (v.size() < 2) return NAN;
  const double m = Mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

void Progress(const CampaignOptions& options, std::mutex& mutex, int done, int total,
              const TraceRecord& record) {
  if (options.progress == nullptr) return;
  std::lock_guard<std::mutex> lock(mutex);
  std::ostream& out = *options.progress;
  if (options.progress_bar) {
    const int width = 30;
    const int filled = total > 0 ? done * width / total : width;
    out << "\r  fitting [" << std::string(filled, '#') << std::string(width - filled, ' ')
        << "] " << done << "/" << total << std::flush;
    if (done == total) out << "\n";
  } else {
    out << "  fit " << done << "/" << total << " " << record.file << ": "
        << ToString(record.status);
    if (record.ok()) {
      char buffer[64];
      std::snprintf(buffer, sizeof(buffer), " I_total = %#.5g kg m^2", record.inertia_total_kg_m2);
      out << buffer;
    } else {
      out << " (" << record.message << ")";
    }
    out << "\n" << std::flush;
  }
}

// Removes OUT/cache and OUT/figures entries no record refers to, so the folder does not grow.
// Fig. 3 and Fig. 4 under names keyed by the ellipse inputs, so an unchanged rerun reuses them.
void DrawCampaignFigures(const CampaignConfig& config, const EllipseResult& fit,
                         const std::string& out_dir, OutputManifest* manifest,
                         CampaignResult* result) {
  std::ostringstream key;
  key.precision(17);
  key << ProgramVersion() << ';' << ToString(config.units) << ';' << fit.a_kg_m2 << ';'
      << fit.b_kg_m2 << ';' << fit.c_kg_m2 << ';' << fit.bootstrap_replicates << ';';
  for (const EllipsePoint& p : fit.points) {
    key << p.pitch_deg << ',' << p.inertia_kg_m2 << ',' << p.std_kg_m2 << ';';
  }
  const std::string hash = HashToHex(Fnv1a64(key.str()));
  EllipsePlotOptions plot;
  if (config.units == DisplayUnits::kImperial) {
    plot.unit_scale = kSlugFt2PerKgM2;
    plot.unit_label = "slug ft#u2#d";
  }
  const fs::path figures = fs::path(out_dir) / "figures";
  std::error_code ec;
  std::string why;
  const std::string moments = "moments_" + hash + ".png", polar = "polar_" + hash + ".png";
  manifest->Record({"figures/" + moments, "figures/" + polar});
  if (fs::exists(figures / moments, ec) ||
      WriteEllipseMomentFigure(fit, (figures / moments).string(), plot, &why)) {
    result->moments_figure = moments;
  }
  plot.figure.width_px = 1000;
  plot.figure.height_px = 520;
  if (fs::exists(figures / polar, ec) ||
      WriteEllipsePolarFigure(fit, (figures / polar).string(), plot, &why)) {
    result->polar_figure = polar;
  }
}

EllipseOptions MakeEllipseOptions(const CampaignConfig& config) {
  EllipseOptions o;
  o.bootstrap_replicates = config.ellipse.bootstrap;
  o.seed = config.ellipse.seed;
  o.confidence = config.ellipse.confidence;
  ParseEllipseCovariance(config.ellipse.covariance, &o.covariance);
  return o;
}

// The ellipse of inertia from every usable aircraft trace (one point per trial, pitch used,
// aircraft inertia after the tare, its std), plus Table 1 and the Fig. 3/4 figures.
void FitCampaignEllipse(const CampaignConfig& config, const CampaignOptions& options,
                        const std::string& out_dir, OutputManifest* manifest,
                        CampaignResult* result) {
  std::vector<EllipsePoint> points;
  for (const TraceRecord& r : result->traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    EllipsePoint p;
    p.pitch_deg = r.pitch_used_deg;
    p.inertia_kg_m2 = r.inertia_kg_m2;
    // The fit's own std: the rig's is one offset shared by every point, not independent noise
    // per point; it is propagated below as EllipseOptions::common_offset_std_kg_m2.
    p.std_kg_m2 = r.inertia_total_std_kg_m2;
    points.push_back(p);
  }
  EllipseOptions ellipse_options = MakeEllipseOptions(config);
  const double rig_std = config.rig_inertia.kind == RigInertiaSpec::Kind::kTare
                             ? result->rig_inertia_std_kg_m2
                             : config.rig_inertia.inertia_std_kg_m2;
  ellipse_options.common_offset_std_kg_m2 = std::isfinite(rig_std) ? rig_std : 0.0;
  // Table 1 from the angle groups (replaced by the ellipse fit's own when it runs).
  std::vector<double> stds, cvs;
  for (const AngleStats& a : result->angles) {
    if (a.n >= 2) {
      stds.push_back(a.inertia_std_kg_m2);
      cvs.push_back(a.cv_percent);
    }
  }
  result->raw_sigma_kg_m2 = Mean(stds);
  result->cv_percent = Mean(cvs);
  CampaignSummary& summary = result->summary;
  if (static_cast<int>(result->angles.size()) < config.ellipse.min_angles) {
    summary.ellipse_fitted = false;
    summary.ellipse_message = "ellipse not fitted: " + std::to_string(result->angles.size()) +
                              " usable pitch angle(s), at least " +
                              std::to_string(config.ellipse.min_angles) + " needed";
    return;
  }
  EllipseResult fit;
  std::string why;
  if (!FitEllipse(points, ellipse_options, &fit, &why) || !fit.IsUsable()) {
    summary.ellipse_fitted = false;
    summary.ellipse_message = "ellipse not fitted: " + (why.empty() ? "fit not usable" : why);
    return;
  }
  summary.ellipse_fitted = true;
  result->regression_rmse_kg_m2 = fit.rmse_kg_m2;
  if (fit.table1.n_angles_with_trials > 0) {
    result->raw_sigma_kg_m2 = fit.table1.mean_angle_std_kg_m2;
    result->cv_percent = fit.table1.mean_cov_percent;
  }
  result->ellipse = EllipseResultToJson(fit);
  if (options.figures) DrawCampaignFigures(config, fit, out_dir, manifest, result);
  result->ellipse_fit = std::move(fit);
}

}  // namespace

bool CampaignOptions::Check(std::string* why) const {
  if (out_dir.empty()) {
    *why = "output folder not set";
    return false;
  }
  if (jobs < 0 || jobs > kMaxJobs) {
    *why = "--jobs must be in [0, " + std::to_string(kMaxJobs) + "] (0 = all cores), got " +
           std::to_string(jobs);
    return false;
  }
  return true;
}

std::vector<RunFile> DiscoverRuns(const CampaignConfig& config) {
  std::vector<RunFile> runs;
  std::error_code ec;
  if (config.runs.root.empty()) throw UserError(config.file + ": no 'runs' section");
  if (!fs::is_directory(config.runs.root, ec)) {
    throw UserError("runs.root: folder '" + config.runs.root + "' does not exist");
  }
  if (!config.runs.table.empty()) {
    runs = DiscoverTable(config);
  } else {
    std::vector<GlobHit> hits;
    const std::vector<std::string> parts = SplitPath(config.runs.pattern);
    if (parts.empty()) throw UserError("runs.pattern is empty");
    GlobWalk(config.runs.root, parts, 0, std::nullopt, &hits);
    for (const GlobHit& hit : hits) {
      RunFile run;
      run.path = fs::path(hit.path).lexically_normal().string();
      run.display = Display(config, run.path);
      double pitch = 0.0;
      if (hit.pitch_text) {
        if (ParsePitchText(*hit.pitch_text, &pitch)) {
          run.pitch_nominal_deg = pitch;
        } else {
          run.error = run.display + ": cannot read the pitch from the path ('" + *hit.pitch_text +
                      "' in pattern " + config.runs.pattern + " is not a number in [-180, 180])";
        }
      } else if (config.runs.pitch_source == PitchSource::kNominal) {
        run.error = run.display + ": runs.pattern has no {pitch_deg} and pitch_source is nominal";
      }
      runs.push_back(run);
    }
    if (runs.empty()) {
      throw UserError("runs: no file matches '" + config.runs.pattern + "' under " +
                      config.runs.root);
    }
  }
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
    std::vector<RunFile> tare = DiscoverTare(config);
    runs.insert(runs.end(), tare.begin(), tare.end());
  }
  // A file matched twice (two tare patterns, a table row repeated) is one log; matched as an
  // aircraft run and as a tare log it is an error row, not "the same content as" itself.
  std::map<std::string, TraceRole> seen;
  std::vector<RunFile> unique;
  for (RunFile& run : runs) {
    auto [it, inserted] = seen.emplace(run.path, run.role);
    if (inserted) {
      unique.push_back(std::move(run));
    } else if (it->second != run.role && run.error.empty()) {
      run.error = run.display + ": listed both as an aircraft run and as a tare log";
      unique.push_back(std::move(run));
    }
  }
  return unique;
}

bool RigInertiaAt(const CampaignConfig& config, double tare_mean_kg_m2, double tare_std_kg_m2,
                  double pitch_deg, double* inertia_kg_m2, double* std_kg_m2, std::string* why) {
  const RigInertiaSpec& spec = config.rig_inertia;
  switch (spec.kind) {
    case RigInertiaSpec::Kind::kValue:
      *inertia_kg_m2 = spec.inertia_kg_m2;
      *std_kg_m2 = spec.inertia_std_kg_m2;
      return true;
    case RigInertiaSpec::Kind::kTare:
      if (!std::isfinite(tare_mean_kg_m2)) {
        *why = "no usable tare log: the rig inertia is unknown";
        return false;
      }
      *inertia_kg_m2 = tare_mean_kg_m2;
      *std_kg_m2 = std::isfinite(tare_std_kg_m2) ? tare_std_kg_m2 : 0.0;
      return true;
    case RigInertiaSpec::Kind::kTable: {
      const auto& table = spec.table_kg_m2;
      if (!std::isfinite(pitch_deg)) {
        *why = "pitch unknown: cannot look up the rig inertia table";
        return false;
      }
      auto hi = table.lower_bound(pitch_deg - 1e-9);
      if (hi != table.end() && std::abs(hi->first - pitch_deg) <= 1e-9) {
        *inertia_kg_m2 = hi->second;
      } else if (hi == table.begin() || hi == table.end()) {
        char buffer[160];
        std::snprintf(buffer, sizeof(buffer),
                      "pitch %.3g deg is outside the rig inertia table [%.3g, %.3g] deg",
                      pitch_deg, table.begin()->first, table.rbegin()->first);
        *why = buffer;
        return false;
      } else {
        auto lo = std::prev(hi);
        const double f = (pitch_deg - lo->first) / (hi->first - lo->first);
        *inertia_kg_m2 = lo->second + f * (hi->second - lo->second);
      }
      *std_kg_m2 = spec.inertia_std_kg_m2;
      return true;
    }
  }
  return false;
}

CampaignResult RunCampaign(const CampaignConfig& config, const CampaignOptions& options) {
  const Clock::time_point start = Clock::now();
  std::string why;
  if (!options.Check(&why)) throw UserError(why);
  if (!config.Check(&why)) throw UserError(config.file + ": " + why);
  std::error_code ec;
  const fs::path out(options.out_dir);
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    throw UserError(options.out_dir + ": output path exists and is not a folder");
  }
  fs::create_directories(out, ec);
  if (ec) throw UserError(options.out_dir + ": cannot create output folder: " + ec.message());
  // pipeline/output_set.h: one run per folder, nothing removed that bifilar did not write.
  const OutputFolderLock lock(out.string());
  OutputManifest manifest(out.string());
  manifest.CheckOwnedPlaces();
  if (options.progress) {
    for (const std::string& problem : CheckOutputSet(out.string(), true)) {
      *options.progress << "warning: previous outputs are a mixed set (" << problem
                        << "); all are rewritten now\n";
    }
  }
  fs::create_directories(out / "cache", ec);
  if (!ec) fs::create_directories(out / "figures", ec);
  if (ec) throw UserError(options.out_dir + ": cannot create output folder: " + ec.message());
  const int jobs = options.jobs > 0 ? options.jobs
                                    : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const TraceFitFunction fit = options.fit_function ? options.fit_function : ProcessTrace;
  const TraceCache cache((out / "cache").string());

  // 1. Discovery and content hashes (in parallel: reading is most of the rerun's time).
  std::vector<RunFile> runs = DiscoverRuns(config);
  DropOutputFolder(out.string(), &runs);  // pipeline/campaign_inputs.h: outputs are not inputs
  if (runs.empty()) {
    throw UserError("runs: every file found is inside the output folder " + out.string());
  }
  const std::vector<std::optional<std::array<double, 2>>> windows = WindowsForRuns(config, runs);
  const int n = static_cast<int>(runs.size());
  CampaignResult result;
  result.traces.resize(n);
  std::vector<std::string> hashes(n), read_errors(n);
  ParallelFor(n, jobs, [&](int i) {
    if (!runs[i].error.empty()) return;
    std::string bytes;
    if (ReadFileBytes(runs[i].path, &bytes, &read_errors[i])) {
      hashes[i] = HashToHex(Fnv1a64(bytes));
    } else {
      read_errors[i] = runs[i].display + ": " +
                       (read_errors[i].rfind(runs[i].path, 0) == 0
                            ? read_errors[i].substr(runs[i].path.size() + 2)
                            : read_errors[i]);
    }
  });

  // 2. Errors, duplicates, cache look-ups.
  std::map<std::string, std::string> first_with_hash;
  std::vector<int> to_fit;
  for (int i = 0; i < n; ++i) {
    const RunFile& run = runs[i];
    TraceRecord& record = result.traces[i];
    record.file = run.display;
    record.role = run.role;
    record.model = ToString(config.fit.model);
    record.pitch_nominal_deg = run.pitch_nominal_deg;
    record.content_hash = hashes[i];
    if (!run.error.empty() || !read_errors[i].empty()) {
      record.status = TraceStatus::kError;
      record.message = !run.error.empty() ? run.error : read_errors[i];
      continue;
    }
    auto [it, inserted] = first_with_hash.emplace(hashes[i], run.display);
    if (!inserted) {
      record.status = TraceStatus::kError;
      record.message = run.display + ": same content as " + it->second + " (duplicate log)";
      continue;
    }
    record.cache_key = CacheKey(hashes[i], FitFingerprint(config, run.role, windows[i]));
    TraceRecord cached;
    std::string cache_problem;
    const bool loaded =
        !options.force && cache.Load(record.cache_key, hashes[i], &cached, &cache_problem);
    if (!cache_problem.empty()) {
      ++result.summary.n_cache_refused;
      if (options.progress) *options.progress << "warning: " << cache_problem << "; refitting\n";
    }
    // Reused only with its figures: a record with a sweep and no sweep figure (an older run's)
    // is refitted, so the report shows I against amplitude for every trace that has a sweep.
    if (loaded &&
        (!options.figures ||
         ((cached.figure.empty() || fs::exists(out / "figures" / cached.figure, ec)) &&
          (cached.sweep_figure.empty() ? !cached.sweep.evaluated
                                       : fs::exists(out / "figures" / cached.sweep_figure, ec))))) {
      cached.role = record.role;
      cached.pitch_nominal_deg = record.pitch_nominal_deg;
      cached.content_hash = record.content_hash;
      cached.cache_key = record.cache_key;
      cached.file = record.file;
      cached.from_cache = true;
      record = cached;
      ++result.summary.n_reused;
    } else {
      to_fit.push_back(i);
    }
  }

  // 3. Fit what is not cached, in parallel (names recorded before the files exist).
  std::vector<std::string> planned;
  for (int i : to_fit) {
    planned.push_back("cache/" + result.traces[i].cache_key + ".json");
    planned.push_back("figures/" + result.traces[i].cache_key + ".svg");
    planned.push_back("figures/" + result.traces[i].cache_key + "_sweep.svg");
  }
  manifest.Record(planned);
  std::mutex progress_mutex;
  std::atomic<int> done{0};
  const int n_fit = static_cast<int>(to_fit.size());
  // Windows are resolved above (WindowsForRuns): the fit gets each in its options, and a config
  // without the list, so no fit searches fit.windows again (cost entries x traces).
  CampaignConfig fit_config = config;
  fit_config.fit.windows_s.clear();
  ParallelFor(n_fit, jobs, [&](int k) {
    const int i = to_fit[k];
    const RunFile& run = runs[i];
    TraceRecord& record = result.traces[i];
    TraceProcessOptions trace_options;
    trace_options.role = run.role;
    trace_options.display_name = run.display;
    trace_options.window_s = windows[i];
    const std::string figure_name = record.cache_key + ".svg";
    const std::string figure_path = (out / "figures" / figure_name).string();
    const std::string sweep_name = record.cache_key + "_sweep.svg";
    const std::string sweep_path = (out / "figures" / sweep_name).string();
    if (options.figures) trace_options.figure_paths = {figure_path};
    if (options.figures) trace_options.sweep_figure_paths = {sweep_path};
    trace_options.compact_figure = true;
    trace_options.figure_width_px = 640;
    trace_options.figure_height_px = 400;
    TraceRecord fitted;
    try {
      fitted = fit(fit_config, run.path, trace_options);
    } catch (const std::bad_alloc&) {
      fitted.status = TraceStatus::kError;
      fitted.message = run.display + ": out of memory while reading or fitting this log (is it "
                                     "far larger than a pendulum log?)";
    } catch (const std::exception& e) {
      fitted.status = TraceStatus::kError;
      fitted.message = run.display + ": " + e.what();
    }
    std::error_code ec2;
    fitted.figure = options.figures && fs::exists(figure_path, ec2) ? figure_name : "";
    fitted.sweep_figure = options.figures && fs::exists(sweep_path, ec2) ? sweep_name : "";
    fitted.file = record.file;
    fitted.role = record.role;
    fitted.pitch_nominal_deg = record.pitch_nominal_deg;
    fitted.content_hash = record.content_hash;
    fitted.cache_key = record.cache_key;
    fitted.from_cache = false;
    try {
      cache.Store(record.cache_key, record.content_hash, fitted);
    } catch (const UserError& e) {
      if (fitted.message.empty()) fitted.message = std::string("not cached: ") + e.what();
    }
    record = fitted;
    Progress(options, progress_mutex, ++done, n_fit, record);
  });
  result.summary.n_fitted = n_fit;

  // 4. The rig: mean of the tare logs, or the configured value / table.
  std::vector<double> tare_values, tare_stds;
  for (TraceRecord& r : result.traces) {
    if (r.role != TraceRole::kTare || !r.ok()) continue;
    tare_values.push_back(r.inertia_total_kg_m2);
    tare_stds.push_back(r.inertia_total_std_kg_m2);
    r.inertia_kg_m2 = r.inertia_total_kg_m2;
    r.inertia_std_kg_m2 = r.inertia_total_std_kg_m2;
  }
  double tare_mean = NAN, tare_std = NAN;
  if (!tare_values.empty()) {
    tare_mean = Mean(tare_values);
    // The larger of the between-log standard error and the fits' own (rms std / sqrt(n)): three
    // logs that happen to agree closely must not claim more than their fits can.
    double fit_var = 0.0;
    for (double v : tare_stds) fit_var += v * v / tare_stds.size();
    const double n_tare = static_cast<double>(tare_values.size());
    const double fit_sem = std::sqrt(fit_var / n_tare);
    tare_std = tare_values.size() >= 2
                   ? std::max(SampleStd(tare_values) / std::sqrt(n_tare), fit_sem)
                   : fit_sem;
  }
  result.rig_tare_n = static_cast<int>(tare_values.size());
  if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
    result.rig_inertia_kg_m2 = tare_mean;
    result.rig_inertia_std_kg_m2 = tare_std;
  } else if (config.rig_inertia.kind == RigInertiaSpec::Kind::kValue) {
    result.rig_inertia_kg_m2 = config.rig_inertia.inertia_kg_m2;
    result.rig_inertia_std_kg_m2 = config.rig_inertia.inertia_std_kg_m2;
  }

  // 5. Pitch used, rig subtracted.
  for (TraceRecord& r : result.traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    if (config.runs.pitch_source == PitchSource::kMeasured) {
      if (!r.pitch_measured_deg) {
        r.status = TraceStatus::kError;
        r.message = r.file + ": pitch_source is measured but the log gave no measured pitch";
        continue;
      }
      r.pitch_used_deg = *r.pitch_measured_deg;
    } else {
      r.pitch_used_deg = r.pitch_nominal_deg ? *r.pitch_nominal_deg : NAN;
    }
    double rig = 0.0, rig_std = 0.0;
    std::string reason;
    if (!RigInertiaAt(config, tare_mean, tare_std, r.pitch_used_deg, &rig, &rig_std, &reason)) {
      r.status = TraceStatus::kError;
      r.message = r.file + ": " + reason;
      continue;
    }
    r.rig_inertia_kg_m2 = rig;
    if (!(r.inertia_total_kg_m2 > rig)) {
      char buffer[200];
      std::snprintf(buffer, sizeof(buffer),
                    ": rig inertia %.6g kg m^2 is not below the measured total %.6g kg m^2 "
                    "(check rig.inertia and the tare logs)",
                    rig, r.inertia_total_kg_m2);
      r.status = TraceStatus::kError;
      r.message = r.file + buffer;
      continue;
    }
    r.inertia_kg_m2 = r.inertia_total_kg_m2 - rig;
    r.inertia_std_kg_m2 = std::hypot(r.inertia_total_std_kg_m2, rig_std);
  }

  // 6. Counts, per-angle groups, the ellipse.
  for (const TraceRecord& r : result.traces) {
    ++result.summary.n_traces;
    if (r.status == TraceStatus::kOk) ++result.summary.n_ok;
    if (r.status == TraceStatus::kRejected) ++result.summary.n_rejected;
    if (r.status == TraceStatus::kError) ++result.summary.n_error;
  }
  // Groups: the nominal pitch when known, else the measured pitch to 0.5 deg.
  std::map<double, std::vector<const TraceRecord*>> groups;
  for (const TraceRecord& r : result.traces) {
    if (r.role != TraceRole::kAircraft || !r.ok()) continue;
    const double key = r.pitch_nominal_deg ? *r.pitch_nominal_deg
                                           : std::round(r.pitch_used_deg * 2.0) / 2.0;
    groups[key].push_back(&r);
  }
  for (const auto& [key, members] : groups) {
    AngleStats a;
    std::vector<double> values, pitches, fit_stds;
    for (const TraceRecord* r : members) {
      values.push_back(r->inertia_kg_m2);
      pitches.push_back(r->pitch_used_deg);
      fit_stds.push_back(r->inertia_std_kg_m2);
    }
    a.pitch_deg = Mean(pitches);
    a.n = static_cast<int>(values.size());
    a.inertia_mean_kg_m2 = Mean(values);
    a.inertia_std_kg_m2 = SampleStd(values);
    a.fit_std_mean_kg_m2 = Mean(fit_stds);
    a.inertia_sem_kg_m2 = a.n >= 2 ? a.inertia_std_kg_m2 / std::sqrt(a.n) : fit_stds[0];
    a.cv_percent = 100.0 * a.inertia_std_kg_m2 / a.inertia_mean_kg_m2;
    result.angles.push_back(a);
  }
  std::vector<double> relative_budget;
  for (const TraceRecord& r : result.traces) {
    if (r.role == TraceRole::kAircraft && r.ok() && std::isfinite(r.budget_total_std_kg_m2)) {
      relative_budget.push_back(r.budget_total_std_kg_m2 / r.inertia_total_kg_m2);
    }
  }
  result.systematic_relative_std = Mean(relative_budget);
  FitCampaignEllipse(config, options, out.string(), &manifest, &result);

  if (result.summary.n_rejected + result.summary.n_error > 0 || !result.summary.ellipse_fitted) {
    result.summary.exit_code = 1;
  }
  result.summary.wall_s = std::chrono::duration<double>(Clock::now() - start).count();

  // 7. Outputs, each atomically, results.json last with its siblings' hashes; then drop the
  // cache entries and figures bifilar wrote that nobody refers to now.
  result.summary.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  nlohmann::json json = ResultsToJson(config, result);
  std::set<std::string> keep = {"results.json", "traces.csv", "angles.csv", "report.html"};
  manifest.Record({keep.begin(), keep.end()});
  WriteOutputSet(out.string(), json, TracesCsv(result), AnglesCsv(result),
                 options.write_report ? &BuildReportHtml : nullptr);
  for (const TraceRecord& r : result.traces) {
    if (!r.cache_key.empty()) keep.insert("cache/" + r.cache_key + ".json");
    if (!r.figure.empty()) keep.insert("figures/" + r.figure);
    if (!r.sweep_figure.empty()) keep.insert("figures/" + r.sweep_figure);
  }
  if (!result.moments_figure.empty()) keep.insert("figures/" + result.moments_figure);
  if (!result.polar_figure.empty()) keep.insert("figures/" + result.polar_figure);
  manifest.Prune(keep);
  return result;
}

}  // namespace bifilar

namespace bifilar {

void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out) {
  const DisplayUnits units = config.units;
  const char* unit = InertiaUnitName(units);
  auto inertia = [&](double kg_m2) { return InertiaToDisplay(kg_m2, units); };
  char line[256];
  const CampaignSummary& s = result.summary;
  if (result.ellipse_fit) {
    const EllipseResult& e = *result.ellipse_fit;
    out << "Table 2 (" << unit << ", +- 1 std):\n";
    auto row = [&](const char* name, const EllipseEstimate& est) {
      if (!est.defined) {
        std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", name);
      } else {
        std::snprintf(line, sizeof(line), "  %-5s  %#10.5g +- %.2g\n", name, inertia(est.value),
                      inertia(est.std));
      }
      out << line;
    };
    row("I_x", e.ix);
    row("I_z", e.iz);
    row("I_xz", e.ixz);
    if (e.tau_deg.defined) {
      std::snprintf(line, sizeof(line), "  %-5s  %10.4f +- %.4f deg\n", "tau", e.tau_deg.value,
                    e.tau_deg.std);
    } else {
      std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", "tau");
    }
    out << line;
    if (std::isfinite(result.systematic_relative_std) && result.systematic_relative_std > 0) {
      std::snprintf(line, sizeof(line),
                    "  (+- %.2f %% systematic, common to all moments, from the configured uncertainties)\n",
                    100.0 * result.systematic_relative_std);
      out << line;
    }
    std::snprintf(line, sizeof(line),
                  "Table 1: raw sigma %#.5g %s, CV %.4f %%, regression RMSE %#.5g %s\n",
                  inertia(result.raw_sigma_kg_m2), unit, result.cv_percent,
                  inertia(result.regression_rmse_kg_m2), unit);
    out << line;
  } else {
    out << s.ellipse_message << "\n";
  }
  if (std::isfinite(result.rig_inertia_kg_m2)) {
    std::snprintf(line, sizeof(line), "Rig inertia %#.5g +- %.2g %s", inertia(result.rig_inertia_kg_m2),
                  inertia(result.rig_inertia_std_kg_m2), unit);
    out << line;
    if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
      out << " (mean of " << result.rig_tare_n << " tare logs)";
    }
    out << "\n";
  }
  int shown = 0;
  for (const TraceRecord& r : result.traces) {
    if (r.ok()) continue;
    if (shown++ == 10) {
      out << "  ...\n";
      break;
    }
    out << "  " << ToString(r.status) << ": " << r.message << "\n";
  }
  std::snprintf(line, sizeof(line),
                "Traces: %d ok, %d rejected, %d error (of %d); fits run %d, reused from cache %d; "
                "wall time %.2f s\n",
                s.n_ok, s.n_rejected, s.n_error, s.n_traces, s.n_fitted, s.n_reused, s.wall_s);
  out << line;
  if (s.n_cache_refused > 0) {
    out << "Warning: " << s.n_cache_refused
        << " cache entr" << (s.n_cache_refused == 1 ? "y was" : "ies were")
        << " damaged or not theirs and refitted (see the warnings above)\n";
  }
}

}  // namespace bifilar
