#pragma once
// The sim2real report: report.json (every figure of the analysis) and a self-contained
// report.html (the story in plain words, the tables, a command x terrain heat map as a coloured
// table, and the PNG figures embedded as base64).
#include <filesystem>
#include <string>
#include <vector>

#include "sim2real/pipeline.h"

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
  std::string recalibration_json;          // JSON object text or empty (--sim-config)
  // The verdict object (verdict.h; always set by the app) and, with --sim-config, the knob
  // analysis details (knob_analysis.h); JSON object texts or empty.
  std::string verdict_json, knob_analysis_json;
  std::string verdict_sentence;            // shown under the conclusion
};

// report.json content (pretty-printed JSON).
std::string ReportJson(const Sim2RealResult& result, const ReportContext& context);
// report.html content; PNGs are read from `dir` and embedded.
std::string ReportHtml(const Sim2RealResult& result, const ReportContext& context,
                       const std::filesystem::path& dir);

}  // namespace dgmm::sim2real
