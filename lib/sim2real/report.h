#pragma once
// Stage 9 of the analysis (analysis.h): the one story in three forms that say the same thing.
// report.json (every figure of the analysis, one schema: docs/sim2real.md "report.json"), a
// self-contained report.html (a section per stage: the verdict, where, what physics, how sure,
// the fit, details; PNG figures embedded as base64) and the summary printed on stdout.
#include <filesystem>
#include <string>
#include <vector>

#include "sim2real/analysis.h"

namespace dgmm::sim2real {

struct ReportFigure {
  std::string file;     // PNG file name inside the output folder
  std::string caption;
};

struct ReportContext {
  std::string sim_path, real_path;
  std::vector<ReportFigure> figures;
  std::vector<std::string> notes;          // e.g. "figures skipped: no X display"
  std::string corrected_model_file, sim_model_file;
  std::string recalibrated_config_file;    // empty: none written
  std::string simulator_config_source;     // where the simulator's config came from, in words
  std::string simulator_fingerprint;
};

// report.json content (pretty-printed JSON).
std::string ReportJson(const Analysis& a, const ReportContext& context);
// report.html content; PNGs are read from `dir` and embedded.
std::string ReportHtml(const Analysis& a, const ReportContext& context, const std::filesystem::path& dir);
// The stdout summary: the verdict sentence, where the mismatch is, the fit, the files.
std::string ReportSummary(const Analysis& a, const ReportContext& context, const std::string& report_path);

}  // namespace dgmm::sim2real
