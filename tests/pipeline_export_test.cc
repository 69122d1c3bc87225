// `bifilar export` (pipeline/report/export.h): a worked example per format (a known tensor -> the
// exact numbers, derived by hand below), the frames checked against a body of point masses whose
// elements are computed from their definitions in each format's own frame, the planar sample
// campaign, and bad input through the real binary.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "base/user_error.h"
#include "pipeline/report/export.h"
#include "test_support.h"

namespace bifilar {
namespace {

using nlohmann::json;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// A results.json with a full tensor section (kg m^2, body FRD, products positive) and the
// config's aircraft mass.
std::string TensorResults(const std::array<double, 6>& v, const std::array<double, 6>& s,
                          const std::string& config =
                              "aircraft:\n  mass_kg: 1.25\n  "
                              "mass_std_kg: 0.01\n") {
  json t;
  const char* names[6] = {"Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz"};
  for (int k = 0; k < 6; ++k) {
    t[std::string(names[k]) + "_kg_m2"] = std::isnan(v[k]) ? json(nullptr) : json(v[k]);
    t[std::string(names[k]) + "_kg_m2_std"] = std::isnan(v[k]) ? json(nullptr) : json(s[k]);
  }
  json j = {{"program", "bifilar"}, {"version", "0.2.0"}, {"config", config}, {"tensor", t}};
  return j.dump(2);
}

// The worked example: Ixx 2, Iyy 3, Izz 4.5, Ixy 0.08, Ixz 0.12, Iyz -0.06 kg m^2 (products
// 2-4 % of the moments, I_yz negative so that every sign rule shows).
const std::array<double, 6> kExample = {2.0, 3.0, 4.5, 0.08, 0.12, -0.06};
const std::array<double, 6> kExampleStd = {0.002, 0.003, 0.004, 0.001, 0.0015, 0.0012};

ExportInertia Example(const ExportOptions& options = ExportOptions()) {
  ExportOptions o = options;
  o.results_path = "example.json";
  return ReadExportInertia(TensorResults(kExample, kExampleStd), "example.json", o);
}

// The element lines of an XML text, without the leading comment.
std::string AfterComment(const std::string& xml) { return xml.substr(xml.find("-->") + 4); }

TEST(ExportWorkedExample, UrdfFluAndFrd) {
  // URDF <inertia> holds the matrix elements, J_xy = -integral x' y' dm, in the link frame.
  // FLU (x' = x, y' = -y, z' = -z): J'_xy = -integral x(-y) dm = +I_xy = 0.08,
  // J'_xz = -integral x(-z) dm = +I_xz = 0.12, J'_yz = -integral (-y)(-z) dm = -I_yz = +0.06.
  const ExportInertia in = Example();
  EXPECT_EQ(AfterComment(FormatUrdfInertial(in, ExportFrame::kFlu)),
            "<inertial>\n"
            "  <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
            "  <mass value=\"1.25\"/>\n"
            "  <inertia ixx=\"2\" ixy=\"0.08\" ixz=\"0.12\" iyy=\"3\" iyz=\"0.06\" izz=\"4.5\"/>\n"
            "</inertial>\n");
  // FRD (the body axes as measured): every element is minus its product: -0.08, -0.12, +0.06.
  EXPECT_NE(FormatUrdfInertial(in, ExportFrame::kFrd)
                .find("<inertia ixx=\"2\" ixy=\"-0.08\" ixz=\"-0.12\" iyy=\"3\" iyz=\"0.06\" "
                      "izz=\"4.5\"/>"),
            std::string::npos);
}

TEST(ExportWorkedExample, Sdf) {
  // SDFormat: "the product of inertia convention -m x y (not +m x y)", link frame FLU as URDF:
  // ixy 0.08, ixz 0.12, iyz 0.06.
  EXPECT_EQ(AfterComment(FormatSdfInertial(Example(), ExportFrame::kFlu)),
            "<inertial>\n"
            "  <pose>0 0 0 0 0 0</pose>\n"
            "  <mass>1.25</mass>\n"
            "  <inertia>\n"
            "    <ixx>2</ixx>\n"
            "    <ixy>0.08</ixy>\n"
            "    <ixz>0.12</ixz>\n"
            "    <iyy>3</iyy>\n"
            "    <iyz>0.06</iyz>\n"
            "    <izz>4.5</izz>\n"
            "  </inertia>\n"
            "</inertial>\n");
}

TEST(ExportWorkedExample, Jsbsim) {
  // JSBSim's structural frame: x_s = -x, y_s = y, z_s = -z. negated_crossproduct_inertia="true":
  // <ixy> = -integral x_s y_s dm = +I_xy = 0.08, <ixz> = -integral x_s z_s dm = -I_xz = -0.12,
  // <iyz> = -integral y_s z_s dm = +I_yz = -0.06. Its loader builds the body matrix
  // [[ixx, -ixy, ixz], [-ixy, iyy, -iyz], [ixz, -iyz, izz]] = [[2, -0.08, -0.12], [-0.08, 3,
  // 0.06], [-0.12, 0.06, 4.5]], which is J = [[Ixx, -Ixy, -Ixz], ...] of results.json.
  EXPECT_EQ(AfterComment(FormatJsbsimMassBalance(Example())),
            "<mass_balance negated_crossproduct_inertia=\"true\">\n"
            "  <ixx unit=\"KG*M2\"> 2 </ixx>\n"
            "  <iyy unit=\"KG*M2\"> 3 </iyy>\n"
            "  <izz unit=\"KG*M2\"> 4.5 </izz>\n"
            "  <ixy unit=\"KG*M2\"> 0.08 </ixy>\n"
            "  <ixz unit=\"KG*M2\"> -0.12 </ixz>\n"
            "  <iyz unit=\"KG*M2\"> -0.06 </iyz>\n"
            "  <emptywt unit=\"KG\"> 1.25 </emptywt>\n"
            "  <location name=\"CG\" unit=\"M\">\n"
            "    <x> 0 </x>\n"
            "    <y> 0 </y>\n"
            "    <z> 0 </z>\n"
            "  </location>\n"
            "</mass_balance>\n");
}

TEST(ExportWorkedExample, Csv) {
  // The CSV keeps results.json's own convention (body FRD, products positive) and the stds.
  const std::string csv = FormatInertiaCsv(Example());
  const std::string row = csv.substr(csv.find('\n') + 1);
  EXPECT_EQ(row,
            "example.json,tensor,body FRD (x forward y right z down) products +integral x y dm,"
            "1.25,0.01,config aircraft.mass_kg,"
            "2,0.002,measured,3,0.003,measured,4.5,0.004,measured,"
            "0.08,0.001,measured,0.12,0.0015,measured,-0.06,0.0012,measured\n");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "results_file,section,frame,mass_kg,mass_std_kg,mass_source,"
            "Ixx_kg_m2,Ixx_std_kg_m2,Ixx_source,Iyy_kg_m2,Iyy_std_kg_m2,Iyy_source,"
            "Izz_kg_m2,Izz_std_kg_m2,Izz_source,Ixy_kg_m2,Ixy_std_kg_m2,Ixy_source,"
            "Ixz_kg_m2,Ixz_std_kg_m2,Ixz_source,Iyz_kg_m2,Iyz_std_kg_m2,Iyz_source");
}

// The attribute values of `tag` in `xml` (URDF) or the element texts (SDF, JSBSim), as numbers.
double XmlNumber(const std::string& xml, const std::string& pattern) {
  std::smatch m;
  const std::string body = AfterComment(xml);
  EXPECT_TRUE(std::regex_search(body, m, std::regex(pattern))) << pattern << "\n" << body;
  return m.size() > 1 ? std::stod(m[1].str()) : NAN;
}

TEST(ExportFrames, PointMassBodyGivesEachFormatsElementsFromTheirDefinitions) {
  // 40 point masses at seeded positions in body FRD axes (about their common CG). The bifilar's
  // numbers are the positive products in FRD; each format's numbers are computed here directly
  // from its definition in its own frame, without the exporter's sign table.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> pos(0.0, 0.5);
  std::uniform_real_distribution<double> mass(0.1, 1.0);
  std::vector<std::array<double, 4>> pts;  // m, x, y, z
  double cg[3] = {0, 0, 0}, total = 0;
  for (int i = 0; i < 40; ++i) {
    pts.push_back({mass(rng), pos(rng), 0.6 * pos(rng), 0.3 * pos(rng) + 0.1 * pos(rng)});
    total += pts.back()[0];
    for (int a = 0; a < 3; ++a) cg[a] += pts.back()[0] * pts.back()[a + 1];
  }
  for (auto& p : pts) {
    for (int a = 0; a < 3; ++a) p[a + 1] -= cg[a] / total;
  }
  // Moments and positive products (x, y, z given per frame as a function of the FRD point).
  const auto inertia = [&pts](auto to_frame) {
    std::array<double, 6> c = {0, 0, 0, 0, 0, 0};  // Ixx Iyy Izz, +sum m x y, +sum m x z, +yz
    for (const auto& p : pts) {
      const std::array<double, 3> r = to_frame(p[1], p[2], p[3]);
      c[0] += p[0] * (r[1] * r[1] + r[2] * r[2]);
      c[1] += p[0] * (r[0] * r[0] + r[2] * r[2]);
      c[2] += p[0] * (r[0] * r[0] + r[1] * r[1]);
      c[3] += p[0] * r[0] * r[1];
      c[4] += p[0] * r[0] * r[2];
      c[5] += p[0] * r[1] * r[2];
    }
    return c;
  };
  const auto frd = inertia([](double x, double y, double z) {
    return std::array<double, 3>{x, y, z};
  });
  const auto flu = inertia([](double x, double y, double z) {
    return std::array<double, 3>{x, -y, -z};
  });
  const auto structural = inertia([](double x, double y, double z) {
    return std::array<double, 3>{-x, y, -z};
  });
  ExportOptions o;
  o.results_path = "points.json";
  const ExportInertia in =
      ReadExportInertia(TensorResults(frd, {1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3}), "points.json", o);
  constexpr double kTol = 1e-8;  // 10 significant digits written, moments ~1 kg m^2
  // URDF/SDF, FLU: elements -sum m x' y' etc. in FLU.
  const std::string urdf = FormatUrdfInertial(in, ExportFrame::kFlu);
  const std::string sdf = FormatSdfInertial(in, ExportFrame::kFlu);
  const char* names[6] = {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"};
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE(names[k]);
    const double expected = k < 3 ? flu[k] : -flu[k];
    EXPECT_NEAR(XmlNumber(urdf, std::string(names[k]) + "=\"([^\"]+)\""), expected, kTol);
    EXPECT_NEAR(XmlNumber(sdf, std::string("<") + names[k] + ">([^<]+)<"), expected, kTol);
    // FRD: elements -sum m x y in the body axes themselves.
    const double frd_element = k < 3 ? frd[k] : -frd[k];
    EXPECT_NEAR(XmlNumber(FormatUrdfInertial(in, ExportFrame::kFrd),
                          std::string(names[k]) + "=\"([^\"]+)\""),
                frd_element, kTol);
    // JSBSim, negated_crossproduct_inertia="true": elements -sum m x_s y_s in the structural
    // frame.
    const double jsb = k < 3 ? structural[k] : -structural[k];
    EXPECT_NEAR(XmlNumber(FormatJsbsimMassBalance(in),
                          std::string("<") + names[k] + " unit=\"KG\\*M2\"> ([^ ]+) <"),
                jsb, kTol);
  }
  // The moments do not depend on the frame (a half turn about an axis).
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(frd[k], flu[k], 1e-12);
    EXPECT_NEAR(frd[k], structural[k], 1e-12);
  }
}

