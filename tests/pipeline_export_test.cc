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
#include "base/version.h"
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
  // JSBSim has no packaged parser to load this in a test; its convention is documented in
  // JSBSim's own source, the class comment of FGMassBalance (src/models/FGMassBalance.h: the
  // <mass_balance> element, <ixx> .. <iyz>, and the attribute negated_crossproduct_inertia,
  // default "true") and implemented in FGMassBalance::Load (src/models/FGMassBalance.cpp), which
  // reads the elements in the structural frame and builds the body-axes matrix shown below; the
  // JSBSim Reference Manual's mass_balance section says the same. The point-mass test below
  // computes each element from that definition.
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
  // The CSV keeps results.json's own convention (body FRD, products positive) and the stds; then
  // the total stds, the full covariance (upper triangle), the CG and the provenance.
  ExportOptions o;
  o.date_utc = "2026-11-28T12:00:00Z";
  const std::string csv = FormatInertiaCsv(Example(o));
  const std::string row = csv.substr(csv.find('\n') + 1);
  const std::string values =
      "example.json,tensor,body FRD (x forward y right z down) products +integral x y dm,"
      "1.25,0.01,config aircraft.mass_kg,"
      "2,0.002,measured,3,0.003,measured,4.5,0.004,measured,"
      "0.08,0.001,measured,0.12,0.0015,measured,-0.06,0.0012,measured,";
  EXPECT_EQ(row.substr(0, values.size()), values);
  // No total_uncertainty, covariance or CG in this results.json: empty; then the provenance.
  EXPECT_EQ(row.substr(values.size()), std::string(6 + 21 + 6 - 1, ',') + ",0.2.0,," +
                                           ProgramVersion() + ",2026-11-28T12:00:00Z\n");
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(header.rfind("results_file,section,frame,mass_kg,mass_std_kg,mass_source,"
                         "Ixx_kg_m2,Ixx_std_kg_m2,Ixx_source,Iyy_kg_m2,Iyy_std_kg_m2,Iyy_source,"
                         "Izz_kg_m2,Izz_std_kg_m2,Izz_source,Ixy_kg_m2,Ixy_std_kg_m2,Ixy_source,"
                         "Ixz_kg_m2,Ixz_std_kg_m2,Ixz_source,Iyz_kg_m2,Iyz_std_kg_m2,Iyz_source,"
                         "Ixx_total_std_kg_m2,",
                         0),
            0u)
      << header;
  EXPECT_NE(header.find(",cov_Ixx_Ixx_kg2_m4,cov_Ixx_Iyy_kg2_m4,"), std::string::npos);
  EXPECT_NE(header.find(",cov_Ixz_Iyz_kg2_m4,cov_Iyz_Iyz_kg2_m4,cg_x_m,"), std::string::npos);
  EXPECT_NE(header.find(",results_version,campaign,export_version,date_utc"), std::string::npos);
}

TEST(ExportWorkedExample, Mjcf) {
  // MJCF fullinertia = "ixx iyy izz ixy ixz iyz", the matrix elements in the body frame (FLU by
  // default): the same numbers as URDF's, in MuJoCo's order.
  EXPECT_EQ(AfterComment(FormatMjcfBody(Example(), ExportFrame::kFlu)),
            "<body name=\"aircraft\">\n"
            "  <inertial pos=\"0 0 0\" mass=\"1.25\" fullinertia=\"2 3 4.5 0.08 0.12 0.06\"/>\n"
            "</body>\n");
  EXPECT_NE(
      FormatMjcfBody(Example(), ExportFrame::kFrd).find("fullinertia=\"2 3 4.5 -0.08 -0.12 0.06\""),
      std::string::npos);
}

