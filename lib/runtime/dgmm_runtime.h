#pragma once
// dgmm's runtime for planners: a single header (Eigen only) that reads a model exported by
// `dgmm export` (JSON, docs/file-format.md) and evaluates log p(x | c) and log p(x | c, z),
// conditions a command's mixture on terrain and samples from it, with no other part of dgmm.
// Densities are in the model's own units (after the set's standardisation, when it has one:
// Model::ToModelUnits maps raw y into them). Copy this file into a robot's code base.
//
//   dgmm_runtime::Model model = dgmm_runtime::Model::FromJson(text);
//   double lp = model.LogDensity(model.CommandIndex("+0.5,0,0"), x, z);   // log p(x | c, z)
//   Eigen::VectorXd next = model.Conditional(c, z).Sample(rng);         // a pose change
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace dgmm_runtime {

// --- A minimal JSON reader (objects, arrays, strings, numbers, true/false/null). ---
struct Json {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject } type = Type::kNull;
  double number = 0;
  bool boolean = false;
  std::string string;
  std::vector<Json> array;
  std::map<std::string, Json> object;

  const Json& operator[](const std::string& key) const {
    const auto it = object.find(key);
    if (type != Type::kObject || it == object.end()) throw std::runtime_error("model JSON: missing \"" + key + "\"");
    return it->second;
  }
  bool Has(const std::string& key) const { return type == Type::kObject && object.count(key) > 0; }
  double Number() const {
    if (type != Type::kNumber) throw std::runtime_error("model JSON: expected a number");
    return number;
  }
  Eigen::VectorXd Vector() const {
    Eigen::VectorXd v(static_cast<int>(array.size()));
    for (std::size_t i = 0; i < array.size(); ++i) v[static_cast<int>(i)] = array[i].Number();
    return v;
  }
  Eigen::MatrixXd Matrix() const {
    const int n = static_cast<int>(array.size());
    Eigen::MatrixXd m(n, n);
    for (int r = 0; r < n; ++r) {
      if (static_cast<int>(array[r].array.size()) != n) throw std::runtime_error("model JSON: covariance not square");
      for (int c = 0; c < n; ++c) m(r, c) = array[r].array[c].Number();
    }
    return m;
  }

  static Json Parse(const std::string& text) {
    std::size_t at = 0;
    Json j = ParseValue(text, &at);
    SkipSpace(text, &at);
    if (at != text.size()) throw std::runtime_error("model JSON: trailing characters");
    return j;
  }

 private:
  static void SkipSpace(const std::string& s, std::size_t* at) {
    while (*at < s.size() && std::isspace(static_cast<unsigned char>(s[*at]))) ++*at;
  }
  static void Expect(const std::string& s, std::size_t* at, const char* word) {
    for (const char* p = word; *p; ++p, ++*at) {
      if (*at >= s.size() || s[*at] != *p) throw std::runtime_error("model JSON: unexpected character");
    }
  }
  static std::string ParseString(const std::string& s, std::size_t* at) {
    Expect(s, at, "\"");
    std::string out;
    while (*at < s.size() && s[*at] != '"') {
      char ch = s[(*at)++];
      if (ch == '\\') {
        if (*at >= s.size()) break;
        const char e = s[(*at)++];
        ch = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == 'b' ? '\b' : e == 'f' ? '\f' : e;
        if (e == 'u') {  // keep \uXXXX as '?' (labels and names only)
          *at += 4;
          ch = '?';
        }
      }
      out.push_back(ch);
    }
    Expect(s, at, "\"");
    return out;
  }
  static Json ParseValue(const std::string& s, std::size_t* at) {
    SkipSpace(s, at);
    if (*at >= s.size()) throw std::runtime_error("model JSON: unexpected end");
    Json j;
    const char ch = s[*at];
    if (ch == '{') {
      j.type = Type::kObject;
      ++*at;
      SkipSpace(s, at);
      if (s[*at] == '}') return ++*at, j;
      for (;;) {
        SkipSpace(s, at);
        const std::string key = ParseString(s, at);
        SkipSpace(s, at);
        Expect(s, at, ":");
        j.object[key] = ParseValue(s, at);
        SkipSpace(s, at);
        if (s[*at] == ',') { ++*at; continue; }
        Expect(s, at, "}");
        return j;
      }
    }
    if (ch == '[') {
      j.type = Type::kArray;
      ++*at;
      SkipSpace(s, at);
      if (s[*at] == ']') return ++*at, j;
      for (;;) {
        j.array.push_back(ParseValue(s, at));
        SkipSpace(s, at);
        if (s[*at] == ',') { ++*at; continue; }
        Expect(s, at, "]");
        return j;
      }
    }
    if (ch == '"') {
      j.type = Type::kString;
      j.string = ParseString(s, at);
      return j;
    }
    if (ch == 't') return Expect(s, at, "true"), j.type = Type::kBool, j.boolean = true, j;
    if (ch == 'f') return Expect(s, at, "false"), j.type = Type::kBool, j;
    if (ch == 'n') return Expect(s, at, "null"), j;
    std::size_t used = 0;
    j.type = Type::kNumber;
    j.number = std::stod(s.substr(*at, 40), &used);
    *at += used;
    return j;
  }
};