TEST(ExportRead, PlanarResultsExportIxxIzzIxzAndNameWhatIsMissing) {
  // The sample campaign (pitch only): the ellipse section, I_x, I_z, I_xz.
  const std::string path =
      std::string(BIFILAR_SOURCE_DIR) + "/sample_runs/prandtl_d/out/results.json";
  const json j = json::parse(ReadFile(path));
  ExportOptions o;
  o.results_path = path;
  ExportInertia in = ReadExportInertia(ReadFile(path), path, o);
  // A sample written since the tensor merge also has a tensor section (mode planar_xz) whose
  // x-z components repeat the ellipse's: export reads it, with the same numbers (exactly: both
  // sections of the one committed file, written in one run; nothing is recomputed here).
  const bool planar_tensor = j.contains("tensor") && j["tensor"].is_object() &&
                             j["tensor"].value("mode", std::string()) == "planar_xz";
  EXPECT_EQ(in.section, planar_tensor ? "tensor" : "ellipse");
  EXPECT_EQ(in.value_kg_m2[0], j["ellipse"]["Ix_kg_m2"].get<double>());
  EXPECT_EQ(in.value_kg_m2[2], j["ellipse"]["Iz_kg_m2"].get<double>());
  EXPECT_EQ(in.value_kg_m2[4], j["ellipse"]["Ixz_kg_m2"].get<double>());
  EXPECT_EQ(in.std_kg_m2[4], j["ellipse"]["Ixz_kg_m2_std"].get<double>());
  EXPECT_EQ(in.Missing(), (std::vector<std::string>{"Iyy", "Ixy", "Iyz"}));
  EXPECT_EQ(in.mass_kg, 5.5);  // aircraft.mass_kg of configs/prandtl_d.yaml
  try {
    FormatUrdfInertial(in, ExportFrame::kFlu);
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("Iyy, Ixy, Iyz are not in this result"), std::string::npos) << m;
    EXPECT_NE(m.find("--set"), std::string::npos) << m;
    EXPECT_NE(m.find("--symmetric"), std::string::npos) << m;
  }
  // The CSV leaves them empty and says so per component.
  const std::string csv = FormatInertiaCsv(in);
  EXPECT_NE(csv.find(",,,missing,"), std::string::npos) << csv;
  // --set Iyy and --symmetric complete it.
  o.set_kg_m2["Iyy"] = 1.5;
  o.symmetric = true;
  in = ReadExportInertia(ReadFile(path), path, o);
  EXPECT_TRUE(in.Missing().empty());
  EXPECT_EQ(in.source[1], "set");
  EXPECT_EQ(in.source[3], "symmetric");
  EXPECT_EQ(in.value_kg_m2[5], 0.0);
  EXPECT_NE(FormatJsbsimMassBalance(in).find("<iyy unit=\"KG*M2\"> 1.5 </iyy>"), std::string::npos);
  // --set cannot replace a measured component.
  o.set_kg_m2["Ixx"] = 3.0;
  EXPECT_THROW(ReadExportInertia(ReadFile(path), path, o), UserError);
}