TEST(ExportWorkedExample, ArdupilotKeepsTheDiagonalAndNamesTheProductsItDrops) {
  // SIM_Frame.cpp reads "mass" and "moment_inertia" (body FRD); the rest is ignored by SITL.
  const std::string text = FormatArdupilotFrame(Example());
  const json j = json::parse(text);
  EXPECT_EQ(j["mass"].get<double>(), 1.25);
  EXPECT_EQ(j["moment_inertia"], json({2.0, 3.0, 4.5}));
  EXPECT_EQ(text.rfind("{\n  \"bifilar_export\": ", 0), 0u) << text;
  // |Ixy| / sqrt(Ixx Iyy) = 0.08 / sqrt(6) = 3.27 %, 0.12 / sqrt(9) = 4 %, 0.06 / sqrt(13.5) =
  // 1.63 %.
  const std::string dropped = DroppedProducts(Example(), ExportFormat::kArdupilot);
  EXPECT_NE(dropped.find("Ixy = 0.08 kg m^2 (3.27 % of sqrt(Ixx Iyy))"), std::string::npos)
      << dropped;
  EXPECT_NE(dropped.find("Ixz = 0.12 kg m^2 (4 % of sqrt(Ixx Izz))"), std::string::npos);
  EXPECT_NE(dropped.find("Iyz = -0.06 kg m^2 (1.63 % of sqrt(Iyy Izz))"), std::string::npos);
  EXPECT_EQ(j["bifilar_export"]["dropped"].get<std::string>(), dropped);
  // Every other format holds the products: no warning.
  for (ExportFormat f : {ExportFormat::kUrdf, ExportFormat::kSdf, ExportFormat::kJsbsim,
                         ExportFormat::kMjcf, ExportFormat::kCsv}) {
    EXPECT_EQ(DroppedProducts(Example(), f), "");
  }
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
  in =
      ReadExportInertia(TensorResults(kExample, kExampleStd, "aircraft: [unclosed\n"), "r.json", o);
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
      {"export " + results + " --format stl",
       "--format must be urdf, sdf, jsbsim, csv, mjcf or ardupilot"},
      {"export " + results + " --format jsbsim --frame flu",
       "--frame applies to urdf, sdf and mjcf"},
      {"export " + results + " --format ardupilot --frame frd",
       "--frame applies to urdf, sdf and mjcf"},
      {"export " + results + " --format urdf --into " + dir.path + "/m.urdf",
       "given together (--into MODEL --link NAME)"},
      {"export " + results + " --format jsbsim --into m.xml --link a", "urdf, sdf or mjcf"},
      {"export " + results + " --format urdf --set Ixx=1", "--set Ixx: " + results + " measured"},
      {"export " + results + " --format urdf --set Ixq=1",
       "--set = \"Ixq\"; must be Ixx, Iyy, Izz, Ixy, Ixz or Iyz (unknown component)"},
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

// issue 35 item 7: a tensor that is not physical is refused by every simulator format with the
// one message (NonPhysicalRefusal), nothing written; --force writes it, the numbers as they are
// (never zeroed), and the warning stays.
TEST(ExportRefusal, EveryFormatRefusesANonPhysicalTensorWithOneMessage) {
  TempDir dir("bifilar_export_refusal");
  // Principal moments 1, 1, 3: 3 > 1 + 1 breaks the triangle inequality.
  const std::string bad =
      WriteFile(dir.path + "/bad.json", TensorResults({1, 1, 3, 0, 0, 0}, {0, 0, 0, 0, 0, 0}));
  const std::string expected_tail =
      ": the principal moments 1, 1, 3 kg m^2 break the triangle inequality (largest > sum of "
      "the others): no rigid body has them; check the products; not written: a ";
  const std::string expected_end =
      " file must be physically valid (simulators refuse such a tensor or silently replace it; "
      "--force writes it anyway)\n";
  for (const char* format : {"urdf", "sdf", "jsbsim", "mjcf", "ardupilot"}) {
    SCOPED_TRACE(format);
    const std::string out = dir.path + "/bad." + format;
    CliRun r = Bifilar(dir, "export " + bad + " --format " + format + " --out " + out);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err, "bifilar: error: " + bad + expected_tail + format + expected_end);
    EXPECT_FALSE(std::filesystem::exists(out));
    r = Bifilar(dir, "export " + bad + " --format " + format + " --force");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + bad + ": the principal moments 1, 1, 3"), std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("3"), std::string::npos);
  }
  // The same function for --into, and the CSV (not a simulator's) carries the warning instead.
  ExportOptions o;
  o.results_path = bad;
  const ExportInertia in = ReadExportInertia(ReadFile(bad), bad, o);
  EXPECT_EQ(NonPhysicalRefusal(in, ExportFormat::kSdf, false),
            bad + expected_tail + "sdf" + expected_end.substr(0, expected_end.size() - 1));
  EXPECT_EQ(NonPhysicalRefusal(in, ExportFormat::kSdf, true), "");
  EXPECT_EQ(NonPhysicalRefusal(in, ExportFormat::kCsv, false), "");
  EXPECT_EQ(NonPhysicalRefusal(Example(), ExportFormat::kUrdf, false), "");
  const std::string model =
      WriteFile(dir.path + "/m.urdf", "<robot name=\"r\"><link name=\"a\"></link></robot>\n");
  const CliRun r =
      Bifilar(dir, "export " + bad + " --format urdf --into " + model + " --link a --force");
  EXPECT_EQ(r.exit_code, 0) << r.err;  // --force: written
  const CliRun refused =
      Bifilar(dir, "export " + bad + " --format urdf --into " + model + " --link a");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_EQ(refused.err, "bifilar: error: " + bad + expected_tail + "urdf" + expected_end);
}

