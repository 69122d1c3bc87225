// report.html: one self-contained page for a processed campaign, built from results.json alone
// (read through ResultsReader, pipeline/records/results_reader.h) plus the figure files in
// OUT/figures/ (embedded; an SVG compacted once is stored compacted in its place), so the page
// needs no other file. It shows the sections of its kind of campaign: planar pitch (the paper's
// Table 1 and Table 2 in the chosen units, moments against pitch with the fitted curve (Fig. 3),
// the polar ellipse (Fig. 4), the NACA-467 comparison), or a full or partial tensor / three
// separate axes (the tensor, its ellipsoid figure when full, per-orientation residuals); then
// per-attitude statistics, every trace with its fit-and-residual figure, the rejected traces with
// reasons, the warnings, and the config used. Conventions: docs/physics.md §3, §4.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/records/results_reader.h"

namespace bifilar {

// The page for the results document `results` (ResultsToJson), read through ResultsReader;
// figures are read from `out_dir`/figures/. A missing figure is shown as a note, never an error.
std::string BuildReportHtml(const nlohmann::json& results, const std::string& out_dir);

// Every results.json key that BuildReportHtml reads for `results` (for the test that each is one
// the writer writes).
KeyLog ReportKeysRead(const nlohmann::json& results, const std::string& out_dir);

// `bifilar report DIR`: rebuilds DIR/report.html from DIR/results.json (written atomically).
// Throws UserError when DIR or its results.json is missing or unreadable.
void RunReport(const std::string& out_dir);

// RFC 4648 base64 of `bytes`.
std::string Base64(const std::string& bytes);

}  // namespace bifilar
