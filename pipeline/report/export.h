// `bifilar export`: the inertia of a results.json in a form a simulator loads. URDF and SDF
// <inertial>, a JSBSim <mass_balance>, a MuJoCo (MJCF) <body> with <inertial fullinertia>, an
// ArduPilot SITL frame JSON (mass and the diagonal only) and a flat CSV; or, with --into, the
// inertial block of one link/body of an existing URDF, SDF or MJCF model rewritten in place.
//
// What results.json holds (docs/physics.md §3): body axes x forward, y right wing, z down (FRD),
// origin at the CG; products positive, I_xy = integral x y dm (likewise I_xz, I_yz), so the
// tensor is J = [[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]]. Each format has its own
// frame and sign, taken from its own documentation:
//
//  format   frame                                  written ixx iyy izz | ixy    ixz    iyz
//  urdf     FLU (x fwd, y left, z up; ROS REP 103)    Ixx Iyy Izz       | +Ixy   +Ixz   -Iyz
//  sdf      FLU, as urdf (SDFormat <inertia>)         Ixx Iyy Izz       | +Ixy   +Ixz   -Iyz
//  urdf/sdf with --frame frd (body axes as measured)  Ixx Iyy Izz       | -Ixy   -Ixz   -Iyz
//  jsbsim   structural (x aft, y right, z up), with   Ixx Iyy Izz       | +Ixy   -Ixz   +Iyz
//           negated_crossproduct_inertia="true"
//  mjcf     FLU as urdf (--frame frd: as urdf frd)    fullinertia="Ixx Iyy Izz  +Ixy +Ixz -Iyz"
//  ardupilot body FRD (SIM_Frame.cpp moment_inertia)  [Ixx, Iyy, Izz]   | dropped: a warning
//  csv      body FRD, results.json's own convention   Ixx Iyy Izz       | Ixy    Ixz    Iyz
//
// - URDF <inertia ixx ixy ixz iyy iyz izz> and SDFormat <inertia><ixx>... are the elements of the
//   3x3 rotational inertia matrix above its diagonal ("the product of inertia convention -m x y
//   (not +m x y) is used", SDFormat spec), about the CG, in the link frame, which ROS REP 103 and
//   Gazebo take as FLU. FRD -> FLU is a half turn about x, (x, y, z) -> (x, -y, -z): the products
//   with one of y, z flip (I_xy, I_xz) and I_yz does not; then the element is minus the product.
// - JSBSim (FGMassBalance) reads the tensor in its structural frame, x aft, y right, z up (a half
//   turn about y from its FRD body frame). With negated_crossproduct_inertia="true" (its default,
//   and what every version reads) <ixy> etc. are the matrix elements, -integral x y dm in that
//   frame: ixy = +I_xy, ixz = -I_xz, iyz = +I_yz of the body products. The attribute is written
//   explicitly so the file reads the same in versions before and after it existed.
// - MuJoCo <inertial fullinertia="ixx iyy izz ixy ixz iyz">: the full inertia matrix of the
//   body's inertial frame, order M(1,1) M(2,2) M(3,3) M(1,2) M(1,3) M(2,3) (MJCF reference), so
//   the off-diagonals are the same elements as URDF's; MuJoCo diagonalizes it at compile time
//   (body_inertia, body_iquat) and refuses one that breaks the triangle inequality.
// - ArduPilot SITL (libraries/SITL/SIM_Frame.cpp, Frame::load_frame_params): reads "mass" and
//   "moment_inertia" ([x, y, z], body FRD, kg m^2) and ignores every other key; a zero component
//   makes it estimate all three from mass and diagonal_size. It holds no products: export names
//   the products it drops and their size against the diagonal.
// - Mass: results.json `aircraft.mass_kg` (older files: the stored config; or --mass-kg); CG:
//   aircraft.cg_m of the stored config (body FRD, from the model origin) in each file's frame,
//   else the origin of the link (URDF/SDF/MJCF) or of the structural frame (JSBSim). The bifilar
//   measures neither the mass nor the CG: the files say so.
#pragma once

#include <array>
#include <limits>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "pipeline/config/config.h"
#include "pipeline/records/results_reader.h"