// issue 35 items 5 and 6: the CG of the config (aircraft.cg_m, body FRD) is written as each
// format's inertial origin in its own frame; every file carries stat and total std and the
// provenance.
TEST(ExportCg, ConfigCgIsTheInertialOriginInEachFormatsFrame) {
  json j = json::parse(TensorResults(
      kExample, kExampleStd,
      "aircraft:\n  mass_kg: 1.25\n  cg_m: [0.1, -0.02, 0.03]\n  cg_std_m: [0.001, 0.001, "
      "0.002]\n"));
  j["config_file"] = "configs/x500.yaml";
  j["total_uncertainty"] = {{"common_mode_relative_std", 0.01}};
  ExportOptions o;
  o.results_path = "r.json";
  o.date_utc = "2026-11-28T12:00:00Z";
  const ExportInertia in = ReadExportInertia(j.dump(), "r.json", o);
  ASSERT_TRUE(in.cg.Given());
  // FLU (x, -y, -z): 0.1 0.02 -0.03; FRD as measured; JSBSim structural (-x, y, -z).
  EXPECT_NE(FormatUrdfInertial(in, ExportFrame::kFlu).find("<origin xyz=\"0.1 0.02 -0.03\""),
            std::string::npos);
  EXPECT_NE(FormatUrdfInertial(in, ExportFrame::kFrd).find("<origin xyz=\"0.1 -0.02 0.03\""),
            std::string::npos);
  EXPECT_NE(FormatSdfInertial(in, ExportFrame::kFlu).find("<pose>0.1 0.02 -0.03 0 0 0</pose>"),
            std::string::npos);
  EXPECT_NE(FormatMjcfBody(in, ExportFrame::kFlu).find("<inertial pos=\"0.1 0.02 -0.03\""),
            std::string::npos);
  const std::string jsb = FormatJsbsimMassBalance(in);
  EXPECT_NE(jsb.find("<x> -0.1 </x>\n    <y> -0.02 </y>\n    <z> -0.03 </z>"), std::string::npos)
      << jsb;
  // Stat and total std (sqrt(0.002^2 + (0.01 * 2)^2) = 0.0201 for Ixx) and the provenance.
  const std::string urdf = FormatUrdfInertial(in, ExportFrame::kFlu);
  EXPECT_NE(urdf.find("Ixx 2 +- 0.002 (stat) +- 0.02009975124 (total)"), std::string::npos) << urdf;
  EXPECT_NE(urdf.find("Provenance: bifilar " + std::string(ProgramVersion()) +
                      " (results.json written by bifilar 0.2.0), campaign configs/x500.yaml, "
                      "exported 2026-11-28T12:00:00Z"),
            std::string::npos)
      << urdf;
  EXPECT_NE(urdf.find("+- 0.001 0.001 0.002 m"), std::string::npos);
  const std::string csv = FormatInertiaCsv(in);
  EXPECT_NE(csv.find(",0.1,-0.02,0.03,0.001,0.001,0.002,0.2.0,configs/x500.yaml,"),
            std::string::npos)
      << csv;
  // A CG that is not 3 numbers: the config names the key and line.
  try {
    ReadAircraftCgText("aircraft:\n  mass_kg: 1\n  cg_m: [0.1, 0.2]\n", "c.yaml");
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("c.yaml:3:9: 'aircraft.cg_m' must be a list of 3 numbers"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ReadAircraftCgText("aircraft:\n  cg_m: [0, 0, 0]\n  cg_std_m: [0, -1, 0]\n", "c"),
               UserError);
  EXPECT_THROW(ReadAircraftCgText("aircraft:\n  cg_std_m: [0, 1, 0]\n", "c"), UserError);
  EXPECT_FALSE(ReadAircraftCgText("aircraft:\n  mass_kg: 1\n", "c").Given());
}

// --into through the real binary: refused without --force on a model export did not write,
// then a backup beside the model, never replacing one that exists.
TEST(ExportCli, IntoRewritesALinkKeepsABackupAndRefusesWithoutForce) {
  TempDir dir("bifilar_export_into_cli");
  const std::string results =
      WriteFile(dir.path + "/out/results.json", TensorResults(kExample, kExampleStd));
  const std::string original =
      "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <link name=\"base_link\">\n"
      "    <inertial>\n      <mass value=\"1\"/>\n      <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" "
      "iyy=\"1\" iyz=\"0\" izz=\"1\"/>\n    </inertial>\n  </link>\n</robot>\n";
  const std::string model = WriteFile(dir.path + "/r.urdf", original);
  const std::string args = "export " + results + " --format urdf --into " + model + " --link ";
  CliRun r = Bifilar(dir, args + "base_link");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(model + ": link 'base_link''s <inertial> was not written by bifilar "
                               "export; add --force"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(ReadFile(model), original);
  r = Bifilar(dir, args + "base --force");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("has no link named 'base' (its links: base_link)"), std::string::npos)
      << r.err;
  r = Bifilar(dir, "export " + results + " --format sdf --into " + model + " --link base_link");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(model + " is urdf, not sdf; give --format urdf"), std::string::npos)
      << r.err;
  WriteFile(model + ".bak", "an older backup\n");
  r = Bifilar(dir, args + "base_link --force");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the file as it was: " + model + ".bak.1"), std::string::npos) << r.err;
  EXPECT_EQ(ReadFile(model + ".bak"), "an older backup\n");
  EXPECT_EQ(ReadFile(model + ".bak.1"), original);
  const std::string now = ReadFile(model);
  EXPECT_EQ(now.substr(0, now.find("<!--")), original.substr(0, original.find("<inertial>")));
  EXPECT_EQ(now.substr(now.find("</inertial>")), original.substr(original.find("</inertial>")));
  EXPECT_NE(now.find("\n      <inertia ixx=\"2\" ixy=\"0.08\" ixz=\"0.12\" iyy=\"3\" iyz=\"0.06\" "
                     "izz=\"4.5\"/>\n"),
            std::string::npos)
      << now;
}

}  // namespace
}  // namespace bifilar
