#pragma once
// Motion models as HDF5 files and as JSON (schema: docs/file-format.md).
#include <nlohmann/json.hpp>
#include <string>

#include "core/motion_model.h"

namespace dgmm {

// Atomic write; throws InputError naming the path on failure.
void WriteModel(const MotionModel& model, const std::string& path);
// Throws InputError for missing, truncated, foreign or inconsistent files.
MotionModel ReadModel(const std::string& path);
// The DGMM options as the JSON object of `dgmm export` and `dgmm info --json` (names as in the
// model file's /dgmm_options).
nlohmann::json DgmmOptionsJson(const DgmmOptions& options);
// JSON export for use outside C++ (atomic write).
void WriteModelJson(const MotionModel& model, const std::string& path);

}  // namespace dgmm
