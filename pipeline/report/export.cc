#include "pipeline/report/export.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/bounded_read.h"
#include "base/enum_names.h"
#include "base/json_error.h"
#include "base/option_check.h"
#include "base/user_error.h"
#include "fit/tensor.h"
#include "pipeline/records/results_reader.h"
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
void RequireComplete(const ExportInertia& in, const char* format) {
  const std::vector<std::string> missing = in.Missing();
  if (!missing.empty()) {
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    const bool planar = in.section == "ellipse" ||
                        (missing.size() == 3 && missing[0] == "Iyy" && missing[1] == "Ixy");
    throw UserError(
        in.results_name + ": " + format + " needs all six components, and " + names +
        (missing.size() == 1 ? " is" : " are") + " not in this result" +
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

// The comment every XML file starts with: source, frame and sign, what is not measured.
std::string XmlHeader(const ExportInertia& in, const std::string& frame_text,
                      const std::string& sign_text, const char* cg_text) {
  std::string s = "bifilar export of " + in.results_name + " (section '" + in.section + "').\n";
  s += "     Frame: " + frame_text + "\n     Signs: " + sign_text + "\n";
  s += "     Inertia about the CG in body axes (x forward, y right, z down; products positive, "
       "I_xy = integral x y dm), kg m^2, value +- std:\n";
  for (int k = 0; k < 6; ++k) {
    s += "       " + std::string(TensorComponentName(k)) + " ";
    if (in.source[k] == "measured") {
      s += Num(in.value_kg_m2[k]) + " +- " +
           (std::isfinite(in.std_kg_m2[k]) ? Num(in.std_kg_m2[k]) : std::string("unknown")) + "\n";
    } else {
      s += Num(in.value_kg_m2[k]) + " (not measured: " +
           (in.source[k] == "set" ? "given by the user"
                                  : "assumed 0, aircraft symmetric about x-z") +
           ")\n";
    }
  }
  s += "     NOT MEASURED by the bifilar: the mass (" + Num(in.mass_kg) + " kg, from " +
       (in.mass_source == "--mass-kg" ? std::string("the command line") : in.mass_source) +
       ") and the CG: " + cg_text + " Move it to the measured CG; the inertia is about the CG.";
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
             Num(p[1]) + ", " + Num(p[2]) + " kg m^2): no rigid body has it, and simulators "
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
             Num(v[pr[0]]) + " and " + TensorComponentName(pr[1]) + " = " + Num(v[pr[1]]) +
             " (" + TensorComponentName(pr[2]) + "^2 >= " + TensorComponentName(pr[0]) + " " +
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
  return start.rfind("<!-- bifilar export of ", 0) == 0 ||
         start.rfind("results_file,section,frame,mass_kg,", 0) == 0;
}

// Throws UserError when --out is the input or a file of its output folder (see RunExport).
void RefuseCampaignFile(const std::string& out_path, const std::string& results_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(out_path, ec), ec);
  const fs::path input = fs::weakly_canonical(fs::absolute(results_path, ec), ec);
  const std::string refused = "export: --out " + out_path + " is ";
  const std::string advice = "; export writes a new file: choose a name outside it";
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

constexpr EnumName<ExportFormat> kExportFormatNames[] = {{ExportFormat::kUrdf, "urdf"},
                                                         {ExportFormat::kSdf, "sdf"},
                                                         {ExportFormat::kJsbsim, "jsbsim"},
                                                         {ExportFormat::kCsv, "csv"}};
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
       CheckFailText("--frame (with --format)", ExportFormatName(format),
                     "urdf or sdf (--frame applies to urdf and sdf only; the others have a fixed "
                     "frame)",
                     &f)) &&
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
  } else if (!named([&] { return results.Str("config"); }).empty()) {  // written before `aircraft` existed
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
  in.nonphysical = NonPhysical(in);
  if (!in.nonphysical.empty()) in.warnings.push_back(name + ": " + in.nonphysical);
  return in;
}

std::string FormatUrdfInertial(const ExportInertia& in, ExportFrame frame) {
  RequireComplete(in, "URDF");
  const std::array<double, 6> e = UrdfElements(in, frame);
  std::string s =
      XmlHeader(in,
                frame == ExportFrame::kFlu
                    ? "the link frame as ROS REP 103 takes it, x forward, y left, z up (FLU)"
                    : "the body axes as measured, x forward, y right, z down (FRD)",
                frame == ExportFrame::kFlu
                    ? "URDF elements of the inertia matrix: ixy = +I_xy, ixz = +I_xz, iyz = -I_yz"
                    : "URDF elements of the inertia matrix: ixy = -I_xy, ixz = -I_xz, iyz = -I_yz",
                "the <origin> is the link origin, 0 0 0.");
  s += "<inertial>\n";
  s += "  <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n";
  s += "  <mass value=\"" + Num(in.mass_kg) + "\"/>\n";
  s += "  <inertia ixx=\"" + Num(e[0]) + "\" ixy=\"" + Num(e[3]) + "\" ixz=\"" + Num(e[4]) +
       "\" iyy=\"" + Num(e[1]) + "\" iyz=\"" + Num(e[5]) + "\" izz=\"" + Num(e[2]) + "\"/>\n";
  s += "</inertial>\n";
  return s;
}

std::string FormatSdfInertial(const ExportInertia& in, ExportFrame frame) {
  RequireComplete(in, "SDF");
  const std::array<double, 6> e = UrdfElements(in, frame);
  std::string s = XmlHeader(
      in,
      frame == ExportFrame::kFlu
          ? "the link frame as Gazebo takes it, x forward, y left, z up (FLU)"
          : "the body axes as measured, x forward, y right, z down (FRD)",
      frame == ExportFrame::kFlu
          ? "SDFormat products are -m x y (not +m x y): ixy = +I_xy, ixz = +I_xz, iyz = -I_yz"
          : "SDFormat products are -m x y (not +m x y): ixy = -I_xy, ixz = -I_xz, iyz = -I_yz",
      "the <pose> is the link origin, 0 0 0.");
  s += "<inertial>\n";
  s += "  <pose>0 0 0 0 0 0</pose>\n";
  s += "  <mass>" + Num(in.mass_kg) + "</mass>\n";
  s += "  <inertia>\n";
  s += "    <ixx>" + Num(e[0]) + "</ixx>\n";
  s += "    <ixy>" + Num(e[3]) + "</ixy>\n";
  s += "    <ixz>" + Num(e[4]) + "</ixz>\n";
  s += "    <iyy>" + Num(e[1]) + "</iyy>\n";
  s += "    <iyz>" + Num(e[5]) + "</iyz>\n";
  s += "    <izz>" + Num(e[2]) + "</izz>\n";
  s += "  </inertia>\n";
  s += "</inertial>\n";
  return s;
}

std::string FormatJsbsimMassBalance(const ExportInertia& in) {
  RequireComplete(in, "JSBSim");
  const auto& v = in.value_kg_m2;
  std::string s =
      XmlHeader(in, "JSBSim's structural frame, x aft, y right, z up",
                "negated_crossproduct_inertia=\"true\": <ixy> etc. are the matrix elements, "
                "-integral x y dm in the structural frame: ixy = +I_xy, ixz = -I_xz, iyz = +I_yz",
                "the <location name=\"CG\"> is 0 0 0 of the structural frame.");
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
  s += "    <x> 0 </x>\n    <y> 0 </y>\n    <z> 0 </z>\n";
  s += "  </location>\n";
  s += "</mass_balance>\n";
  return s;
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
  return header + "\n" + row + "\n";
}

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
  std::string text;
  if (!ReadRegularFile(path, OutputFileCap(), &text, &why)) throw UserError(why);
  const ExportInertia in = ReadExportInertia(text, path, options);
  if (!in.nonphysical.empty() && options.format != ExportFormat::kCsv && !options.force) {
    err << "bifilar: error: " << path << ": " << in.nonphysical << "; not written: a "
        << ExportFormatName(options.format)
        << " file must be physically valid (--force writes it anyway)\n";
    return 1;
  }
  std::string body;
  switch (options.format) {
    case ExportFormat::kUrdf:
      body = FormatUrdfInertial(in, options.frame);
      break;
    case ExportFormat::kSdf:
      body = FormatSdfInertial(in, options.frame);
      break;
    case ExportFormat::kJsbsim:
      body = FormatJsbsimMassBalance(in);
      break;
    case ExportFormat::kCsv:
      body = FormatInertiaCsv(in);
      break;
  }
  for (const std::string& w : in.warnings) err << "bifilar: warning: " << w << "\n";
  const std::vector<std::string> missing = in.Missing();
  if (!missing.empty()) {  // CSV only: the XML formats refused above
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
      << (options.format == ExportFormat::kCsv ? "CSV does not locate" : "file puts at its origin")
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