// results.json's `aircraft` (written by ResultsToJson) is the mass export uses; the stored
// config is read only for files written before that key (the test above: the committed sample).
TEST(ExportRead, MassFromTheResultsAircraftSectionBeforeTheStoredConfig) {
  json j = json::parse(TensorResults(kExample, kExampleStd));
  j["aircraft"] = {{"mass_kg", 2.5}, {"mass_std_kg", 0.02}};  // differs from the config's 1.25
  ExportOptions o;
  o.results_path = "r.json";
  ExportInertia in = ReadExportInertia(j.dump(), "r.json", o);
  EXPECT_EQ(in.mass_kg, 2.5);
  EXPECT_EQ(in.mass_std_kg, 0.02);
  EXPECT_EQ(in.mass_source, "config aircraft.mass_kg");
  // No std given in the config: null, read as unknown.
  j["aircraft"]["mass_std_kg"] = nullptr;
  in = ReadExportInertia(j.dump(), "r.json", o);
  EXPECT_EQ(in.mass_kg, 2.5);
  EXPECT_TRUE(std::isnan(in.mass_std_kg));
  // No aircraft in the campaign: null, no mass (the stored config is not consulted).
  j["aircraft"] = nullptr;
  in = ReadExportInertia(j.dump(), "r.json", o);
  EXPECT_TRUE(std::isnan(in.mass_kg));
  EXPECT_TRUE(in.mass_source.empty());
  // A file without the key: the stored config, as before.
  j.erase("aircraft");
  in = ReadExportInertia(j.dump(), "r.json", o);
  EXPECT_EQ(in.mass_kg, 1.25);
  EXPECT_EQ(in.mass_std_kg, 0.01);
}