// --- Gaussians and mixtures with cached Cholesky factors; densities in log space. ---
class Gaussian {
 public:
  Gaussian() = default;
  Gaussian(Eigen::VectorXd mean, Eigen::MatrixXd cov) : mean_(std::move(mean)), cov_(std::move(cov)), llt_(cov_) {
    if (llt_.info() != Eigen::Success) throw std::runtime_error("model: a covariance is not positive definite");
    const Eigen::MatrixXd l = llt_.matrixL();
    log_norm_ = -0.5 * mean_.size() * std::log(2 * M_PI) - l.diagonal().array().log().sum();
  }
  // log N(x; mean, cov) = log_norm - |L^-1 (x - mean)|^2 / 2.
  double LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
    return log_norm_ - 0.5 * llt_.matrixL().solve(x - mean_).squaredNorm();
  }
  // The blocks [0, a) given [a, n) = z: mean_a + S_ab S_bb^-1 (z - mean_b), S_aa - S_ab S_bb^-1 S_ba;
  // *log_marginal = log N(z; mean_b, S_bb).
  Gaussian Condition(int a, const Eigen::Ref<const Eigen::VectorXd>& z, double* log_marginal) const {
    const int b = static_cast<int>(mean_.size()) - a;
    const Gaussian marginal(mean_.tail(b), cov_.bottomRightCorner(b, b));
    *log_marginal = marginal.LogDensity(z);
    const Eigen::MatrixXd gain = marginal.llt_.solve(cov_.bottomLeftCorner(b, a)).transpose();
    Eigen::MatrixXd cov = cov_.topLeftCorner(a, a) - gain * cov_.bottomLeftCorner(b, a);
    cov = 0.5 * (cov + cov.transpose());
    return Gaussian(mean_.head(a) + gain * (z - mean_.tail(b)), cov);
  }
  Gaussian Marginal(int a) const { return Gaussian(mean_.head(a), cov_.topLeftCorner(a, a)); }
  template <typename Rng>
  Eigen::VectorXd Sample(Rng& rng) const {
    std::normal_distribution<double> normal;
    Eigen::VectorXd e(mean_.size());
    for (int i = 0; i < e.size(); ++i) e[i] = normal(rng);
    return mean_ + llt_.matrixL() * e;
  }
  const Eigen::VectorXd& mean() const { return mean_; }
  const Eigen::MatrixXd& covariance() const { return cov_; }

 private:
  Eigen::VectorXd mean_;
  Eigen::MatrixXd cov_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  double log_norm_ = 0;
};

class Mixture {
 public:
  // Adds a component; weights are relative until Normalise().
  void Add(double log_weight, Gaussian g) {
    log_w_.push_back(log_weight);
    components_.push_back(std::move(g));
  }
  // Scales the weights to sum to one.
  void Normalise() {
    double m = -std::numeric_limits<double>::infinity();
    for (double w : log_w_) m = std::max(m, w);
    if (!std::isfinite(m)) return;
    double s = 0;
    for (double w : log_w_) s += std::exp(w - m);
    for (double& w : log_w_) w -= m + std::log(s);
  }
  // log sum_i w_i N_i(x), weights normalised.
  double LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
    double m = -std::numeric_limits<double>::infinity();
    std::vector<double> v(components_.size());
    for (std::size_t i = 0; i < v.size(); ++i) m = std::max(m, v[i] = log_w_[i] + components_[i].LogDensity(x));
    if (!std::isfinite(m)) return m;
    double s = 0;
    for (double t : v) s += std::exp(t - m);
    return m + std::log(s);
  }
  // p(x_a | x_b = z) for x = x_a || x_b, x_a the first `a` dimensions (eqs. 15-19 of the paper).
  Mixture Condition(int a, const Eigen::Ref<const Eigen::VectorXd>& z) const {
    Mixture out;
    for (std::size_t i = 0; i < components_.size(); ++i) {
      double log_marginal = 0;
      Gaussian g = components_[i].Condition(a, z, &log_marginal);
      out.log_w_.push_back(log_w_[i] + log_marginal);
      out.components_.push_back(std::move(g));
    }
    out.Normalise();
    return out;
  }
  Mixture Marginal(int a) const {
    Mixture out;
    for (std::size_t i = 0; i < components_.size(); ++i) {
      out.log_w_.push_back(log_w_[i]);
      out.components_.push_back(components_[i].Marginal(a));
    }
    return out;
  }
  template <typename Rng>
  Eigen::VectorXd Sample(Rng& rng) const {
    std::uniform_real_distribution<double> u(0, 1);
    double r = u(rng), acc = 0;
    for (std::size_t i = 0; i < components_.size(); ++i) {
      acc += std::exp(log_w_[i]);
      if (r < acc || i + 1 == components_.size()) return components_[i].Sample(rng);
    }
    throw std::runtime_error("model: an empty mixture");
  }
  int size() const { return static_cast<int>(components_.size()); }
  double weight(int i) const { return std::exp(log_w_[i]); }
  const Gaussian& component(int i) const { return components_[i]; }

 private:
  std::vector<double> log_w_;
  std::vector<Gaussian> components_;
};

