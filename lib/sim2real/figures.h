#pragma once
// PNG figures of the report (through render/, which needs an X display): the command x terrain
// deficit heat map, before/after density maps of p(dx, dy | c, z) for the worst regions with the
// real samples overlaid, and the held-out log-likelihood bars. Degrades to no figures and a note.
#include <filesystem>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/pipeline.h"
#include "sim2real/report.h"

namespace dgmm::sim2real {

// Writes the PNGs into `dir`; returns them with captions. When figures cannot be drawn (no
// display, render not built) returns none and sets *note to one line saying why.
std::vector<ReportFigure> RenderFigures(const Sim2RealResult& result, const SampleSet& sim,
                                        const SampleSet& real, const std::filesystem::path& dir,
                                        std::string* note);

}  // namespace dgmm::sim2real