namespace bifilar {

enum class ExportFormat { kUrdf, kSdf, kJsbsim, kCsv, kMjcf, kArdupilot };
bool ParseExportFormat(const std::string& name, ExportFormat* format);  // false: no such name
const char* ExportFormatName(ExportFormat format);
std::string ExportFormatAllowedValues();  // "urdf, sdf, jsbsim, csv, mjcf or ardupilot"

// The frame of a URDF/SDF <inertial>: FLU (REP 103, the default) or the body FRD as measured.
enum class ExportFrame { kFlu, kFrd };
bool ParseExportFrame(const std::string& name, ExportFrame* frame);  // false: no such name
std::string ExportFrameAllowedValues();                              // "flu or frd"

struct ExportOptions {
  std::string results_path;  // results.json written by `bifilar process`
  ExportFormat format = ExportFormat::kCsv;
  std::string out_path;                   // write here (atomically); empty: to the output stream
  ExportFrame frame = ExportFrame::kFlu;  // urdf, sdf and mjcf only
  bool frame_given = false;  // --frame was given (an error for jsbsim, ardupilot and csv)
  // --into MODEL --link NAME: rewrite the inertial block of link/body NAME of the URDF, SDF or
  // MJCF file MODEL in place (the format is the file's: --format must match it or be absent).
  std::string into_path;
  std::string link_name;
  // The date written in the provenance (UTC, ISO 8601); "": the current date.
  std::string date_utc;
  // Mass (kg) to write instead of the config's aircraft.mass_kg; NaN: use the config. > 0.
  double mass_kg = std::numeric_limits<double>::quiet_NaN();
  // Values (kg m^2, body FRD, products positive) for components the result does not hold, by
  // name ("Iyy", "Ixy", ...). A component the result measured cannot be set.
  std::map<std::string, double> set_kg_m2;
  // Take Ixy = Iyz = 0 when the result does not hold them: an aircraft symmetric about its x-z
  // plane (the paper's assumption for a pitch-only campaign).
  bool symmetric = false;
  // --force: replace an --out file that `bifilar export` did not write, rewrite an --into
  // link whose inertial export did not write, and write any simulator format of a tensor that
  // is not physical (the warning stays). Never lets --out be the input or a file of the
  // campaign's output folder.
  bool force = false;

  bool Check(std::string* why) const;
};

// The largest moment or product accepted (kg m^2): 1e8 is twice an A380's yaw inertia; a value
// beyond it is a corrupt or mis-scaled result, not an aircraft.
constexpr double kMaxExportInertiaKgM2 = 1e8;

// The inertia to export: six components (kg m^2, body FRD, products positive, order Ixx, Iyy,
// Izz, Ixy, Ixz, Iyz), each with its std and where it came from.
struct ExportInertia {
  std::array<double, 6> value_kg_m2 = {};  // NaN when missing
  std::array<double, 6> std_kg_m2 = {};    // NaN when unknown
  // "measured", "set" (--set), "symmetric" (--symmetric) or "missing".
  std::array<std::string, 6> source;
  std::string section;  // "tensor" or "ellipse": the results.json section read
  double mass_kg = std::numeric_limits<double>::quiet_NaN();
  double mass_std_kg = std::numeric_limits<double>::quiet_NaN();
  std::string mass_source;  // "config aircraft.mass_kg", "--mass-kg" or "" (none)
  // Why the stored config gave no usable mass ("" when it gave one or has none): e.g.
  // "aircraft.mass_kg = -5 in the stored config is not a positive mass".
  std::string mass_problem;
  // The first condition of a physical inertia that the components fail ("" when they pass or
  // none is there): finite, |value| <= kMaxExportInertiaKgM2, moments > 0, and when all six are
  // there positive definite and the triangle inequality of the principal moments (largest <=
  // sum of the others); of a partial result, the moments and products it holds (Ixx, Izz, Ixz
  // of a pitch campaign: the 2x2 block positive definite). Also in `warnings`.
  std::string nonphysical;
  std::string results_name;  // the file, for comments
  // The total std of each component: the stat std and the campaign's common-mode scale
  // (results.json total_uncertainty.common_mode_relative_std) in quadrature; NaN when unknown.
  std::array<double, 6> total_std_kg_m2 = {};
  // results.json tensor.covariance_kg2_m4 (order as value_kg_m2; NaN where null or absent).
  std::array<std::array<double, 6>, 6> covariance_kg2_m4 = {};
  // Provenance: the bifilar version that wrote results.json, its config_file (the campaign),
  // the bifilar version that exports, and the export date (UTC).
  std::string results_version, campaign, export_version, date_utc;
  AircraftCg cg;  // aircraft.cg_m / cg_std_m of the stored config (pipeline/config/config.h)
  std::vector<std::string> warnings;