// A model: for every command a mixture over y = x || z.
class Model {
 public:
  static Model FromJson(const std::string& text) {
    const Json j = Json::Parse(text);
    if (j["dgmm_format"].string != "model") throw std::runtime_error("model JSON: not a dgmm model export");
    Model m;
    m.pose_dim_ = static_cast<int>(j["pose_dim"].Number());
    m.terrain_dim_ = static_cast<int>(j["terrain_dim"].Number());
    for (const auto& c : j["commands"].array) {
      Mixture mixture;
      const auto& weights = c["weights"].array;
      for (std::size_t i = 0; i < weights.size(); ++i) {
        mixture.Add(std::log(weights[i].Number()), Gaussian(c["means"].array[i].Vector(), c["covariances"].array[i].Matrix()));
      }
      mixture.Normalise();
      m.labels_.push_back(c["label"].string);
      m.values_.push_back(c["values"].Vector());
      m.mixtures_.push_back(std::move(mixture));
    }
    if (j.Has("transform") && j["transform"].type == Json::Type::kObject) {
      m.offset_ = j["transform"]["offset"].Vector();
      m.scale_ = j["transform"]["scale"].Vector();
    }
    return m;
  }
  int pose_dim() const { return pose_dim_; }
  int terrain_dim() const { return terrain_dim_; }
  int num_commands() const { return static_cast<int>(mixtures_.size()); }
  const std::string& label(int c) const { return labels_.at(c); }
  const Eigen::VectorXd& command_values(int c) const { return values_.at(c); }
  // The index of the command with this label; throws when there is none.
  int CommandIndex(const std::string& label) const {
    for (int c = 0; c < num_commands(); ++c) {
      if (labels_[c] == label) return c;
    }
    throw std::runtime_error("model: no command \"" + label + "\"");
  }
  const Mixture& Joint(int c) const { return mixtures_.at(c); }
  // p(x | c, z) as a mixture over x.
  Mixture Conditional(int c, const Eigen::Ref<const Eigen::VectorXd>& z) const {
    if (terrain_dim_ == 0 || z.size() != terrain_dim_) throw std::runtime_error("model: z has the wrong size");
    return mixtures_.at(c).Condition(pose_dim_, z);
  }
  // log p(x | c), the marginal over the pose.
  double LogDensity(int c, const Eigen::Ref<const Eigen::VectorXd>& x) const {
    return terrain_dim_ == 0 ? mixtures_.at(c).LogDensity(x) : mixtures_.at(c).Marginal(pose_dim_).LogDensity(x);
  }
  // log p(x | c, z).
  double LogDensity(int c, const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& z) const {
    return Conditional(c, z).LogDensity(x);
  }
  // Raw y (the training set's units) into the model's: (y - offset) / scale; identity without a transform.
  Eigen::VectorXd ToModelUnits(const Eigen::Ref<const Eigen::VectorXd>& y_raw) const {
    if (offset_.size() == 0) return y_raw;
    return (y_raw - offset_.head(y_raw.size())).cwiseQuotient(scale_.head(y_raw.size()));
  }

 private:
  int pose_dim_ = 0, terrain_dim_ = 0;
  std::vector<std::string> labels_;
  std::vector<Eigen::VectorXd> values_;
  std::vector<Mixture> mixtures_;
  Eigen::VectorXd offset_, scale_;
};

}  // namespace dgmm_runtime
