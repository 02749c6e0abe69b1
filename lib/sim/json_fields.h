#pragma once
// Internal to dgmm_sim: strict reading of one JSON object's fields (nlohmann), shared by the
// config's top level and its blocks (sim_config.cc, robot_description.cc, terrain.cc). Errors are InputError
// "<source>: <path>.<key>: <problem>"; keys never asked for are reported by Done().
#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "util/error.h"

namespace dgmm::sim {

// Reads one JSON object's fields; keys never asked for are reported as unknown.
class JsonFields {
 public:
  // path: the object's place in the file ("" for the file's top level).
  JsonFields(const nlohmann::json& object, std::string path, const std::string& source)
      : object_(object), path_(std::move(path)), source_(source) {
    if (!object_.is_object()) Fail(path_.empty() ? "(root)" : path_, "expected a JSON object");
  }
  // The fields of the object under `key` (an empty object when absent).
  JsonFields Child(const char* key) {
    static const nlohmann::json kEmpty = nlohmann::json::object();
    const nlohmann::json* v = Find(key);
    return JsonFields(v ? *v : kEmpty, Field(key), source_);
  }
  const nlohmann::json* Find(const char* key) {
    used_.insert(key);
    const auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }
  void String(const char* key, std::string* out, bool allow_empty = false) {
    if (const nlohmann::json* v = Find(key)) {
      if (!v->is_string()) Fail(Field(key), allow_empty ? "expected a string" : "expected a non-empty string");
      if (!allow_empty && v->get<std::string>().empty()) Fail(Field(key), "expected a non-empty string");
      *out = v->get<std::string>();
    }
  }
  // A number whose range the caller checks.
  void Number(const char* key, double* out) {
    if (const nlohmann::json* v = Find(key)) {
      if (!v->is_number()) Fail(Field(key), "expected a number");
      *out = v->get<double>();
    }
  }
  // Exactly n numbers into an indexable array.
  template <int n, typename Array>
  void Numbers(const char* key, Array* out) {
    if (const nlohmann::json* v = Find(key)) {
      const std::string expected = "expected an array of " + std::to_string(n) + " numbers";
      if (!v->is_array() || v->size() != n) Fail(Field(key), expected);
      for (int i = 0; i < n; ++i) {
        if (!(*v)[i].is_number()) Fail(Field(key), expected);
        (*out)[i] = (*v)[i].template get<double>();
      }
    }
  }
  void Number(const char* key, double* out, double lo, double hi) {
    if (const nlohmann::json* v = Find(key)) {
      if (!v->is_number() || !std::isfinite(v->get<double>()) || v->get<double>() < lo || v->get<double>() > hi) {
        Fail(Field(key), "expected a number in [" + Str(lo) + ", " + Str(hi) + "]");
      }
      *out = v->get<double>();
    }
  }
  void Bool(const char* key, bool* out) {
    if (const nlohmann::json* v = Find(key)) {
      if (!v->is_boolean()) Fail(Field(key), "expected true or false");
      *out = v->get<bool>();
    }
  }
  void Strings(const char* key, std::vector<std::string>* out) {
    if (const nlohmann::json* v = Find(key)) {
      if (!v->is_array()) Fail(Field(key), "expected an array of names");
      for (const auto& s : *v) {
        if (!s.is_string() || s.get<std::string>().empty()) Fail(Field(key), "expected an array of names");
        out->push_back(s.get<std::string>());
      }
    }
  }
  void Vector3(const char* key, Eigen::Vector3d* out) { Numbers<3>(key, out); }
  void Done() const {
    for (const auto& [key, unused] : object_.items()) {
      if (!used_.count(key)) Fail(Field(key.c_str()), "unknown key");
    }
  }
  std::string Field(const char* key) const { return path_.empty() ? key : path_ + "." + key; }
  [[noreturn]] void Fail(const std::string& field, const std::string& problem) const {
    throw MakeInputError(source_, field, problem);
  }

 private:
  static std::string Str(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  const nlohmann::json& object_;
  std::string path_;
  const std::string& source_;
  std::set<std::string> used_;
};

}  // namespace dgmm::sim
