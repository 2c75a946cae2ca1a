#pragma once
// IESNA LM-63 photometric files: the candela distribution of a luminaire, used as the emission
// profile of a spot light ("profile": {"ies": file} in scene.json, docs/scene-format.md).
//
// Reads LM-63-1986 (no header line), LM-63-1991 ("IESNA91"), LM-63-1995, LM-63-2002 and LM-63-2019
// ("IES:LM-63-2019"). Keyword lines ([KEY] value, [MORE] continues the previous keyword),
// TILT=NONE, TILT=INCLUDE (the tilt block follows) and TILT=<file> (read relative to the IES file)
// are understood; CRLF line ends, ISO-8859-1 bytes in keyword text (converted to UTF-8) and numbers
// split across lines anywhere (the numeric block is whitespace/comma separated) are accepted. Every
// bad input throws igi::InputError with one line "FILE: line N: FIELD: VALUE: RULE".
//
// Angles are in degrees, intensities in candela (cd), fluxes in lumens (lm). Type C
// (photometric_type 1, the usual one for interior and spot luminaires): the vertical angle is
// measured from nadir (0 = straight down the luminaire's axis, 180 = straight up), the horizontal
// angle counter-clockwise about that axis (0 = the luminaire's reference plane). Types A and B (3,
// 2; automotive, floodlights) are parsed and stored, and Candela() interpolates in their own
// (vertical, horizontal) grid with their symmetries, but the fluxes (TotalLumens,
// InterpolatedLumens) throw InputError for them: their frames are not implemented.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace igi::recon {

// Photometric types of LM-63 (field 6 of the first numeric line).
inline constexpr int kIesTypeC = 1;
inline constexpr int kIesTypeB = 2;
inline constexpr int kIesTypeA = 3;

// The TILT block: multiplying factors for lamp tilt angles (only meaningful for lamps whose output
// depends on burning position). Candela() ignores it: the stored candela values are for the
// luminaire as tested.
struct IesTilt {
  std::string mode = "NONE";           // "NONE", "INCLUDE" or the file name after TILT=
  int lamp_to_luminaire_geometry = 0;  // 1, 2 or 3 when present
  std::vector<double> angles_deg;
  std::vector<double> factors;
};

struct IesProfile {
  std::string file;      // the path it was read from
  std::string standard;  // "IESNA:LM-63-2002", "IESNA91", "LM-63-1986" (no header), ...
  // [TEST], [MANUFAC], ...: values trimmed, UTF-8; [MORE] lines and repeated keys are appended
  // after a newline. LM-63-1986 free-text label lines are kept under "LABEL".
  std::map<std::string, std::string> keywords;
  IesTilt tilt;

  int lamp_count = 1;
  double lumens_per_lamp = -1;       // -1 = absolute photometry
  double declared_lamp_lumens = -1;  // lamp_count * lumens_per_lamp, or -1 (absolute photometry)
  double candela_multiplier = 1;     // already applied to `candela`
  double ballast_factor = 1;         // already applied to `candela`
  // LM-63-1986..1995: ballast-lamp photometric factor (already applied to `candela`); LM-63-2002:
  // "future use" (applied; it is 1 in conforming files); LM-63-2019: file generation type (NOT
  // applied: it is a code such as 1.10000).
  double ballast_lamp_factor = 1;
  double input_watts = 0;
  int photometric_type = kIesTypeC;          // 1 = C, 2 = B, 3 = A
  int units_type = 1;                        // 1 = feet, 2 = meters (for the luminous opening)
  double width = 0, length = 0, height = 0;  // luminous opening, in units_type

  std::vector<double> vertical_deg;    // strictly increasing, as in the file
  std::vector<double> horizontal_deg;  // strictly increasing, as in the file
  // candela[h * vertical_deg.size() + v], all multipliers above already applied.
  std::vector<double> candela;

  // Intensity (cd) towards (vertical, horizontal), bilinear in the angles and using the symmetry
  // implied by the horizontal range. Type C: any angles are accepted (folded onto the sphere);
  // directions outside the vertical range emit 0. Types A/B: angles in the file's own frame,
  // mirrored when the file holds only the non-negative half; outside the range gives 0.
  double Candela(double vertical_deg, double horizontal_deg) const;
  double MaxCandela() const;
  // Luminous flux (lm) by the zonal-lumen method of photometric reports: each zone between
  // consecutive tabulated vertical angles carries the mean candela of its two edges (trapezoid in
  // azimuth, mirrored by symmetry) times its solid angle. Matches Photometric Toolbox. Throws
  // InputError for types A and B (not supported).
  double TotalLumens() const;
  // The exact integral over the sphere of the distribution that Candela() evaluates (it differs
  // from TotalLumens() by under 0.1 % on real files). Same type support.
  double InterpolatedLumens() const;
};

// Reads and validates an LM-63 file; throws igi::InputError naming the file, line, field, value and
// rule on any problem (and "PATH: cannot read" when the file cannot be opened).
IesProfile ReadIesProfile(const std::filesystem::path& path);

// The same, from text already in memory (`file` names it in errors; a TILT=<file> is read relative
// to file's folder).
IesProfile ParseIesProfile(const std::string& text, const std::filesystem::path& file);

}  // namespace igi::recon