  std::vector<std::string> Missing() const;  // names of the missing components
};

// Reads the inertia from results.json text (`name` prefixes every message) and fills missing
// components from the options. Throws UserError naming the file on: text that is not JSON, a
// document bifilar did not write, no `tensor` or `ellipse` section with a number, a --set of a
// measured or unknown component.
// Reads through ResultsReader (pipeline/records/results_reader.h); `keys_read`, when given,
// receives every key read (the test that each is one the writer writes).
ExportInertia ReadExportInertia(const std::string& text, const std::string& name,
                                const ExportOptions& options, KeyLog* keys_read = nullptr);

// The text of each format (see the table above). URDF, SDF and JSBSim throw UserError when a
// component or the mass is missing, naming them and how to supply them; the CSV leaves them empty.
std::string FormatUrdfInertial(const ExportInertia& inertia, ExportFrame frame);
std::string FormatSdfInertial(const ExportInertia& inertia, ExportFrame frame);
std::string FormatJsbsimMassBalance(const ExportInertia& inertia);
std::string FormatInertiaCsv(const ExportInertia& inertia);
std::string FormatMjcfBody(const ExportInertia& inertia, ExportFrame frame,
                           const std::string& body_name = "aircraft");
// ArduPilot needs the three moments and the mass only; the products are dropped (see
// DroppedProducts).
std::string FormatArdupilotFrame(const ExportInertia& inertia);
// The text of `format` (the functions above).
std::string FormatExport(const ExportInertia& inertia, ExportFormat format, ExportFrame frame);

// Whether `format` holds the products of inertia (ardupilot does not).
bool ExportFormatHoldsProducts(ExportFormat format);
// The warning for a format that cannot hold products: which products it drops and how large
// each is against its two moments (|I_ab| / sqrt(I_aa I_bb), the bound of a physical tensor);
// "" when the format holds them.
std::string DroppedProducts(const ExportInertia& inertia, ExportFormat format);

// THE refusal of a tensor that is not physical, the one every format and --into goes through:
// "" when `inertia` may be written in `format` (it is physical, or `force`, or the format is the
// CSV, which is not a simulator's and carries the warning); else the one message, naming the
// file, the failed condition (ExportInertia::nonphysical) and the format. The check behind it is
// ExportInertia::nonphysical (triangle inequality and positive definiteness of the tensor):
// swap the check there, the refusal follows.
std::string NonPhysicalRefusal(const ExportInertia& inertia, ExportFormat format, bool force);

// --into: the text of `model` (a URDF, SDF or MJCF document, `model_name` in messages) with the
// inertial block of link/body `link` replaced by the inertia in the model's format, every other
// byte unchanged. The block replaced is the <inertial> element that is a direct child of the
// link (with export's comment just before it, when there); a link without one gets it as its
// first child. Without a CG, the block keeps the model's inertial position (its rotation, which
// the tensor in link axes cannot have, is dropped with a warning into `warnings`). Throws
// UserError naming the model when the document is not URDF, SDF or MJCF, the link is not there
// or is there twice, or its inertial was not written by export and `force` is false.
std::string RewriteModelInertial(const std::string& model, const std::string& model_name,
                                 const std::string& link, const ExportInertia& inertia,
                                 ExportFrame frame, bool force, std::vector<std::string>* warnings);
// The format of a model's text: its root element (robot: urdf, sdf: sdf, mujoco: mjcf); false
// for any other.
bool DetectModelFormat(const std::string& model, ExportFormat* format);

// Reads options.results_path, formats, writes options.out_path atomically (or the text to `out`),
// and prints warnings and the CG/mass note to `err`. With options.into_path: rewrites that model
// (RewriteModelInertial) after copying it to MODEL.bak (MODEL.bak.1, .2, ... when that exists:
// no backup is ever replaced), and writes it atomically. Returns 0, or 1 (nothing written, the
// failed condition printed) for a URDF, SDF or JSBSim file of a non-physical tensor without
// options.force. Throws UserError, before writing, when --out resolves (links, "..", hard links)
// to the input results.json or to a file of the input's output folder (a result file, the
// manifest or lock, cache/, figures/, or a name its manifest lists), or exists and was not
// written by `bifilar export` (its first line is not export's) and options.force is false.
int RunExport(const ExportOptions& options, std::ostream& out, std::ostream& err);

}  // namespace bifilar
