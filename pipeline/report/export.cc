#include "pipeline/report/export.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/enum_names.h"
#include "base/json_error.h"
#include "base/option_check.h"
#include "base/user_error.h"
#include "base/version.h"
#include "fit/physical_check.h"
#include "fit/tensor.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/results_reader.h"
#include "pipeline/records/total_uncertainty.h"
#include "pipeline/report/export_steps.h"
#include "pipeline/store/output_set.h"

namespace bifilar {
namespace {

using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Numbers in the files: 10 significant digits (a bifilar std is >= 1e-5 of the moment), the C
// locale's '.', no "-0".
std::string Num(double v) {
  if (v == 0.0) v = 0.0;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// A number, or "" when it is not known (CSV).
std::string CsvNum(double v) { return std::isfinite(v) ? Num(v) : std::string(); }

// Text for an XML comment: "--" is not allowed inside one (nor a final "-"): "--set" becomes
// "- -set".
std::string CommentSafe(std::string s) {
  for (size_t at = s.find("--"); at != std::string::npos; at = s.find("--", at)) {
    s.insert(at + 1, " ");
  }
  if (!s.empty() && s.back() == '-') s += ' ';
  return s;
}

// A CSV field: quoted when it holds a comma, quote or line break.
std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// The elements written for URDF/SDF in `frame` (ixx iyy izz ixy ixz iyz).
std::array<double, 6> UrdfElements(const ExportInertia& in, ExportFrame frame) {
  const auto& v = in.value_kg_m2;
  // FLU = a half turn about x: I_xy and I_xz change sign, I_yz does not; the element is minus
  // the product.
  if (frame == ExportFrame::kFlu) return {v[kIxx], v[kIyy], v[kIzz], v[kIxy], v[kIxz], -v[kIyz]};
  return {v[kIxx], v[kIyy], v[kIzz], -v[kIxy], -v[kIxz], -v[kIyz]};
}

// Missing components or mass: an error naming them and how to supply them.
void RequireComplete(const ExportInertia& in, const char* format, bool moments_only = false) {
  std::vector<std::string> missing = in.Missing();
  if (moments_only) {  // ArduPilot: the diagonal only ("Ixy": a product, dropped anyway)
    missing.erase(std::remove_if(missing.begin(), missing.end(),
                                 [](const std::string& m) { return m[1] != m[2]; }),
                  missing.end());
  }
  if (!missing.empty()) {
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    const bool planar = in.section == "ellipse" ||
                        (missing.size() == 3 && missing[0] == "Iyy" && missing[1] == "Ixy");
    throw UserError(
        in.results_name + ": " + format +
        (moments_only ? " needs the three moments" : " needs all six components") + ", and " +
        names + (missing.size() == 1 ? " is" : " are") + " not in this result" +
        (planar ? " (a pitch-only campaign measures Ixx, Izz and Ixz)" : "") + "; give " +
        (missing.size() == 1 ? "it" : "them") +
        " with --set NAME=VALUE (kg m^2, body axes, products positive)" +
        (std::find(missing.begin(), missing.end(), "Ixy") != missing.end() ||
                 std::find(missing.begin(), missing.end(), "Iyz") != missing.end()
             ? ", or --symmetric for Ixy = Iyz = 0 (an aircraft symmetric about its x-z plane)"
             : "") +
        ", or export --format csv, which leaves them empty");
  }
  if (!std::isfinite(in.mass_kg)) {
    throw UserError(in.results_name + ": " + format + " needs the mass, and " +
                    (in.mass_problem.empty()
                         ? std::string("the config stored in this result has no aircraft.mass_kg")
                         : in.mass_problem) +
                    "; give it with --mass-kg");
  }
}

// A component's line of the comments: "value +- stat (stat) +- total (total)", or what set it.
std::string ComponentText(const ExportInertia& in, int k) {
  if (in.source[k] != "measured") {
    return Num(in.value_kg_m2[k]) + " (not measured: " +
           (in.source[k] == "set" ? "given by the user"
                                  : "assumed 0, aircraft symmetric about x-z") +
           ")";
  }
  std::string s = Num(in.value_kg_m2[k]) + " +- " +
                  (std::isfinite(in.std_kg_m2[k]) ? Num(in.std_kg_m2[k]) : std::string("unknown")) +
                  " (stat)";
  if (std::isfinite(in.total_std_kg_m2[k])) s += " +- " + Num(in.total_std_kg_m2[k]) + " (total)";
  return s;
}

// Provenance: "bifilar 0.3.0 (results.json by bifilar 0.3.0), campaign configs/x.yaml, exported
// 2026-11-28".
std::string ProvenanceText(const ExportInertia& in) {
  return "bifilar " + in.export_version + " (results.json written by bifilar " +
         (in.results_version.empty() ? std::string("?") : in.results_version) + "), campaign " +
         (in.campaign.empty() ? std::string("?") : in.campaign) + ", exported " + in.date_utc;
}

// The CG line: where the origin of the file is, and what the bifilar does not measure.
std::string CgText(const ExportInertia& in, const std::string& origin_text) {
  std::string s =
      "NOT MEASURED by the bifilar: the mass (" + Num(in.mass_kg) + " kg" +
      (std::isfinite(in.mass_std_kg) ? " +- " + Num(in.mass_std_kg) : std::string()) + ", from " +
      (in.mass_source == "--mass-kg" ? std::string("the command line") : in.mass_source) +
      ") and the CG: ";
  if (in.cg.Given()) {
    s += "aircraft.cg_m = " + Num(in.cg.cg_m[0]) + " " + Num(in.cg.cg_m[1]) + " " +
         Num(in.cg.cg_m[2]) + " m (body x forward, y right, z down)";
    if (!std::isnan(in.cg.cg_std_m[0])) {
      s += " +- " + Num(in.cg.cg_std_m[0]) + " " + Num(in.cg.cg_std_m[1]) + " " +
           Num(in.cg.cg_std_m[2]) + " m";
    }
    s += ", measured apart; " + origin_text;
  } else {
    s += origin_text +
         " Move it to the measured CG (or give aircraft.cg_m in the config); the "
         "inertia is about the CG.";
  }
  return s;
}

// The comment every XML file starts with: source, frame and sign, uncertainty, provenance, what
// is not measured.
std::string XmlHeader(const ExportInertia& in, const std::string& frame_text,
                      const std::string& sign_text, const std::string& origin_text) {
  std::string s = "bifilar export of " + in.results_name + " (section '" + in.section + "').\n";
  s += "     Provenance: " + ProvenanceText(in) + "\n";
  s += "     Frame: " + frame_text + "\n     Signs: " + sign_text + "\n";
  s += "     Inertia about the CG in body axes (x forward, y right, z down; products positive, "
       "I_xy = integral x y dm), kg m^2, value +- std (stat: the fit; total: with the "
       "campaign's common-mode scale):\n";
  for (int k = 0; k < 6; ++k) {
    s += "       " + std::string(TensorComponentName(k)) + " " + ComponentText(in, k) + "\n";
  }
  s += "     " + CgText(in, origin_text);
  return "<!-- " + CommentSafe(s) + " -->\n";
}

// The first condition of a physical inertia that `in` fails, "" when none (see
// ExportInertia::nonphysical).
std::string NonPhysical(const ExportInertia& in) {
  const auto& v = in.value_kg_m2;
  for (int k = 0; k < 6; ++k) {
    if (in.source[k] == "missing") continue;
    const std::string what = std::string(k < 3 ? "the moment " : "the product ") +
                             TensorComponentName(k) + " = " + Num(v[k]) + " kg m^2";
    if (!std::isfinite(v[k])) return what + " is not finite";
    if (std::abs(v[k]) > kMaxExportInertiaKgM2) {
      return what + " is beyond any aircraft (|I| <= " + Num(kMaxExportInertiaKgM2) +
             " kg m^2): a corrupt or mis-scaled result";
    }
    if (k < 3 && !(v[k] > 0)) return what + " is not positive: no body has it";
  }
  if (in.Missing().empty()) {
    Eigen::Matrix3d t;
    t << v[kIxx], -v[kIxy], -v[kIxz], -v[kIxy], v[kIyy], -v[kIyz], -v[kIxz], -v[kIyz], v[kIzz];
    const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(t).eigenvalues();
    if (!(p[0] > 0)) {
      return "the tensor is not positive definite (principal moments " + Num(p[0]) + ", " +
             Num(p[1]) + ", " + Num(p[2]) +
             " kg m^2): no rigid body has it, and simulators "
             "reject it";
    }
    if (p[2] > (p[0] + p[1]) * (1 + 1e-12)) {
      return "the principal moments " + Num(p[0]) + ", " + Num(p[1]) + ", " + Num(p[2]) +
             " kg m^2 break the triangle inequality (largest > sum of the others): no rigid "
             "body has them; check the products";
    }
    return "";
  }
  // A partial result: every 2x2 block of moments and their product that it holds is positive
  // definite (a block of a positive definite tensor is).
  const int pairs[3][3] = {{kIxx, kIyy, kIxy}, {kIxx, kIzz, kIxz}, {kIyy, kIzz, kIyz}};
  for (const auto& pr : pairs) {
    if (in.source[pr[0]] == "missing" || in.source[pr[1]] == "missing" ||
        in.source[pr[2]] == "missing") {
      continue;
    }
    if (!(v[pr[0]] * v[pr[1]] > v[pr[2]] * v[pr[2]])) {
      return std::string("the product ") + TensorComponentName(pr[2]) + " = " + Num(v[pr[2]]) +
             " kg m^2 is too large for the moments " + TensorComponentName(pr[0]) + " = " +
             Num(v[pr[0]]) + " and " + TensorComponentName(pr[1]) + " = " + Num(v[pr[1]]) + " (" +
             TensorComponentName(pr[2]) + "^2 >= " + TensorComponentName(pr[0]) + " " +
             TensorComponentName(pr[1]) + "): the tensor is not positive definite";
    }
  }
  return "";
}

// True when the file at `path` starts as a file `bifilar export` writes (an XML comment
// "<!-- bifilar export of" or the CSV header): replacing it replaces export's own output.
bool WrittenByExport(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char head[64] = {};
  file.read(head, sizeof(head));
  const std::string start(head, static_cast<size_t>(file.gcount()));
  return start.rfind(kExportMark, 0) == 0 || start.rfind("{\n  \"bifilar_export\": ", 0) == 0 ||
         start.rfind("results_file,section,frame,mass_kg,", 0) == 0;
}

// Throws UserError when --out (or --into: `option`) is the input or a file of its output folder
// (see RunExport).
void RefuseCampaignFile(const std::string& out_path, const std::string& results_path,
                        const char* option = "--out") {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(out_path, ec), ec);
  const fs::path input = fs::weakly_canonical(fs::absolute(results_path, ec), ec);
  const std::string refused = std::string("export: ") + option + " " + out_path + " is ";
  const std::string advice = std::string(option) == "--out"
                                 ? "; export writes a new file: choose a name outside it"
                                 : "; --into rewrites a model file, not a campaign's";
  if (out == input || (fs::exists(out_path, ec) && fs::equivalent(out_path, results_path, ec))) {
    throw UserError(refused + "the input " + results_path + " itself" + advice);
  }
  const fs::path folder = input.parent_path();
  const fs::path relative = out.lexically_relative(folder);
  if (relative.empty() || *relative.begin() == "..") return;  // outside the output folder
  // The folder is a campaign's when the input is its results.json or it holds a manifest.
  const bool has_manifest = fs::exists(folder / OutputManifest::kFileName, ec);
  if (input.filename() != "results.json" && !has_manifest) return;
  const std::string first = relative.begin()->string();
  bool owned = first == "cache" || first == "figures" || first == OutputManifest::kFileName ||
               first == ".bifilar.lock";
  for (const char* name : {"results.json", "traces.csv", "angles.csv", "report.html"}) {
    owned = owned || relative == name;
  }
  if (!owned && has_manifest) {
    try {
      owned = OutputManifest(folder.string()).Contains(relative.generic_string());
    } catch (const UserError&) {
      owned = true;  // a damaged manifest: nothing in the folder is safe to replace
    }
  }
  if (owned) {
    throw UserError(refused + relative.generic_string() + " of the output folder " +
                    folder.string() + " that holds " + results_path + advice);
  }
}

}  // namespace

namespace {

constexpr EnumName<ExportFormat> kExportFormatNames[] = {
    {ExportFormat::kUrdf, "urdf"},     {ExportFormat::kSdf, "sdf"},
    {ExportFormat::kJsbsim, "jsbsim"}, {ExportFormat::kCsv, "csv"},
    {ExportFormat::kMjcf, "mjcf"},     {ExportFormat::kArdupilot, "ardupilot"}};
constexpr EnumName<ExportFrame> kExportFrameNames[] = {{ExportFrame::kFlu, "flu"},
                                                       {ExportFrame::kFrd, "frd"}};

}  // namespace

bool ParseExportFormat(const std::string& name, ExportFormat* format) {
  return ParseEnum(kExportFormatNames, name, format);
}
const char* ExportFormatName(ExportFormat format) {
  return EnumToString(kExportFormatNames, format, "?");
}
std::string ExportFormatAllowedValues() { return EnumAllowedValues(kExportFormatNames); }

bool ParseExportFrame(const std::string& name, ExportFrame* frame) {
  return ParseEnum(kExportFrameNames, name, frame);
}
std::string ExportFrameAllowedValues() { return EnumAllowedValues(kExportFrameNames); }

bool ExportOptions::Check(std::string* why) const {
  CheckFailure f;
  bool ok =
      (!results_path.empty() ||
       CheckFailText("results_path", results_path, "a results.json", &f)) &&
      (!frame_given || format == ExportFormat::kUrdf || format == ExportFormat::kSdf ||
       format == ExportFormat::kMjcf ||
       CheckFailText("--frame (with --format)", ExportFormatName(format),
                     "urdf, sdf or mjcf (--frame applies to urdf, sdf and mjcf only; the others "
                     "have a fixed frame)",
                     &f)) &&
      (into_path.empty() == link_name.empty() ||
       CheckFailText("--into/--link", into_path.empty() ? link_name : into_path,
                     "given together (--into MODEL --link NAME)", &f)) &&
      (into_path.empty() || out_path.empty() ||
       CheckFailText("--out (with --into)", out_path,
                     "absent: --into rewrites MODEL itself (and keeps a backup)", &f)) &&
      (into_path.empty() || format == ExportFormat::kUrdf || format == ExportFormat::kSdf ||
       format == ExportFormat::kMjcf ||
       CheckFailText("--format (with --into)", ExportFormatName(format),
                     "urdf, sdf or mjcf (the formats of a model file with links or bodies)", &f)) &&
      (std::isnan(mass_kg) || CheckFiniteGt("--mass-kg", mass_kg, 0, &f));
  for (auto it = set_kg_m2.begin(); ok && it != set_kg_m2.end(); ++it) {
    const std::string& name = it->first;
    int k = 0;
    while (k < 6 && name != TensorComponentName(k)) ++k;
    if (k == 6) {
      ok = CheckFailText("--set", name, "Ixx, Iyy, Izz, Ixy, Ixz or Iyz (unknown component)", &f);
    } else {
      // A moment (Ixx, Iyy, Izz) is > 0; a product any finite number.
      ok = k < 3 ? CheckFiniteGt("--set " + name, it->second, 0, &f)
                 : CheckFinite("--set " + name, it->second, &f);
    }
  }
  return ok || FailWith(f, why);
}

std::vector<std::string> ExportInertia::Missing() const {
  std::vector<std::string> m;
  for (int k = 0; k < 6; ++k) {
    if (source[k] == "missing") m.push_back(TensorComponentName(k));
  }
  return m;
}

namespace {

// A key of the wrong type in results.json is named with the file (the reader names the key).
template <typename Read>
auto NamedRead(const std::string& name, const Read& read) {
  try {
    return read();
  } catch (const UserError& e) {
    throw UserError(name + ": " + e.what());
  }
}

// The mass: the option, else results.json's `aircraft` (written from the config), else (files
// written before that key) the config stored in results.json.
void ReadExportMass(const ResultsReader& results, const json& j, const std::string& name,
                    const ExportOptions& options, ExportInertia* in) {
  const auto named = [&name](const auto& read) { return NamedRead(name, read); };
  double stored_mass_kg = kNaN, stored_mass_std_kg = kNaN;
  if (!std::isnan(options.mass_kg)) {
    in->mass_kg = options.mass_kg;
    in->mass_source = "--mass-kg";
  } else if (j.contains("aircraft")) {  // null: the config gave no mass
    const ResultsReader aircraft = results.Get("aircraft");
    stored_mass_kg = named([&] { return aircraft.Num("mass_kg"); });
    stored_mass_std_kg = named([&] { return aircraft.Num("mass_std_kg"); });
    if (!std::isnan(stored_mass_kg)) {
      in->mass_kg = stored_mass_kg;
      in->mass_std_kg = stored_mass_std_kg;
      in->mass_source = "config aircraft.mass_kg";
    }
  } else if (!named([&] {
                return results.Str("config");
              }).empty()) {  // written before `aircraft` existed
    try {
      const YAML::Node config = YAML::Load(results.Str("config"));
      const YAML::Node aircraft = config.IsMap() ? config["aircraft"] : YAML::Node();
      // A key that is absent gives an invalid node, whose IsScalar() throws: IsDefined first.
      const auto scalar = [&aircraft](const char* key) {
        return aircraft[key].IsDefined() && aircraft[key].IsScalar();
      };
      // An absent section or key gives an invalid node, which throws on IsMap()/IsScalar():
      // IsDefined first, so a config without aircraft.mass_std_kg (or without aircraft) is read
      // without a warning.
      if (aircraft.IsDefined() && aircraft.IsMap() && scalar("mass_kg")) {
        in->mass_kg = aircraft["mass_kg"].as<double>();
        in->mass_source = "config aircraft.mass_kg";
        if (scalar("mass_std_kg")) in->mass_std_kg = aircraft["mass_std_kg"].as<double>();
      }
    } catch (const YAML::Exception& e) {
      in->warnings.push_back(name + ": the stored config could not be read for the mass (" +
                             e.what() + ")");
    }
    if (!in->mass_source.empty() && !(std::isfinite(in->mass_kg) && in->mass_kg > 0)) {
      in->mass_problem = "aircraft.mass_kg = " + Num(in->mass_kg) +
                         " in the config stored in this result is not a positive mass";
      in->mass_kg = kNaN;
      in->mass_source.clear();
    }
  }
}

// The total stds (the stat std and the common-mode scale in quadrature), the covariance, the
// provenance and the CG of the stored config.
void ReadExportUncertaintyAndProvenance(const ResultsReader& results, const std::string& name,
                                        const ExportOptions& options, ExportInertia* in) {
  const double common_mode = NamedRead(name, [&] {
    return results.Get("total_uncertainty").NumOrNull("common_mode_relative_std", name);
  });
  for (int k = 0; k < 6; ++k) {
    in->total_std_kg_m2[k] =
        in->source[k] == "measured" && std::isfinite(common_mode)
            ? WithCommonModeScale(in->value_kg_m2[k], in->std_kg_m2[k], common_mode)
            : kNaN;
    in->covariance_kg2_m4[k].fill(kNaN);
  }
  if (in->section == "tensor") {
    const std::vector<std::vector<double>> rows = results.Get("tensor").Rows("covariance_kg2_m4");
    for (size_t a = 0; a < rows.size() && a < 6; ++a) {
      for (size_t b = 0; b < rows[a].size() && b < 6; ++b) in->covariance_kg2_m4[a][b] = rows[a][b];
    }
  }
  in->results_version = NamedRead(name, [&] { return results.Str("version"); });
  in->campaign = NamedRead(name, [&] { return results.Str("config_file"); });
  in->export_version = ProgramVersion();
  in->date_utc = options.date_utc;
  if (in->date_utc.empty()) {
    const std::time_t now = std::time(nullptr);
    std::tm tm = {};
    gmtime_r(&now, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    in->date_utc = buf;
  }
  const std::string config = NamedRead(name, [&] { return results.Str("config"); });
  if (!config.empty()) {
    try {
      in->cg = ReadAircraftCgText(config, name + " (its stored config)");
    } catch (const UserError& e) {
      in->warnings.push_back(std::string(e.what()) + "; the CG is not written");
    }
  }
}

}  // namespace

ExportInertia ReadExportInertia(const std::string& text, const std::string& name,
                                const ExportOptions& options, KeyLog* keys_read) {
  std::string why;
  if (!options.Check(&why)) throw UserError("export: " + why);
  json j;
  try {
    j = json::parse(text);
  } catch (const std::exception& e) {
    throw UserError(name + ": not valid JSON (" + DescribeJsonError(e) +
                    "); export reads the results.json written by `bifilar process`");
  }
  const ResultsReader results(j, keys_read);
  if (!j.is_object() || NamedRead(name, [&] { return results.Str("program"); }) != "bifilar") {
    throw UserError(name +
                    ": not a results.json written by bifilar (no \"program\": "
                    "\"bifilar\"); export reads the results.json of `bifilar process`");
  }
  CheckResultsSchema(j, name);  // a newer schema: named before any key is read
  ExportInertia in;
  in.results_name = name;
  in.value_kg_m2.fill(kNaN);
  in.std_kg_m2.fill(kNaN);
  in.source.fill("missing");
  // The tensor section (issue 17) when it holds a number, else the ellipse's I_x, I_z, I_xz; read
  // through the one results.json reader (pipeline/records/results_reader.h).
  bool found = false;
  const ResultsReader tensor = results.Get("tensor");
  if (tensor.IsObject()) {
    for (int k = 0; k < 6; ++k) {
      const std::string key = std::string(TensorComponentName(k)) + "_kg_m2";
      in.value_kg_m2[k] = tensor.NumOrNull(key.c_str(), name);
      if (std::isnan(in.value_kg_m2[k])) continue;
      in.std_kg_m2[k] = tensor.NumOrNull((key + "_std").c_str(), name);
      in.source[k] = "measured";
      found = true;
    }
    if (found) in.section = "tensor";
  }
  const ResultsReader ellipse = results.Get("ellipse");
  if (!found && ellipse.IsObject()) {
    const std::pair<int, const char*> keys[] = {
        {kIxx, "Ix_kg_m2"}, {kIzz, "Iz_kg_m2"}, {kIxz, "Ixz_kg_m2"}};
    for (const auto& [k, key] : keys) {
      in.value_kg_m2[k] = ellipse.NumOrNull(key, name);
      if (std::isnan(in.value_kg_m2[k])) continue;
      in.std_kg_m2[k] = ellipse.NumOrNull((std::string(key) + "_std").c_str(), name);
      in.source[k] = "measured";
      found = true;
    }
    if (found) in.section = "ellipse";
  }
  if (!found) {
    throw UserError(name +
                    ": holds no inertia to export (no 'tensor' or 'ellipse' section with "
                    "a number; did the campaign's fit fail? see its summary)");
  }
  // Fill what the result does not hold.
  for (const auto& [component, value] : options.set_kg_m2) {
    int k = 0;
    while (TensorComponentName(k) != component) ++k;
    if (in.source[k] == "measured") {
      throw UserError("export: --set " + component + ": " + name + " measured " + component + " (" +
                      Num(in.value_kg_m2[k]) +
                      " kg m^2); --set only fills components the result does not hold");
    }
    in.value_kg_m2[k] = value;
    in.source[k] = "set";
  }
  if (options.symmetric) {
    for (int k : {kIxy, kIyz}) {
      if (in.source[k] != "missing") continue;
      in.value_kg_m2[k] = 0.0;
      in.std_kg_m2[k] = kNaN;
      in.source[k] = "symmetric";
    }
  }
  ReadExportMass(results, j, name, options, &in);
  ReadExportUncertaintyAndProvenance(results, name, options, &in);
  // The campaign's own physical check (fit/physical.h: the triangle inequalities and positive
  // definiteness against the components' combined std) comes first: it refuses what is clearly
  // broken within its std, not only exactly broken, and names the attitude that drives it, as
  // `process` printed. Then the exact conditions on the values written.
  if (j.contains("physical") && j["physical"].is_object() &&
      j["physical"].value("status", std::string()) ==
          PhysicalStatusName(PhysicalStatus::kNotPhysical)) {
    in.nonphysical = "the campaign's physical check says not physical: " +
                     j["physical"].value("message", std::string("(no message)"));
  } else {
    in.nonphysical = NonPhysical(in);
  }
  if (!in.nonphysical.empty()) in.warnings.push_back(name + ": " + in.nonphysical);
  return in;
}

namespace {

// The frame texts of URDF, SDF and MJCF.
std::string LinkFrameText(ExportFormat format, ExportFrame frame) {
  if (frame == ExportFrame::kFrd)
    return "the body axes as measured, x forward, y right, z down (FRD)";
  return format == ExportFormat::kUrdf
             ? "the link frame as ROS REP 103 takes it, x forward, y left, z up (FLU)"
         : format == ExportFormat::kSdf
             ? "the link frame as Gazebo takes it, x forward, y left, z up (FLU)"
             : "the body frame, x forward, y left, z up (FLU, as URDF and Gazebo)";
}

std::string LinkSignText(ExportFormat format, ExportFrame frame) {
  const std::string signs = frame == ExportFrame::kFlu ? "ixy = +I_xy, ixz = +I_xz, iyz = -I_yz"
                                                       : "ixy = -I_xy, ixz = -I_xz, iyz = -I_yz";
  if (format == ExportFormat::kUrdf) return "URDF elements of the inertia matrix: " + signs;
  if (format == ExportFormat::kSdf) return "SDFormat products are -m x y (not +m x y): " + signs;
  return "MJCF fullinertia = ixx iyy izz ixy ixz iyz, the inertia matrix elements: " + signs;
}

std::string Xyz(const std::array<double, 3>& v) {
  return Num(v[0]) + " " + Num(v[1]) + " " + Num(v[2]);
}

}  // namespace

InertialOrigin DefaultOrigin(const ExportInertia& in, ExportFormat format, ExportFrame frame) {
  InertialOrigin o;
  if (!in.cg.Given()) return o;
  const auto& c = in.cg.cg_m;
  if (format == ExportFormat::kJsbsim) {
    o.xyz = {-c[0], c[1], -c[2]};  // structural: x aft, y right, z up
  } else if (frame == ExportFrame::kFlu) {
    o.xyz = {c[0], -c[1], -c[2]};
  } else {
    o.xyz = c;
  }
  return o;
}

std::string InertialBlock(const ExportInertia& in, ExportFormat format, ExportFrame frame,
                          const InertialOrigin& origin) {
  const char* label = format == ExportFormat::kUrdf  ? "URDF"
                      : format == ExportFormat::kSdf ? "SDF"
                                                     : "MJCF";
  RequireComplete(in, label);
  const std::array<double, 6> e = UrdfElements(in, frame);
  const char* where = format == ExportFormat::kUrdf  ? "the <origin>"
                      : format == ExportFormat::kSdf ? "the <pose>"
                                                     : "the inertial pos";
  const std::string origin_text =
      !origin.note.empty() ? origin.note
      : in.cg.Given()
          ? std::string(where) + " is that CG in this file's frame, " + Xyz(origin.xyz) + "."
          : std::string(where) + " is the link origin, 0 0 0.";
  std::string s =
      XmlHeader(in, LinkFrameText(format, frame), LinkSignText(format, frame), origin_text);
  if (format == ExportFormat::kUrdf) {
    s += "<inertial>\n";
    s += "  <origin xyz=\"" + Xyz(origin.xyz) + "\" rpy=\"0 0 0\"/>\n";
    s += "  <mass value=\"" + Num(in.mass_kg) + "\"/>\n";
    s += "  <inertia ixx=\"" + Num(e[0]) + "\" ixy=\"" + Num(e[3]) + "\" ixz=\"" + Num(e[4]) +
         "\" iyy=\"" + Num(e[1]) + "\" iyz=\"" + Num(e[5]) + "\" izz=\"" + Num(e[2]) + "\"/>\n";
    s += "</inertial>\n";
  } else if (format == ExportFormat::kSdf) {
    s += "<inertial>\n";
    s += "  <pose>" + Xyz(origin.xyz) + " 0 0 0</pose>\n";
    s += "  <mass>" + Num(in.mass_kg) + "</mass>\n";
    s += "  <inertia>\n";
    const char* tags[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
    const int order[6] = {0, 3, 4, 1, 5, 2};
    for (int i = 0; i < 6; ++i) {
      s += std::string("    <") + tags[i] + ">" + Num(e[order[i]]) + "</" + tags[i] + ">\n";
    }
    s += "  </inertia>\n";
    s += "</inertial>\n";
  } else {
    s += "<inertial pos=\"" + Xyz(origin.xyz) + "\" mass=\"" + Num(in.mass_kg) +
         "\" fullinertia=\"" + Num(e[0]) + " " + Num(e[1]) + " " + Num(e[2]) + " " + Num(e[3]) +
         " " + Num(e[4]) + " " + Num(e[5]) + "\"/>\n";
  }
  return s;
}

std::string FormatUrdfInertial(const ExportInertia& in, ExportFrame frame) {
  return InertialBlock(in, ExportFormat::kUrdf, frame,
                       DefaultOrigin(in, ExportFormat::kUrdf, frame));
}

std::string FormatSdfInertial(const ExportInertia& in, ExportFrame frame) {
  return InertialBlock(in, ExportFormat::kSdf, frame, DefaultOrigin(in, ExportFormat::kSdf, frame));
}

std::string FormatMjcfBody(const ExportInertia& in, ExportFrame frame,
                           const std::string& body_name) {
  const std::string block =
      InertialBlock(in, ExportFormat::kMjcf, frame, DefaultOrigin(in, ExportFormat::kMjcf, frame));
  const size_t at = block.find("-->\n") + 4;  // the comment stays above the body
  return block.substr(0, at) + "<body name=\"" + body_name + "\">\n  " + block.substr(at) +
         "</body>\n";
}

std::string FormatJsbsimMassBalance(const ExportInertia& in) {
  RequireComplete(in, "JSBSim");
  const auto& v = in.value_kg_m2;
  const InertialOrigin origin = DefaultOrigin(in, ExportFormat::kJsbsim, ExportFrame::kFlu);
  std::string s =
      XmlHeader(in, "JSBSim's structural frame, x aft, y right, z up",
                "negated_crossproduct_inertia=\"true\": <ixy> etc. are the matrix elements, "
                "-integral x y dm in the structural frame: ixy = +I_xy, ixz = -I_xz, iyz = +I_yz",
                in.cg.Given() ? "the <location name=\"CG\"> is that CG in the structural frame "
                                "(x aft, y right, z up), " +
                                    Xyz(origin.xyz) + "."
                              : "the <location name=\"CG\"> is 0 0 0 of the structural frame.");
  const auto element = [](const char* tag, double value) {
    return std::string("  <") + tag + " unit=\"KG*M2\"> " + Num(value) + " </" + tag + ">\n";
  };
  s += "<mass_balance negated_crossproduct_inertia=\"true\">\n";
  s += element("ixx", v[kIxx]);
  s += element("iyy", v[kIyy]);
  s += element("izz", v[kIzz]);
  s += element("ixy", v[kIxy]);
  s += element("ixz", -v[kIxz]);
  s += element("iyz", v[kIyz]);
  s += "  <emptywt unit=\"KG\"> " + Num(in.mass_kg) + " </emptywt>\n";
  s += "  <location name=\"CG\" unit=\"M\">\n";
  s += "    <x> " + Num(origin.xyz[0]) + " </x>\n    <y> " + Num(origin.xyz[1]) +
       " </y>\n    <z> " + Num(origin.xyz[2]) + " </z>\n";
  s += "  </location>\n";
  s += "</mass_balance>\n";
  return s;
}

std::string FormatArdupilotFrame(const ExportInertia& in) {
  RequireComplete(in, "ArduPilot", /*moments_only=*/true);
  const auto& v = in.value_kg_m2;
  const auto str = [](const std::string& t) { return json(t).dump(); };
  // The keys SITL reads ("mass", "moment_inertia"), and one it ignores ("bifilar_export", first:
  // the mark that export wrote the file) with the uncertainty and provenance.
  std::string s = "{\n  \"bifilar_export\": {\n";
  s += "    \"results_file\": " + str(in.results_name) + ",\n";
  s += "    \"provenance\": " + str(ProvenanceText(in)) + ",\n";
  s += "    \"frame\": \"body FRD (x forward, y right, z down), about the CG; SITL's multicopter "
       "model takes its CG at the body origin\",\n";
  for (int k = 0; k < 3; ++k) {
    s +=
        std::string("    \"") + TensorComponentName(k) + "\": " + str(ComponentText(in, k)) + ",\n";
  }
  const std::string dropped = DroppedProducts(in, ExportFormat::kArdupilot);
  s += "    \"dropped\": " + str(dropped) + ",\n";
  s += "    \"not_measured\": " + str(CgText(in, "SITL puts the CG at the body origin.")) + "\n";
  s += "  },\n";
  s += "  \"mass\": " + Num(in.mass_kg) + ",\n";
  s += "  \"moment_inertia\": [" + Num(v[kIxx]) + ", " + Num(v[kIyy]) + ", " + Num(v[kIzz]) + "]\n";
  s += "}\n";
  return s;
}

bool ExportFormatHoldsProducts(ExportFormat format) { return format != ExportFormat::kArdupilot; }

std::string DroppedProducts(const ExportInertia& in, ExportFormat format) {
  if (ExportFormatHoldsProducts(format)) return "";
  const auto& v = in.value_kg_m2;
  const int pairs[3][3] = {{kIxy, kIxx, kIyy}, {kIxz, kIxx, kIzz}, {kIyz, kIyy, kIzz}};
  std::string s = std::string(ExportFormatName(format)) +
                  " holds the three moments only and drops the products:";
  for (const auto& pr : pairs) {
    const std::string n = TensorComponentName(pr[0]);
    if (in.source[pr[0]] == "missing") {
      s += " " + n + " (not measured),";
      continue;
    }
    const double scale = std::sqrt(v[pr[1]] * v[pr[2]]);
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.3g", 100.0 * std::abs(v[pr[0]]) / scale);
    s += " " + n + " = " + Num(v[pr[0]]) + " kg m^2 (" + pct + " % of sqrt(" +
         TensorComponentName(pr[1]) + " " + TensorComponentName(pr[2]) + "))" + ",";
  }
  s.back() = ';';
  s += " the simulated body's principal axes are its body axes";
  return s;
}

std::string NonPhysicalRefusal(const ExportInertia& in, ExportFormat format, bool force) {
  if (in.nonphysical.empty() || force || format == ExportFormat::kCsv) return "";
  return in.results_name + ": " + in.nonphysical + "; not written: a " + ExportFormatName(format) +
         " file must be physically valid (simulators refuse such a tensor or silently replace it;"
         " --force writes it anyway)";
}

std::string FormatExport(const ExportInertia& in, ExportFormat format, ExportFrame frame) {
  switch (format) {
    case ExportFormat::kUrdf:
      return FormatUrdfInertial(in, frame);
    case ExportFormat::kSdf:
      return FormatSdfInertial(in, frame);
    case ExportFormat::kJsbsim:
      return FormatJsbsimMassBalance(in);
    case ExportFormat::kMjcf:
      return FormatMjcfBody(in, frame);
    case ExportFormat::kArdupilot:
      return FormatArdupilotFrame(in);
    case ExportFormat::kCsv:
      break;
  }
  return FormatInertiaCsv(in);
}

std::string FormatInertiaCsv(const ExportInertia& in) {
  std::string header = "results_file,section,frame,mass_kg,mass_std_kg,mass_source";
  std::string row = CsvField(in.results_name) + "," + in.section +
                    ",body FRD (x forward y right z down) products +integral x y dm," +
                    CsvNum(in.mass_kg) + "," + CsvNum(in.mass_std_kg) + "," +
                    CsvField(in.mass_source.empty() ? "missing" : in.mass_source);
  for (int k = 0; k < 6; ++k) {
    const std::string n = TensorComponentName(k);
    header += "," + n + "_kg_m2," + n + "_std_kg_m2," + n + "_source";
    row += "," + CsvNum(in.value_kg_m2[k]) + "," + CsvNum(in.std_kg_m2[k]) + "," + in.source[k];
  }
  // The total stds, the full covariance (upper triangle, results.json tensor.covariance_kg2_m4),
  // the CG and the provenance.
  for (int k = 0; k < 6; ++k) {
    header += "," + std::string(TensorComponentName(k)) + "_total_std_kg_m2";
    row += "," + CsvNum(in.total_std_kg_m2[k]);
  }
  for (int a = 0; a < 6; ++a) {
    for (int b = a; b < 6; ++b) {
      header +=
          ",cov_" + std::string(TensorComponentName(a)) + "_" + TensorComponentName(b) + "_kg2_m4";
      row += "," + CsvNum(in.covariance_kg2_m4[a][b]);
    }
  }
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    header += ",cg_" + std::string(axes[i]) + "_m";
    row += "," + CsvNum(in.cg.cg_m[i]);
  }
  for (int i = 0; i < 3; ++i) {
    header += ",cg_" + std::string(axes[i]) + "_std_m";
    row += "," + CsvNum(in.cg.cg_std_m[i]);
  }
  header += ",results_version,campaign,export_version,date_utc";
  row += "," + CsvField(in.results_version) + "," + CsvField(in.campaign) + "," +
         CsvField(in.export_version) + "," + CsvField(in.date_utc);
  return header + "\n" + row + "\n";
}

namespace {

// A backup name beside `path` that does not exist: PATH.bak, else PATH.bak.1, .2, ...
std::string FreeBackupName(const std::string& path) {
  std::error_code ec;
  std::string name = path + ".bak";
  for (int i = 1;
       std::filesystem::symlink_status(name, ec).type() != std::filesystem::file_type::not_found;
       ++i) {
    name = path + ".bak." + std::to_string(i);
  }
  return name;
}

// --into: rewrites the model in place after writing its backup; the warnings go to `err`.
void RunExportInto(const ExportOptions& options, const ExportInertia& in, std::ostream& err) {
  std::string model, why;
  if (!ReadRegularFile(options.into_path, OutputFileCap(), &model, &why)) throw UserError(why);
  ExportFormat model_format;
  if (!DetectModelFormat(model, &model_format)) {
    throw UserError("export --into: " + options.into_path +
                    " is not a URDF (<robot>), SDF (<sdf>) or MJCF (<mujoco>) model");
  }
  if (model_format != options.format) {
    throw UserError("export --into: " + options.into_path + " is " +
                    ExportFormatName(model_format) + ", not " + ExportFormatName(options.format) +
                    "; give --format " + ExportFormatName(model_format));
  }
  std::vector<std::string> warnings;
  const std::string text = RewriteModelInertial(model, options.into_path, options.link_name, in,
                                                options.frame, options.force, &warnings);
  CheckFileTarget(options.into_path);
  const std::string backup = FreeBackupName(options.into_path);
  WriteFileAtomically(backup, model);
  WriteFileAtomically(options.into_path, text);
  for (const std::string& w : warnings) err << "bifilar: warning: " << w << "\n";
  err << "wrote " << options.into_path << " (the inertial of " << options.link_name << ", "
      << ExportFormatName(model_format) << "); the file as it was: " << backup << "\n";
}

}  // namespace

int RunExport(const ExportOptions& options, std::ostream& out, std::ostream& err) {
  std::string why;
  if (!options.Check(&why)) throw UserError("export: " + why);
  std::string path = options.results_path;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {  // the output folder of `bifilar process`
    path = (std::filesystem::path(path) / "results.json").string();
  }
  if (!options.out_path.empty()) {
    RefuseCampaignFile(options.out_path, path);
    // A link, device or folder first: only a regular file is opened to see who wrote it.
    CheckFileTarget(options.out_path);  // base/atomic_file.h
    if (!WrittenByExport(options.out_path)) {
      RefuseToReplace(options.out_path, "export --out", options.force);
    }
  }
  if (!options.into_path.empty()) {
    RefuseCampaignFile(options.into_path, path, "--into");
    CheckFileTarget(options.into_path);
  }
  std::string text;
  if (!ReadRegularFile(path, OutputFileCap(), &text, &why)) throw UserError(why);
  const ExportInertia in = ReadExportInertia(text, path, options);
  // The one refusal of a tensor that is not physical, for every format and --into.
  const std::string refusal = NonPhysicalRefusal(in, options.format, options.force);
  if (!refusal.empty()) {
    err << "bifilar: error: " << refusal << "\n";
    return 1;
  }
  for (const std::string& w : in.warnings) err << "bifilar: warning: " << w << "\n";
  if (!options.into_path.empty()) {
    RunExportInto(options, in, err);
    return 0;
  }
  const std::string body = FormatExport(in, options.format, options.frame);
  const std::string dropped = DroppedProducts(in, options.format);
  if (!dropped.empty()) err << "bifilar: warning: " << path << ": " << dropped << "\n";
  const std::vector<std::string> missing = in.Missing();
  if (!missing.empty() && options.format == ExportFormat::kCsv) {  // the others refused above
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    err << "bifilar: warning: " << path << ": " << names
        << " not in this result; left empty in the CSV\n";
  }
  err << "bifilar: note: the bifilar measures neither the mass nor the CG: "
      << (std::isfinite(in.mass_kg)
              ? "the mass written (" + Num(in.mass_kg) + " kg) is from " + in.mass_source + ", and "
              : std::string())
      << "the inertia is about the CG, which the "
      << (options.format == ExportFormat::kCsv         ? "CSV does not locate"
          : options.format == ExportFormat::kArdupilot ? "ArduPilot SITL takes at the body origin"
          : in.cg.Given()                              ? "file puts at aircraft.cg_m of the config"
                                                       : "file puts at its origin")
      << "\n";
  if (options.out_path.empty()) {
    out << body;
  } else {
    WriteFileAtomically(options.out_path, body);
    err << "wrote " << options.out_path << " (" << ExportFormatName(options.format) << ")\n";
  }
  return 0;
}

}  // namespace bifilar