// issue 25 item 6: a tensor campaign's stored config without aircraft.mass_std_kg, or without an
// aircraft section, is read without "could not be read for the mass" (the mass is written from
// it, or named as missing); a config that is not YAML still says so.
TEST(ExportRead, StoredConfigWithoutMassStdOrAircraftGivesNoFalseWarning) {
  ExportOptions o;
  o.results_path = "r.json";
  const auto no_read_warning = [](const ExportInertia& in) {
    for (const std::string& w : in.warnings) {
      if (w.find("could not be read") != std::string::npos) return false;
    }
    return true;
  };
  ExportInertia in = ReadExportInertia(
      TensorResults(kExample, kExampleStd, "rig:\n  mass_kg: 0.6\naircraft:\n  mass_kg: 3.34\n"),
      "r.json", o);
  EXPECT_EQ(in.mass_kg, 3.34);
  EXPECT_TRUE(std::isnan(in.mass_std_kg));
  EXPECT_TRUE(no_read_warning(in));
  in = ReadExportInertia(TensorResults(kExample, kExampleStd, "rig:\n  mass_kg: 0.6\n"), "r.json",
                         o);
  EXPECT_TRUE(std::isnan(in.mass_kg));
  EXPECT_TRUE(no_read_warning(in));
  in = ReadExportInertia(TensorResults(kExample, kExampleStd, "aircraft: [unclosed\n"), "r.json", o);
  EXPECT_FALSE(no_read_warning(in));
}

