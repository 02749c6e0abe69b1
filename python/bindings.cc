// dgmm._dgmm: the library's sample sets, motion models (DGMM and EM), mixtures and prediction for
// Python (pybind11). NumPy arrays in and out: a set's x and z are views of its own arrays (no
// copy); everything else is returned as new arrays. Bad input raises ValueError with the library's
// one-line message. The scikit-learn style estimators live in python/dgmm/__init__.py.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <random>

#include "core/dgmm_options.h"
#include "core/motion_model.h"
#include "core/sample_set.h"
#include "em/em_model.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "predict/ground_terrain.h"
#include "predict/predict.h"
#include "predict/region_calibration.h"
#include "util/error.h"

namespace py = pybind11;

namespace dgmm {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A set from arrays: x (n x dx), command ids (n) into a table of `labels` (default: the distinct
// ids), optional z (n x dz).
SampleSet MakeSet(const Eigen::MatrixXd& x, const Eigen::VectorXi& command, const std::optional<Eigen::MatrixXd>& z,
                  std::vector<std::string> labels, std::vector<std::string> x_names, std::vector<std::string> z_names) {
  SampleSet set;
  set.x = x;
  set.command = command;
  set.z = z ? *z : Eigen::MatrixXd(x.rows(), 0);
  const int commands = command.size() > 0 ? command.maxCoeff() + 1 : 0;
  if (labels.empty()) {
    for (int c = 0; c < commands; ++c) labels.push_back(std::to_string(c));
  }
  set.command_labels = labels;
  set.commands = Eigen::MatrixXd(static_cast<int>(labels.size()), 0);
  for (int d = static_cast<int>(x_names.size()); d < x.cols(); ++d) x_names.push_back("x" + std::to_string(d));
  for (int d = static_cast<int>(z_names.size()); d < set.z.cols(); ++d) z_names.push_back("z" + std::to_string(d));
  set.x_names = x_names;
  set.z_names = z_names;
  set.x_units.assign(x.cols(), "");
  set.z_units.assign(set.z.cols(), "");
  set.source = "python";
  if (std::string e = set.Validate(); !e.empty()) throw InputError("sample set: " + e);
  return set;
}

// p(x | c) or p(x | c, z) in the raw units of x and z (MotionModel::RawPoseDistribution).
Mixture PoseMixture(const MotionModel& model, int command, const std::optional<Eigen::VectorXd>& z) {
  return model.RawPoseDistribution(command, z ? *z : Eigen::VectorXd());
}

MotionModel FitDgmm(const SampleSet& set, double k, bool with_terrain, std::uint64_t seed, long long max_components,
                    const std::string& variant, const std::string& covariance, double init_scale) {
  MotionModelOptions o;
  o.seed = seed;
  o.with_terrain = with_terrain;
  o.dgmm.k = k;
  const auto v = ParseVariant(variant);
  if (!v) throw InputError("variant: '" + variant + "', expected faithful or improved");
  o.dgmm.variant = *v;
  const auto r = ParseCovarianceRule(covariance);
  if (!r) throw InputError("covariance: '" + covariance + "', expected literal, blend or prior");
  o.dgmm.covariance_rule = *r;
  o.dgmm.initial_covariance_fraction = init_scale;
  const int dim = set.pose_dim() + (with_terrain ? set.terrain_dim() : 0);
  o.dgmm.max_components = static_cast<int>(max_components > 0 ? max_components : DefaultMaxComponents(set.size(), dim));
  std::string error;
  if (!o.dgmm.IsValid(&error)) throw InputError("options: " + error);
  return LearnMotionModel(set, o);
}

py::dict MixtureDict(const Mixture& m) {
  const int k = m.size(), d = m.dim();
  Eigen::VectorXd weights(k);
  RowMatrix means(k, d);
  py::array_t<double> covariances({k, d, d});
  auto c = covariances.mutable_unchecked<3>();
  for (int i = 0; i < k; ++i) {
    weights[i] = m.weight(i) / m.total_weight();
    means.row(i) = m.component(i).mean().transpose();
    for (int r = 0; r < d; ++r) {
      for (int s = 0; s < d; ++s) c(i, r, s) = m.component(i).covariance()(r, s);
    }
  }
  py::dict out;
  out["weights"] = weights;
  out["means"] = means;
  out["covariances"] = covariances;
  return out;
}

void BindSampleSet(py::module_& m) {
  py::class_<SampleSet>(m, "SampleSet", "Samples of pose change x, terrain z and command (HDF5 on disk).")
      .def(py::init(&MakeSet), py::arg("x"), py::arg("command"), py::arg("z") = std::nullopt,
           py::arg("command_labels") = std::vector<std::string>{}, py::arg("x_names") = std::vector<std::string>{},
           py::arg("z_names") = std::vector<std::string>{})
      .def_static("read", &ReadSampleSet, py::arg("path"))
      .def("write", [](const SampleSet& s, const std::string& path) { WriteSampleSet(s, path); }, py::arg("path"))
      .def_property_readonly("x", [](const SampleSet& s) -> const Eigen::MatrixXd& { return s.x; },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("z", [](const SampleSet& s) -> const Eigen::MatrixXd& { return s.z; },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("command", [](const SampleSet& s) -> const Eigen::VectorXi& { return s.command; },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("episode", [](const SampleSet& s) -> const Eigen::VectorXi& { return s.episode; },
                             py::return_value_policy::reference_internal)
      .def_property_readonly("step", [](const SampleSet& s) -> const Eigen::VectorXi& { return s.step; },
                             py::return_value_policy::reference_internal)
      .def_readonly("command_labels", &SampleSet::command_labels)
      .def_readonly("x_names", &SampleSet::x_names)
      .def_readonly("z_names", &SampleSet::z_names)
      .def("__len__", &SampleSet::size);
}

void BindModel(py::module_& m) {
  py::class_<MotionModel>(m, "MotionModel", "p(x | c) and p(x | c, z), one mixture per command.")
      .def_static("read", &ReadModel, py::arg("path"))
      .def("write", [](const MotionModel& model, const std::string& path) { WriteModel(model, path); }, py::arg("path"))
      .def_readonly("kind", &MotionModel::kind)
      .def_readonly("pose_dim", &MotionModel::pose_dim)
      .def_readonly("terrain_dim", &MotionModel::terrain_dim)
      .def_readonly("command_labels", &MotionModel::command_labels)
      .def_property_readonly("commands",
                             [](const MotionModel& model) {
                               std::vector<int> ids;
                               for (const auto& [id, unused] : model.mixtures) ids.push_back(id);
                               return ids;
                             })
      .def("components", [](const MotionModel& model, int c) { return model.MixtureFor(c).size(); }, py::arg("command"))
      .def("samples_near",
           [](const MotionModel& model, int c, const Eigen::VectorXd& z) {
             double at_data = 0;
             const double near = model.SamplesNear(c, z, &at_data);
             return std::make_pair(near, at_data);
           },
           py::arg("command"), py::arg("z"),
           "(training samples near z, the same at the densest data): kernel-weighted counts under "
           "the model's marginal of z (continuous commands and terrain), raw units")
      .def("score_samples", &ScoreSamples, py::arg("set"), "log p(x_i | c_i [, z_i]) per sample, raw units of x")
      .def("score", [](const MotionModel& model, const SampleSet& set) { return ScoreSampleSet(model, set).mean_log_likelihood; },
           py::arg("set"), "mean log-likelihood per sample")
      .def("pose_mixture",
           [](const MotionModel& model, int c, const std::optional<Eigen::VectorXd>& z) {
             return MixtureDict(PoseMixture(model, c, z));
           },
           py::arg("command"), py::arg("z") = std::nullopt,
           "p(x | c[, z]) in raw units: dict of weights (K), means (K x d), covariances (K x d x d)")
      .def("log_density",
           [](const MotionModel& model, int c, const Eigen::MatrixXd& x, const std::optional<Eigen::VectorXd>& z) {
             const Eigen::MatrixXd xt = x.transpose();
             return Eigen::VectorXd(PoseMixture(model, c, z).LogDensity(xt));
           },
           py::arg("command"), py::arg("x"), py::arg("z") = std::nullopt, "log p(x | c[, z]) of each row of x")
      .def("sample",
           [](const MotionModel& model, int c, int n, const std::optional<Eigen::VectorXd>& z, std::uint64_t seed) {
             if (n < 0) throw InputError("n: expected >= 0");
             std::mt19937_64 rng(seed);
             return RowMatrix(PoseMixture(model, c, z).Sample(n, rng).transpose());
           },
           py::arg("command"), py::arg("n"), py::arg("z") = std::nullopt, py::arg("seed") = 1,
           "n draws of x from p(x | c[, z]), raw units (n x dx); same seed, same draws");
}

predict::StepPersistence PersistenceFromDict(const std::optional<py::dict>& d) {
  predict::StepPersistence p;
  if (!d) return p;
  p.shared = (*d)["shared"].cast<Eigen::VectorXd>();
  p.decay = (*d)["decay"].cast<Eigen::VectorXd>();
  if (d->contains("first_scale")) p.first_scale = (*d)["first_scale"].cast<Eigen::VectorXd>();
  return p;
}

predict::RegionCalibration CalibrationFromDict(const std::optional<py::dict>& d) {
  predict::RegionCalibration c;
  if (!d) return c;
  c.levels = (*d)["levels"].cast<std::vector<double>>();
  c.factor = (*d)["factor"].cast<Eigen::MatrixXd>();
  if (d->contains("episodes")) c.episodes = (*d)["episodes"].cast<Eigen::VectorXi>();
  return c;
}

void BindFitAndPredict(py::module_& m) {
  m.def("fit_dgmm", &FitDgmm, py::arg("set"), py::arg("k") = 0.7, py::arg("with_terrain") = true, py::arg("seed") = 1,
        py::arg("max_components") = 0, py::arg("variant") = "faithful", py::arg("covariance") = "prior",
        py::arg("init_scale") = DgmmOptions{}.initial_covariance_fraction,
        "One DGMM per command, samples added one at a time in set order (as `dgmm fit`).");
  m.def("fit_em",
        [](const SampleSet& set, int components, int n_init, int max_iterations, double tolerance, double reg_covar,
           std::uint64_t seed, bool with_terrain) {
          EmOptions o;
          o.components = components;
          o.n_init = n_init;
          o.max_iterations = max_iterations;
          o.tolerance = tolerance;
          o.reg_covar = reg_covar;
          o.seed = seed;
          std::string error;
          if (!o.IsValid(&error)) throw InputError("options: " + error);
          return FitEmMotionModel(set, o, with_terrain, "set").model;
        },
        py::arg("set"), py::arg("components") = 2, py::arg("n_init") = 1, py::arg("max_iterations") = 100,
        py::arg("tolerance") = 1e-3, py::arg("reg_covar") = 1e-6, py::arg("seed") = 1, py::arg("with_terrain") = true,
        "The EM reference: one full-covariance mixture per command (as `dgmm em`).");
  m.def("predict",
        [](const MotionModel& model, const std::vector<int>& commands, const std::optional<Eigen::MatrixXd>& terrain,
           const Eigen::Vector3d& start, int trajectories, std::uint64_t seed, const std::vector<std::string>& pose_dims,
           std::optional<double> ground_slope_deg, const std::optional<py::dict>& persistence, bool walking,
           const std::optional<py::dict>& calibration) {
          std::vector<predict::Step> steps;
          for (std::size_t k = 0; k < commands.size(); ++k) {
            predict::Step s{commands[k], {}};
            if (terrain) {
              const int row = terrain->rows() == 1 ? 0 : static_cast<int>(k);
              if (row >= terrain->rows()) throw InputError("terrain: expected one row, or one row per command");
              s.terrain = terrain->row(row).transpose();
            }
            steps.push_back(s);
          }
          predict::PredictOptions o;
          o.trajectories = trajectories;
          o.seed = seed;
          o.pose_dims = pose_dims;
          if (ground_slope_deg) o.ground = predict::GroundTerrain(model, {*ground_slope_deg * M_PI / 180});
          o.from_rest = !walking;
          o.persistence = PersistenceFromDict(persistence);
          o.calibration = CalibrationFromDict(calibration);
          const predict::Prediction p = predict::Predict(model, start, steps, o);
          const int n = static_cast<int>(p.steps.size());
          const int levels = n > 0 ? static_cast<int>(p.steps[0].region_levels.size()) : 0;
          py::array_t<double> poses({n, trajectories, 4}), mean({n, 4}), cov({n, 4, 4}), r2({n, levels});
          auto R = r2.mutable_unchecked<2>();
          auto P = poses.mutable_unchecked<3>();
          auto M = mean.mutable_unchecked<2>();
          auto C = cov.mutable_unchecked<3>();
          for (int k = 0; k < n; ++k) {
            for (int t = 0; t < trajectories; ++t) {
              for (int d = 0; d < 4; ++d) P(k, t, d) = p.steps[k].poses(t, d);
            }
            for (int d = 0; d < 4; ++d) {
              M(k, d) = p.steps[k].mean[d];
              for (int e = 0; e < 4; ++e) C(k, d, e) = p.steps[k].covariance(d, e);
            }
            for (int l = 0; l < levels; ++l) R(k, l) = p.steps[k].region_r2[l];
          }
          py::dict out;
          out["poses"] = poses;
          out["mean"] = mean;
          out["covariance"] = cov;
          out["region_levels"] = n > 0 ? p.steps[0].region_levels : o.region_levels;
          out["region_r2"] = r2;
          return out;
        },
        py::arg("model"), py::arg("commands"), py::arg("terrain") = std::nullopt,
        py::arg("start") = Eigen::Vector3d::Zero(), py::arg("trajectories") = 1000, py::arg("seed") = 1,
        py::arg("pose_dims") = std::vector<std::string>{}, py::arg("ground_slope_deg") = std::nullopt,
        py::arg("persistence") = std::nullopt, py::arg("walking") = false, py::arg("calibration") = std::nullopt,
        "Where a command sequence takes the robot (as `dgmm predict`): poses (steps x trajectories x "
        "[x, y, z, yaw]), their mean and covariance per step, and region_r2 (steps x region_levels): r2 of "
        "the planar regions (p - mean)^T C^-1 (p - mean) <= r2 in x, y holding those shares (calibrated: "
        "calibrate_regions' dict). pose_dims: the model's names for dx, dy, dyaw "
        "(planar composition) or dx, dy, dyaw, dz, droll, dpitch; default: SE(3) when the model has them all. "
        "ground_slope_deg: condition each trajectory on a plane's pitch and roll at its heading (as --ground). "
        "persistence: estimate_persistence's dict; correlates each trajectory's draws from step to step (as --persistence). "
        "walking: the robot walks before the first command (as --walking).");
  m.def("calibrate_regions",
        [](const MotionModel& model, const SampleSet& set, int trajectories, std::uint64_t seed,
           const std::vector<std::string>& pose_dims, const std::optional<py::dict>& persistence, bool walking,
           const std::vector<double>& levels, int min_episodes) {
          predict::PredictOptions o;
          o.trajectories = trajectories;
          o.seed = seed;
          o.pose_dims = pose_dims;
          o.persistence = PersistenceFromDict(persistence);
          o.from_rest = !walking;
          o.region_levels = levels;
          predict::CalibrationOptions c;
          c.min_episodes = min_episodes;
          const predict::RegionCalibration r = predict::CalibrateRegions(model, set, o, c);
          py::dict out;
          out["levels"] = r.levels;
          out["factor"] = r.factor;
          out["episodes"] = r.episodes;
          return out;
        },
        py::arg("model"), py::arg("set"), py::arg("trajectories") = 1000, py::arg("seed") = 1,
        py::arg("pose_dims") = std::vector<std::string>{}, py::arg("persistence") = std::nullopt,
        py::arg("walking") = false, py::arg("levels") = std::vector<double>{0.5, 0.9}, py::arg("min_episodes") = 20,
        "Factors on the regions' r2 per horizon (as predict --calibrate) from held-out episodes the model did not "
        "learn from: dict of levels, factor (horizons x levels) and episodes per horizon; pass it to predict "
        "as calibration=, with the same persistence and pose_dims.");
  m.def("estimate_persistence",
        [](const MotionModel& model, const SampleSet& set, int max_lag) {
          predict::PersistenceOptions o;
          o.max_lag = max_lag;
          const predict::PersistenceSummary s = predict::EstimatePersistence(model, set, o);
          py::dict out;
          out["shared"] = s.persistence.shared;
          out["decay"] = s.persistence.decay;
          out["first_scale"] = s.persistence.first_scale;
          out["first_steps"] = s.first_steps;
          out["residual_rms"] = s.residual_rms;
          out["lag_correlation"] = s.lag_correlation;
          out["pairs"] = s.pairs;
          out["episodes"] = s.episodes;
          return out;
        },
        py::arg("model"), py::arg("set"), py::arg("max_lag") = 5,
        "How the model's deviations persist over consecutive steps of the set's episodes (as predict "
        "--persistence): dict of shared (a) and decay (phi) per pose dimension, corr(t, t + l) = a phi^l, "
        "first_scale (the first step's spread from standing relative to the model's), "
        "with the measured lag correlations (pose dims x max_lag) and pairs per lag.");
}

}  // namespace
}  // namespace dgmm

PYBIND11_MODULE(_dgmm, m) {
  m.doc() = "dgmm: dynamic Gaussian mixture motion models (C++ library bindings)";
  py::register_exception<dgmm::InputError>(m, "InputError", PyExc_ValueError);
  dgmm::BindSampleSet(m);
  dgmm::BindModel(m);
  dgmm::BindFitAndPredict(m);
}
