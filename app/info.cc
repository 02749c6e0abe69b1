// `dgmm info`: what a dgmm HDF5 file holds: a sample set (sizes, names, commands with sample
// counts, per-dimension ranges) or a model (dims, options, components per command).
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>

#include "app/command.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "io/sample_stream.h"

namespace dgmm::app {
namespace {

using nlohmann::json;

struct InfoArgs {
  std::string file;
  bool json = false;
};

json Vec(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

std::string Join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(unnamed)" : s;
}

// Per-dimension mean, sd, min and max over y = x || z, streamed.
json SetInfo(const std::string& path) {
  SampleSetReader reader(path);
  const SampleSet& h = reader.header();
  const int dx = h.pose_dim(), dz = h.terrain_dim(), d = dx + dz;
  std::vector<long long> counts(h.num_commands(), 0);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(d), sum2 = sum;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(d, INFINITY), hi = -lo;
  std::set<int> episodes;
  SampleSet chunk;
  long long done = 0;
  while (reader.Next(&chunk)) {
    for (int i = 0; i < chunk.size(); ++i) {
      ++counts[chunk.command[i]];
      const Eigen::VectorXd y = chunk.Joint(i);
      sum += y;
      sum2 += y.cwiseAbs2();
      lo = lo.cwiseMin(y);
      hi = hi.cwiseMax(y);
      if (chunk.has_sequence()) episodes.insert(chunk.episode[i]);
    }
    done += chunk.size();
    ReportProgress("info", done, reader.size());
  }
  const double n = static_cast<double>(reader.size());
  const Eigen::VectorXd mean = sum / n;
  const Eigen::VectorXd sd = (sum2 / n - mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  json commands = json::array();
  for (int c = 0; c < h.num_commands(); ++c) {
    commands.push_back(
        {{"command", c},
         {"label", c < static_cast<int>(h.command_labels.size()) ? h.command_labels[c] : ""},
         {"values", Vec(h.commands.row(c).transpose())},
         {"samples", counts[c]}});
  }
  json j = {{"file", path},
            {"kind", "sample_set"},
            {"source", h.source},
            {"samples", reader.size()},
            {"pose_dim", dx},
            {"pose_names", h.x_names},
            {"pose_units", h.x_units},
            {"terrain_dim", dz},
            {"terrain_names", h.z_names},
            {"command_dim_names", h.command_dim_names},
            {"commands", commands},
            {"episodes", h.has_sequence() || !episodes.empty() ? json(episodes.size()) : json()},
            {"mean", Vec(mean)},
            {"sd", Vec(sd)},
            {"min", Vec(lo)},
            {"max", Vec(hi)},
            {"standardized", !h.transform.empty()},
            {"metadata", h.metadata}};
  if (!h.transform.empty()) {
    j["transform"] = {{"offset", Vec(h.transform.offset)}, {"scale", Vec(h.transform.scale)}};
  }
  return j;
}

json ModelInfo(const std::string& path) {
  const MotionModel m = ReadModel(path);
  json commands = json::array();
  for (const auto& [id, mixture] : m.mixtures) {
    auto label = m.command_labels.find(id);
    commands.push_back({{"command", id},
                        {"label", label == m.command_labels.end() ? "" : label->second},
                        {"components", mixture.size()},
                        {"total_weight", mixture.empty() ? 0.0 : mixture.total_weight()}});
  }
  const DgmmOptions& o = m.dgmm_options;
  return {{"file", path},
          {"kind", "model"},
          {"model_kind", m.kind},
          {"pose_dim", m.pose_dim},
          {"terrain_dim", m.terrain_dim},
          {"pose_names", m.pose_names},
          {"terrain_names", m.terrain_names},
          {"seed", m.seed},
          {"k", o.k},
          {"variant", VariantName(o.variant)},
          {"covariance_floor", o.covariance_floor},
          {"initial_covariance_diagonal", Vec(o.initial_covariance_diagonal)},
          {"dgmm_options", DgmmOptionsJson(o)},
          {"commands", commands},
          {"table_commands", m.command_values.size()},
          {"standardized", !m.transform.empty()},
          {"metadata", m.metadata}};
}

void PrintSet(const json& j) {
  std::printf("%s: sample set from '%s', %lld samples\n", j["file"].get<std::string>().c_str(),
              j["source"].get<std::string>().c_str(), j["samples"].get<long long>());
  std::printf("  x: %d dims (%s)\n", j["pose_dim"].get<int>(), Join(j["pose_names"]).c_str());
  if (j["terrain_dim"].get<int>() > 0) {
    std::printf("  z: %d dims (%s)\n", j["terrain_dim"].get<int>(),
                Join(j["terrain_names"]).c_str());
  } else {
    std::printf("  z: none\n");
  }
  const auto& mean = j["mean"];
  // Column names of y = x || z ("x0", "z1", ... where the file has none).
  std::vector<std::string> names;
  for (const char* part : {"pose", "terrain"}) {
    const int dims = j[std::string(part) + "_dim"];
    const auto& given = j[std::string(part) + "_names"];
    for (int i = 0; i < dims; ++i) {
      names.push_back(static_cast<int>(given.size()) == dims
                          ? given[i].get<std::string>()
                          : (part[0] == 'p' ? "x" : "z") + std::to_string(i));
    }
  }
  for (size_t i = 0; i < mean.size(); ++i) {
    const std::string& name = names[i];
    std::printf("    %s: mean %.6g, sd %.6g, range [%.6g, %.6g]\n", name.c_str(),
                mean[i].get<double>(), j["sd"][i].get<double>(), j["min"][i].get<double>(),
                j["max"][i].get<double>());
  }
  std::printf("  commands: %zu (dims: %s)\n", j["commands"].size(),
              Join(j["command_dim_names"]).c_str());
  for (const auto& c : j["commands"]) {
    std::printf("    %d '%s': %lld samples\n", c["command"].get<int>(),
                c["label"].get<std::string>().c_str(), c["samples"].get<long long>());
  }
  if (!j["episodes"].is_null()) std::printf("  episodes: %zu\n", j["episodes"].get<size_t>());
  std::printf("  standardised: %s\n", j["standardized"].get<bool>() ? "yes" : "no");
  for (const auto& [k, v] : j["metadata"].items()) {
    std::printf("  metadata %s = %s\n", k.c_str(), v.get<std::string>().c_str());
  }
}

void PrintModel(const json& j) {
  std::printf("%s: %s model, %d pose + %d terrain dims (%s)\n",
              j["file"].get<std::string>().c_str(), j["model_kind"].get<std::string>().c_str(),
              j["pose_dim"].get<int>(), j["terrain_dim"].get<int>(), Join(j["pose_names"]).c_str());
  const json& o = j["dgmm_options"];
  std::printf("  k %g, %s, covariance %s (nu0 %g), S0 %s, floor %g, seed %llu\n",
              j["k"].get<double>(), j["variant"].get<std::string>().c_str(),
              o["covariance_rule"].get<std::string>().c_str(),
              o["prior_pseudo_count"].get<double>(),
              o["initial_covariance_rule"].get<std::string>().c_str(),
              j["covariance_floor"].get<double>(), j["seed"].get<unsigned long long>());
  for (const auto& c : j["commands"]) {
    std::printf("    command %d '%s': %s, total weight %g\n", c["command"].get<int>(),
                c["label"].get<std::string>().c_str(),
                Plural(c["components"].get<int>(), "component").c_str(),
                c["total_weight"].get<double>());
  }
  std::printf("  standardised: %s\n", j["standardized"].get<bool>() ? "yes" : "no");
  for (const auto& [k, v] : j["metadata"].items()) {
    std::printf("  metadata %s = %s\n", k.c_str(), v.get<std::string>().c_str());
  }
}

void Run(const InfoArgs& args) {
  const bool is_set = DgmmFileKind(args.file) == "sample_set";
  const json j = is_set ? SetInfo(args.file) : ModelInfo(args.file);
  if (args.json) {
    std::cout << j.dump(2) << "\n";
  } else if (is_set) {
    PrintSet(j);
  } else {
    PrintModel(j);
  }
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = root.add_subcommand(
      "info",
      "Describe a dgmm HDF5 file: a sample set (sizes, names, commands with sample "
      "counts, per-dimension statistics) or a model (dims, options, components per "
      "command).");
  cmd->add_option("file", args->file, "sample set or model (.h5)")->required();
  cmd->add_flag("--json", args->json, "print the description as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("info", Setup);
}  // namespace dgmm::app