TEST(ExportRead, ThreeAxisTensorNamesTheMissingProducts) {
  const double nan = NAN;
  ExportOptions o;
  o.results_path = "three.json";
  const std::string text =
      TensorResults({0.02, 0.021, 0.035, nan, nan, nan}, {1e-5, 1e-5, 1e-5, 0, 0, 0});
  ExportInertia in = ReadExportInertia(text, "three.json", o);
  EXPECT_EQ(in.section, "tensor");
  EXPECT_EQ(in.Missing(), (std::vector<std::string>{"Ixy", "Ixz", "Iyz"}));
  // --symmetric fills Ixy and Iyz only: Ixz is still missing and named.
  o.symmetric = true;
  in = ReadExportInertia(text, "three.json", o);
  try {
    FormatSdfInertial(in, ExportFrame::kFlu);
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("Ixz is not in this result"), std::string::npos)
        << e.what();
  }
}

TEST(ExportRead, UnphysicalTensorWarns) {
  ExportOptions o;
  o.results_path = "bad.json";
  // Principal moments 1, 1, 3: 3 > 1 + 1 breaks the triangle inequality.
  const ExportInertia in =
      ReadExportInertia(TensorResults({1, 1, 3, 0, 0, 0}, {0, 0, 0, 0, 0, 0}), "bad.json", o);
  ASSERT_EQ(in.warnings.size(), 1u);
  EXPECT_NE(in.warnings[0].find("triangle inequality"), std::string::npos) << in.warnings[0];
}

using test_support::Bifilar;
using test_support::CliRun;

