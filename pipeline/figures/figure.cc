#include "pipeline/figures/figure.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>

#include <plplot.h>

#include "base/atomic_file.h"
#include "base/user_error.h"
#include "pipeline/figures/svg_compact.h"

namespace bifilar {
namespace {

// kFigureBand's red, green and blue (kFigureTranslucentBand's too).
constexpr PLINT kBandRgb[3] = {120, 160, 220};

std::mutex& PlplotMutex() {
  static std::mutex mutex;
  return mutex;
}

// The SVG at `path` rewritten in place by CompactSvg; false when it cannot be read or written.
bool CompactSvgFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream text;
  text << in.rdbuf();
  in.close();
  const std::string compact = CompactSvg(text.str());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << compact;
  return static_cast<bool>(out);
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

bool WriteFigure(const std::string& path, const FigureOptions& options,
                 const std::function<void()>& draw, std::string* why) {
  const char* device = nullptr;
  if (EndsWith(path, ".png")) device = "pngcairo";
  // PLplot's own SVG driver keeps text as text (svgcairo draws every glyph as an outline: 2.8 MB
  // for a fit figure, and nothing to search); CompactSvg then applies its flip and joins its
  // polylines.
  const bool svg = EndsWith(path, ".svg");
  if (svg) device = "svg";
  if (device == nullptr) {
    *why = path + ": figure file name must end in .png or .svg";
    return false;
  }
  if (options.width_px <= 0 || options.height_px <= 0) {
    *why = "figure size must be positive";
    return false;
  }
  // Never replace a link, folder or device (base/atomic_file.h): the rename below would.
  try {
    CheckFileTarget(path);
  } catch (const UserError& e) {
    *why = e.what();
    return false;
  }
  const std::string temporary = path + ".tmp";
  // PLplot opens the name as given: a stale temporary, or a link planted under its name, is
  // removed first so the figure never writes through a link to a file elsewhere. The temporary
  // is then created here, exclusively and without following a link: PLplot, unable to open a
  // file (a missing or read-only folder), asks for another name ten times and exits the process.
  ::unlink(temporary.c_str());
  const int probe =
      ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (probe < 0) {
    *why = path + ": cannot write the figure (" + std::strerror(errno) + ")";
    return false;
  }
  ::close(probe);
  {
    std::lock_guard<std::mutex> lock(PlplotMutex());
    PLINT stream = 0;
    plmkstrm(&stream);
    plsdev(device);
    plsfnam(temporary.c_str());
    plspage(0, 0, options.width_px, options.height_px, 0, 0);
    plscolbg(255, 255, 255);  // white background, dark foreground
    plscol0(1, 0, 0, 0);
    plinit();
    plfontld(1);
    plscol0(kFigureBlue, 31, 90, 180);
    plscol0(kFigureRed, 200, 30, 30);
    plscol0(kFigureGrey, 135, 135, 135);
    plscol0(kFigureGreen, 20, 140, 60);
    plscol0(kFigureLight, 220, 220, 220);
    plscol0(kFigureBand, kBandRgb[0], kBandRgb[1], kBandRgb[2]);
    draw();
    plend1();
  }
  if (svg && !CompactSvgFile(temporary)) {
    std::remove(temporary.c_str());
    *why = path + ": could not write figure";
    return false;
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    *why = path + ": could not write figure";
    return false;
  }
  return true;
}

// "(U)^-1/2" of a display unit "A B#u2#d" (PLplot text) as "A#u-1/2#d B#u-1#d"; other labels as
// "1/#(2267)(U)".
std::string InverseSqrtUnit(const std::string& unit) {
  const std::string squared = "#u2#d";
  const size_t space = unit.find(' ');
  if (space != std::string::npos && unit.size() > squared.size() &&
      unit.compare(unit.size() - squared.size(), squared.size(), squared) == 0) {
    return "(" + unit.substr(0, space) + "#u-1/2#d " +
           unit.substr(space + 1, unit.size() - squared.size() - space - 1) + "#u-1#d)";
  }
  return "1/#(2267)(" + unit + ")";
}

const char* InertiaUnitPlotLabel(DisplayUnits units) {
  return units == DisplayUnits::kImperial ? "slug ft#u2#d" : "kg m#u2#d";
}

void SetTranslucentBand(double opacity) {
  plscol0a(kFigureTranslucentBand, kBandRgb[0], kBandRgb[1], kBandRgb[2], opacity);
}

// The power of ten to draw radii up to `r_max` in: 0 within [0.1, 1000), else its exponent.
int PowerOfTenFor(double r_max) {
  if (!(r_max > 0) || !std::isfinite(r_max) || (r_max >= 0.1 && r_max < 1000.0)) return 0;
  return static_cast<int>(std::floor(std::log10(r_max)));
}

// "(slug ft^2)" drawn in units of 10^power: "(10^power slug ft^2)".
std::string ScaledUnit(const std::string& unit, int power) {
  if (power == 0) return unit;
  const std::string ten = "10#u" + std::to_string(power) + "#d ";
  if (unit.size() >= 2 && unit.front() == '(' && unit.back() == ')') {
    return "(" + ten + unit.substr(1);
  }
  return "(" + ten + unit + ")";
}

double TickStep(double lo, double hi, int max_ticks) {
  const double range = std::fabs(hi - lo);
  if (!(range > 0) || !std::isfinite(range)) return 1.0;
  const double raw = range / std::max(1, max_ticks);
  const double ten = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * ten >= raw * (1.0 - 1e-9)) return m * ten;
  }
  return 10.0 * ten;
}

int TickDecimals(double step) {
  if (!(step > 0) || !std::isfinite(step)) return 0;
  // The decimals of the step's first significant digit (2.5e-3 as 1, 2 or 5 x 10^n: 3).
  const int d = -static_cast<int>(std::floor(std::log10(step) + 1e-9));
  return std::clamp(d, 0, 15);
}

std::string TickLabel(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  std::string text = buffer;
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

namespace {

// plslabelfunc's callback: the decimals of the x and y axes in `data` (int[2]).
void TickLabelCallback(PLINT axis, PLFLT value, char* label, PLINT length, PLPointer data) {
  const int* decimals = static_cast<const int*>(data);
  const std::string text = TickLabel(value, decimals[axis == PL_Y_AXIS ? 1 : 0]);
  std::snprintf(label, static_cast<size_t>(std::max<PLINT>(length, 1)), "%s", text.c_str());
}

}  // namespace

void LabelledBox(const char* x_opt, const char* y_opt, double x_step, double y_step) {
  PLFLT x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  plgvpw(&x0, &x1, &y0, &y1);
  if (!(x_step > 0)) x_step = TickStep(x0, x1);
  if (!(y_step > 0)) y_step = TickStep(y0, y1, 6);
  int decimals[2] = {TickDecimals(x_step), TickDecimals(y_step)};
  plslabelfunc(TickLabelCallback, decimals);
  const std::string x = std::string(x_opt) + "o", y = std::string(y_opt) + "o";
  plbox(x.c_str(), x_step, 0, y.c_str(), y_step, 0);
  plslabelfunc(nullptr, nullptr);
}

}  // namespace bifilar