TEST(ExportCli, WritesEachFormatAndRefusesBadInputNamingTheFile) {
  TempDir dir("bifilar_export");
  const std::string results =
      WriteFile(dir.path + "/out/results.json", TensorResults(kExample, kExampleStd));
  // --out writes the file; stdout stays empty, stderr notes the mass and CG.
  CliRun r = Bifilar(dir, "export " + results + " --format urdf --out " + dir.path + "/a.urdf");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("neither the mass nor the CG"), std::string::npos) << r.err;
  const std::string written = ReadFile(dir.path + "/a.urdf");
  EXPECT_EQ(AfterComment(written), AfterComment(FormatUrdfInertial(Example(), ExportFrame::kFlu)));
  EXPECT_EQ(written.rfind("<!-- bifilar export of " + results, 0), 0u) << written;
  // The output folder works as well as the file; the text goes to stdout without --out.
  r = Bifilar(dir, "export " + dir.path + "/out --format jsbsim");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("<ixz unit=\"KG*M2\"> -0.12 </ixz>"), std::string::npos) << r.out;
  r = Bifilar(dir, "export " + results + " --format sdf --frame frd");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("<iyz>0.06</iyz>"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("<ixy>-0.08</ixy>"), std::string::npos) << r.out;

  // Bad input: one line, exit 2, naming the file or option.
  const std::string not_json = WriteFile(dir.path + "/notjson.json", "{ \"program\": ");
  const std::string other = WriteFile(dir.path + "/other.json", "{\"program\": \"xfoil\"}");
  const std::string empty =
      WriteFile(dir.path + "/empty.json", "{\"program\": \"bifilar\", \"traces\": []}");
  const std::string no_mass = WriteFile(
      dir.path + "/nomass.json", TensorResults(kExample, kExampleStd, "rig:\n  mass_kg: 1\n"));
  const struct {
    std::string args, expect;
  } cases[] = {
      {"export " + not_json + " --format csv", not_json + ": not valid JSON"},
      {"export " + other + " --format csv", other + ": not a results.json written by bifilar"},
      {"export " + empty + " --format csv", empty + ": holds no inertia to export"},
      {"export " + dir.path + "/missing.json --format csv", "missing.json: cannot open"},
      {"export " + results + " --format stl", "--format must be urdf, sdf, jsbsim or csv"},
      {"export " + results + " --format jsbsim --frame flu", "--frame applies to urdf and sdf"},
      {"export " + results + " --format urdf --set Ixx=1", "--set Ixx: " + results + " measured"},
      {"export " + results + " --format urdf --set Ixq=1", "--set = \"Ixq\"; must be Ixx, Iyy, Izz, Ixy, Ixz or Iyz (unknown component)"},
      {"export " + results + " --format urdf --set Iyy", "expected NAME=VALUE"},
      {"export " + no_mass + " --format urdf", no_mass + ": URDF needs the mass"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    r = Bifilar(dir, c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // The mass option fills it, and the CSV needs no mass.
  r = Bifilar(dir, "export " + no_mass + " --format urdf --mass-kg 0.9");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("<mass value=\"0.9\"/>"), std::string::npos) << r.out;
  // An XML comment holds no "--" (not even from a path): the file stays well-formed.
  const std::string dashes = WriteFile(dir.path + "/a--b/results.json", ReadFile(no_mass));
  r = Bifilar(dir, "export " + dashes + " --format sdf --mass-kg 0.9 --set Ixy=0.01 --symmetric");
  ASSERT_EQ(r.exit_code, 2) << r.err;  // Ixy is measured: cannot be set
  r = Bifilar(dir, "export " + dashes + " --format sdf --mass-kg 0.9");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string comment = r.out.substr(4, r.out.find("-->") - 4);
  EXPECT_EQ(comment.find("--"), std::string::npos) << comment;
  EXPECT_EQ(r.out.find("-->"), r.out.rfind("-->"));
  r = Bifilar(dir, "export " + no_mass + " --format csv");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(",,,missing,2,"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace bifilar
